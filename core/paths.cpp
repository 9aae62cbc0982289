#include "core/paths.h"

#include <atomic>

#include "core/error.h"

namespace fs = std::filesystem;

namespace eik {
namespace {

std::atomic<bool> g_allow_outside{false};

// Absolute, symlinks resolved for the part that exists, "." and ".." removed.
fs::path resolved(const fs::path& path) {
  std::error_code ec;
  fs::path absolute = fs::absolute(path, ec);
  if (ec) absolute = path;
  fs::path canonical = fs::weakly_canonical(absolute, ec);
  return ec ? absolute.lexically_normal() : canonical;
}

}  // namespace

void allowPathsOutsideFolder(bool allow) { g_allow_outside.store(allow); }
bool pathsOutsideFolderAllowed() { return g_allow_outside.load(); }

bool isInsideFolder(const fs::path& path, const fs::path& folder) {
  const fs::path p = resolved(path);
  const fs::path f = resolved(folder);
  auto pi = p.begin();
  for (auto fi = f.begin(); fi != f.end(); ++fi, ++pi) {
    if (fi->empty()) break;  // a trailing separator ends the folder
    if (pi == p.end() || *pi != *fi) return false;
  }
  for (; pi != p.end(); ++pi)
    if (!pi->empty()) return true;  // at least one component below the folder
  return false;
}

fs::path resolveInsideFolder(const fs::path& folder, const std::string& source, const std::string& key,
                             const std::string& named) {
  const fs::path base = folder.empty() ? fs::path(".") : folder;
  const fs::path path = fs::path(named).is_absolute() ? fs::path(named) : base / named;
  if (!pathsOutsideFolderAllowed() && !isInsideFolder(path, base)) {
    throw InputError(source, key,
                     "'" + named + "' is outside the folder of " + fs::path(source).filename().string() +
                         " (a path inside a file must stay in its folder; --allow-outside-paths lifts the rule)");
  }
  return path;
}

fs::path resolveInsideFolder(const fs::path& source, const std::string& key, const std::string& named) {
  return resolveInsideFolder(source.parent_path(), source.string(), key, named);
}

}  // namespace eik
