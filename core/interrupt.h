// Clean interrupts (docs/programs.md "Interrupts"): SIGINT and SIGTERM remove the temporaries of
// every unfinished atomic write (core/atomic_file.h: nothing under a final name is ever partial)
// and end the program at once with exit code 130 or 143 (128 + the signal), as shells expect.
// runMain installs the handlers for every program.
#pragma once

#include <string>

namespace eik {

// Installs the SIGINT and SIGTERM handlers; `program` (a string literal) prefixes the message
// "PROGRAM: interrupted" they print on stderr.
void installInterruptHandlers(const char* program);

// The temporaries a signal removes. Async-signal-safe on the handler's side: a fixed table of
// paths (kSlots of them, each shorter than kPathBytes; a path that does not fit is only removed by
// the normal path, AtomicFileSet's discard).
// Test hook (docs/testing.md, "Interrupts"): with EIKONAL_TEST_SIGNAL_AT=SIG@N in the environment,
// the N-th call of this function in the process (N from 1) raises signal SIG (2 SIGINT, 9 SIGKILL,
// 15 SIGTERM) at once. The atomic writes call it at every step: before each file is staged, before
// each rename, before each removal of a superseded file, and once after a commit, so a test can
// stop a program at every point of its write phase. Without the variable it does nothing.
void testSignalPoint() noexcept;

namespace pending_temporaries {
constexpr int kSlots = 256;
constexpr int kPathBytes = 1024;
// Registers `path`; returns its slot, or -1 when it does not fit.
int add(const std::string& path) noexcept;
// Forgets a slot (committed or discarded); -1 does nothing.
void remove(int slot) noexcept;
// Registers `path` instead of the slot's path (add, then remove: one of the two is registered at
// every moment); returns the new slot.
int replace(int slot, const std::string& path) noexcept;
// Unlinks every registered path (the signal handler's work; tests).
void unlinkAll() noexcept;
// How many are registered (tests).
int count() noexcept;
}  // namespace pending_temporaries

}  // namespace eik
