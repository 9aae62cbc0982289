// Helpers shared by the tests: a temporary directory that cleans up after itself, and whole-file
// reads and writes. Only tests include this; it is header-only so that it adds nothing to the
// libraries (core/CMakeLists.txt globs core/*.cpp into eikonal_core).
//
// The namespace is eik::test_support, not eik::testing: inside namespace eik a nested `testing`
// would hide gtest's ::testing from every unqualified `testing::Test` or `testing::Values`.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace eik::test_support {

// A fresh directory under the system temp dir, named <prefix>-<pid>-<counter>-<random>, removed
// with everything in it on destruction.
class TempDir {
 public:
  explicit TempDir(std::string_view prefix = "eikonal-test") {
    static std::atomic<unsigned> counter{0};
    std::random_device random;
    const std::filesystem::path base = std::filesystem::temp_directory_path();
    for (int attempt = 0;; ++attempt) {
      path_ = base / (std::string(prefix) + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" +
                      std::to_string(random()));
      if (std::filesystem::create_directory(path_)) break;  // false: the name was taken
      if (attempt == 100) throw std::runtime_error("cannot create a unique directory under " + base.string());
    }
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::filesystem::path& name) const { return path_ / name; }

  // The name of every entry, hidden ones (such as atomic-write temporaries) included, sorted.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(path_)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::filesystem::path path_;
};

// The whole file, byte for byte; throws std::runtime_error when it cannot be opened.
inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path.string() + " for reading");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Creates or replaces the file with exactly `bytes`; throws std::runtime_error when it cannot.
inline void writeFile(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot open " + path.string() + " for writing");
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace eik::test_support
