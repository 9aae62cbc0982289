// Runs one of our programs as a user would (argv, no shell), capturing exit code and output, in a
// fresh temporary directory per test (test_support::TempDir, from core/testing.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/testing.h"

namespace eik::test {

using test_support::readFile;
using test_support::TempDir;
using test_support::writeFile;

struct ProgramResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
  long peak_rss_kib = 0;  // the program's peak resident memory (getrusage ru_maxrss of the child)
};

// Runs `program` with `args` in `cwd`; EIKONAL_THREADS etc. are inherited. With `signal_number`,
// sends it that signal `signal_after_s` seconds after the start (a user's Ctrl-C, a kill).
ProgramResult runProgram(const std::string& program, const std::vector<std::string>& args,
                         const std::filesystem::path& cwd, int signal_number = 0, double signal_after_s = 0.0);

}  // namespace eik::test
