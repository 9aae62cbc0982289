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
// sends it that signal (a user's Ctrl-C, a kill) once its output contains `signal_when_output_has`:
// a marker the program prints when it is at work, so the signal never lands before the program has
// started (a timed signal did, under a sanitizer build on a loaded machine).
ProgramResult runProgram(const std::string& program, const std::vector<std::string>& args,
                         const std::filesystem::path& cwd, int signal_number = 0,
                         const std::string& signal_when_output_has = {});

}  // namespace eik::test
