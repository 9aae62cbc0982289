// Paths named inside files (docs/programs.md, "Paths inside files"): a NRRD's `data file`, a
// manifest's field and receiver files, a SCENE's volumes and environment map, a glTF's buffer and
// image URIs. Each must resolve inside the folder of the file that names it, after symlinks, so
// that a downloaded scene can never make a program read (or quote in an error) a file elsewhere on
// the machine. `--allow-outside-paths` (every program) lifts the rule for one run.
#pragma once

#include <filesystem>
#include <string>

namespace eik {

// Set once by the programs' command line (--allow-outside-paths); off by default.
void allowPathsOutsideFolder(bool allow);
bool pathsOutsideFolderAllowed();

// Resolves `named`, as written in the file `source` under the key `key`, against the folder of
// `source`, and returns it. Throws InputError(source, key, ...) naming the path when the result
// (with symlinks resolved, as far as it exists) leaves that folder and the rule is not lifted.
// Nothing is opened; only directory entries are looked up.
std::filesystem::path resolveInsideFolder(const std::filesystem::path& source, const std::string& key,
                                          const std::string& named);
// The same with the folder given apart from the file's name for messages (`source`).
std::filesystem::path resolveInsideFolder(const std::filesystem::path& folder, const std::string& source,
                                          const std::string& key, const std::string& named);

// Is `path` (made absolute, symlinks resolved as far as it exists) inside the directory `folder`
// (likewise resolved)? The folder itself is not inside.
bool isInsideFolder(const std::filesystem::path& path, const std::filesystem::path& folder);

}  // namespace eik
