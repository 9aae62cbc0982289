// Clean interrupts (see interrupt.h).
#include "core/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

namespace eik {

namespace {

enum SlotState : int { kFree = 0, kFilling = 1, kReady = 2 };

struct Slot {
  std::atomic<int> state{kFree};
  char path[pending_temporaries::kPathBytes];
};
Slot g_slots[pending_temporaries::kSlots];
const char* g_program = "eikonal";

void writeAll(const char* text) noexcept {
  std::size_t length = std::strlen(text);
  while (length > 0) {
    const ssize_t n = ::write(STDERR_FILENO, text, length);
    if (n <= 0) return;
    text += n;
    length -= static_cast<std::size_t>(n);
  }
}

extern "C" void onInterrupt(int signal_number) {
  pending_temporaries::unlinkAll();
  writeAll(g_program);
  writeAll(signal_number == SIGINT ? ": interrupted (SIGINT); no output written\n"
                                   : ": terminated (SIGTERM); no output written\n");
  ::_exit(128 + signal_number);
}

}  // namespace

namespace pending_temporaries {

int add(const std::string& path) noexcept {
  if (path.size() + 1 > static_cast<std::size_t>(kPathBytes)) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (!g_slots[i].state.compare_exchange_strong(expected, kFilling, std::memory_order_acquire)) continue;
    std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
    g_slots[i].state.store(kReady, std::memory_order_release);
    return i;
  }
  return -1;
}

void remove(int slot) noexcept {
  if (slot >= 0 && slot < kSlots) g_slots[slot].state.store(kFree, std::memory_order_release);
}

void unlinkAll() noexcept {
  for (Slot& slot : g_slots)
    if (slot.state.load(std::memory_order_acquire) == kReady) ::unlink(slot.path);
}

int replace(int slot, const std::string& path) noexcept {
  const int added = add(path);
  remove(slot);
  return added;
}

int count() noexcept {
  int n = 0;
  for (const Slot& slot : g_slots) n += slot.state.load(std::memory_order_acquire) == kReady ? 1 : 0;
  return n;
}

}  // namespace pending_temporaries

void testSignalPoint() noexcept {
  // Parsed once; "SIG@N".
  static const std::pair<int, long> target = [] {
    const char* text = std::getenv("EIKONAL_TEST_SIGNAL_AT");
    int signal_number = 0;
    long n = 0;
    if (text == nullptr || std::sscanf(text, "%d@%ld", &signal_number, &n) != 2 || n < 1) return std::pair<int, long>{0, 0};
    return std::pair<int, long>{signal_number, n};
  }();
  if (target.first == 0) return;
  static std::atomic<long> calls{0};
  if (++calls == target.second) ::raise(target.first);
}

void installInterruptHandlers(const char* program) {
  g_program = program;
  struct sigaction action;
  std::memset(&action, 0, sizeof action);
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  sigaddset(&action.sa_mask, SIGINT);
  sigaddset(&action.sa_mask, SIGTERM);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

}  // namespace eik
