// Runs one of our programs as a user would (argv, no shell), capturing exit code and output, in a
// fresh temporary directory per test.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace eik::test {

struct ProgramResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs `program` with `args` in `cwd`; EIKONAL_THREADS etc. are inherited.
ProgramResult runProgram(const std::string& program, const std::vector<std::string>& args,
                         const std::filesystem::path& cwd);

// A directory under the system temp dir, removed on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  // Every file name in the directory, sorted.
  std::vector<std::string> files() const;

 private:
  std::filesystem::path path_;
};

void writeText(const std::filesystem::path& path, const std::string& text);
std::string readText(const std::filesystem::path& path);

}  // namespace eik::test
