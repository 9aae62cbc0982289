// What every libFuzzer harness in fuzz/ shares (header only): the fuzzer's bytes as a file under
// the name a reader expects, and the rule that a reader may refuse an input only with InputError
// (exit 2 in the programs, docs/programs.md). Anything else escaping a reader (another exception,
// a crash, a sanitizer report, memory past the limits) is a bug that libFuzzer reports.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.h"

namespace eik::fuzz {

// A folder of this process's own for the inputs, in memory (/dev/shm) where there is one (removed by
// scripts/fuzz.sh afterwards).
inline const std::filesystem::path& workDirectory() {
  static const std::filesystem::path dir = [] {
    std::error_code ec;
    const std::filesystem::path base =
        std::filesystem::is_directory("/dev/shm", ec) ? std::filesystem::path("/dev/shm") : std::filesystem::temp_directory_path();
    std::filesystem::path d = base / ("eikonal-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

// Writes the input to workDirectory()/name and returns its path.
inline std::filesystem::path inputFile(const char* name, const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = workDirectory() / name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {  // the folder was removed under us (a cleanup of another run): make it again
    std::error_code ec;
    std::filesystem::create_directories(workDirectory(), ec);
    f = std::fopen(path.c_str(), "wb");
  }
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

// The readers' memory limit (core/limits.h) well under libFuzzer's -rss_limit_mb (2048 by default):
// a header that asks for more must be refused before the allocation.
inline void limitMemory(const char* bytes = "536870912") { ::setenv("EIKONAL_MEMORY_LIMIT_BYTES", bytes, 1); }

// Runs a reader on one input: InputError is the expected refusal; everything else propagates.
template <typename Read>
int readOrRefuse(Read&& read) {
  try {
    read();
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace eik::fuzz

// A harness that hands the input, as the file NAME, to READ(path) (a reader function).
#define EIKONAL_FUZZ_FILE_READER(NAME, READ)                                                \
  extern "C" int LLVMFuzzerInitialize(int*, char***) {                                     \
    eik::fuzz::limitMemory();                                                              \
    return 0;                                                                              \
  }                                                                                        \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {      \
    const std::filesystem::path path = eik::fuzz::inputFile(NAME, data, size);             \
    return eik::fuzz::readOrRefuse([&] { READ(path); });                                   \
  }
