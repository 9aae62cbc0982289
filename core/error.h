// Errors shared by every program, and the exit codes they map to (docs/programs.md):
// 0 success, 1 runtime failure, 2 bad usage or bad input.
#pragma once

#include <stdexcept>
#include <string>

namespace eik {

constexpr int kExitOk = 0;
constexpr int kExitRuntime = 1;
constexpr int kExitBadInput = 2;

// Bad input from the user: a file, a flag or a field is wrong. The message names the file (or flag)
// and the field, e.g. "sphere.ior.nrrd: sizes: 64 64 does not match dimension 3".
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& source, const std::string& field, const std::string& what);
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// A failure that is not the input's fault (GL context lost, disk full, ...).
class RuntimeError : public std::runtime_error {
 public:
  explicit RuntimeError(const std::string& message) : std::runtime_error(message) {}
};

// Runs `body` and turns exceptions into the documented exit codes, printing
// "PROGRAM: error: MESSAGE" on stderr, after installing the SIGINT/SIGTERM handlers
// (core/interrupt.h: exit 130/143, no temporaries left). Every executable's main() goes through this.
int runMain(const char* program, int (*body)(int, char**), int argc, char** argv);

}  // namespace eik
