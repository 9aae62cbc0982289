#include "core/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <system_error>
#include <utility>

#include "core/error.h"
#include "core/interrupt.h"

namespace eik {
namespace fs = std::filesystem;

namespace {

std::string randomSuffix() {
  // A per-process random seed plus a counter: unique across threads and concurrent processes.
  static const std::uint64_t seed = [] {
    std::random_device device;
    return (static_cast<std::uint64_t>(device()) << 32) ^ device();
  }();
  static std::atomic<std::uint64_t> counter{0};
  std::uint64_t value = seed + 0x9E3779B97F4A7C15ull * ++counter;
  value ^= value >> 29;
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

fs::path directoryOf(const fs::path& target) {
  fs::path dir = target.parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

}  // namespace

void removeStaleTemporaries(const fs::path& dir, const std::function<bool(const std::string&)>& of_target) noexcept {
  std::error_code ec;
  for (fs::directory_iterator it(dir.empty() ? fs::path(".") : dir, ec), end; !ec && it != end; it.increment(ec)) {
    // .NAME.tmp-<pid>-<random>
    const std::string name = it->path().filename().string();
    const std::size_t tmp = name.rfind(".tmp-");
    if (name.empty() || name[0] != '.' || tmp == std::string::npos || tmp < 2) continue;
    const char* digits = name.c_str() + tmp + 5;
    char* after = nullptr;
    errno = 0;
    const long pid = std::strtol(digits, &after, 10);
    if (after == digits || *after != '-' || errno == ERANGE || pid <= 0 || pid == ::getpid()) continue;
    if (!of_target(name.substr(1, tmp - 1))) continue;
    // Only a process that no longer exists: kill(pid, 0) fails with ESRCH. A live one (or one we
    // may not signal, EPERM) may still be writing.
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    std::error_code remove_ec;
    fs::remove(it->path(), remove_ec);
  }
}

void removeStaleTemporaries(const fs::path& target) noexcept {
  const std::string target_name = target.filename().string();
  removeStaleTemporaries(directoryOf(target), [&](const std::string& name) { return name == target_name; });
}

fs::path temporaryPathFor(const fs::path& target) {
  std::string name = "." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                     randomSuffix();
  return target.parent_path() / name;
}

AtomicFileSet::~AtomicFileSet() { discard(); }

AtomicFileSet::AtomicFileSet(AtomicFileSet&& other) noexcept
    : entries_(std::move(other.entries_)), committed_(other.committed_) {
  other.entries_.clear();
}

AtomicFileSet& AtomicFileSet::operator=(AtomicFileSet&& other) noexcept {
  if (this != &other) {
    discard();
    entries_ = std::move(other.entries_);
    committed_ = other.committed_;
    other.entries_.clear();
  }
  return *this;
}

fs::path AtomicFileSet::stage(const fs::path& target) {
  if (committed_) throw RuntimeError(target.string() + ": cannot stage a file in a committed AtomicFileSet");
  if (target.filename().empty()) throw InputError(target.string(), "", "not a file name");
  for (const Entry& entry : entries_) {
    if (entry.target == target) throw RuntimeError(target.string() + ": staged twice for one atomic write");
  }
  std::error_code ec;
  fs::path dir = directoryOf(target);
  if (!fs::is_directory(dir, ec)) {
    throw InputError(target.string(), "", "output directory " + dir.string() + " does not exist");
  }
  if (fs::is_directory(target, ec)) throw InputError(target.string(), "", "is a directory");
  testSignalPoint();
  removeStaleTemporaries(target);
  Entry entry{target, temporaryPathFor(target), -1};
  entry.slot = pending_temporaries::add(entry.temporary.string());  // a signal removes it (interrupt.h)
  entries_.push_back(std::move(entry));
  return entries_.back().temporary;
}

void AtomicFileSet::write(const fs::path& target, std::string_view bytes) {
  fs::path temporary = stage(target);
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(temporary.c_str(), "wb"));
  if (!file) throw RuntimeError(target.string() + ": cannot create file: " + std::strerror(errno));
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size()) {
    throw RuntimeError(target.string() + ": write failed: " + std::strerror(errno));
  }
  if (std::fclose(file.release()) != 0) {
    throw RuntimeError(target.string() + ": write failed: " + std::strerror(errno));
  }
}

void AtomicFileSet::commit() {
  if (committed_) return;
  // A file renamed to a name that did not exist before stays registered (under its final name)
  // until the last rename: an interrupt, or a failed rename, before then removes it again, so the
  // folder is left as it was. A file that replaced another cannot be undone and is released.
  std::vector<std::size_t> fresh;
  auto release = [&] {
    for (std::size_t j : fresh) pending_temporaries::remove(entries_[j].slot), entries_[j].slot = -1;
  };
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    testSignalPoint();
    Entry& entry = entries_[i];
    std::error_code ec;
    const bool existed = fs::exists(fs::symlink_status(entry.target, ec));
    fs::rename(entry.temporary, entry.target, ec);
    if (ec) {
      std::string message = entry.target.string() + ": cannot move the finished file into place: " + ec.message();
      for (std::size_t j : fresh) {
        std::error_code remove_ec;
        fs::remove(entries_[j].target, remove_ec);
      }
      release();
      // The rest are still temporaries: discard them.
      entries_.erase(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(i));
      discard();
      throw RuntimeError(message);
    }
    if (!existed && i + 1 < entries_.size()) {
      entry.slot = pending_temporaries::replace(entry.slot, entry.target.string());
      fresh.push_back(i);
    } else {
      pending_temporaries::remove(entry.slot);
      entry.slot = -1;
    }
  }
  release();
  entries_.clear();
  committed_ = true;
  testSignalPoint();
}

void AtomicFileSet::discard() noexcept {
  for (const Entry& entry : entries_) {
    std::error_code ec;
    fs::remove(entry.temporary, ec);  // the file may never have been created: ignore errors
    pending_temporaries::remove(entry.slot);
  }
  entries_.clear();
}

std::vector<fs::path> AtomicFileSet::targets() const {
  std::vector<fs::path> result;
  result.reserve(entries_.size());
  for (const Entry& entry : entries_) result.push_back(entry.target);
  return result;
}

void writeFileAtomic(const fs::path& path, std::string_view bytes) {
  AtomicFileSet files;
  files.write(path, bytes);
  files.commit();
}

}  // namespace eik
