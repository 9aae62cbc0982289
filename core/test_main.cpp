// The main of every test program: Google Test's own, except how the process ends. After the tests
// have run and their output is flushed, it leaves with std::_Exit, skipping static destructors and
// atexit handlers. The GL test programs keep one context alive until the end (test_scenes.h,
// gl_test_fixture.h), and tearing Mesa's llvmpipe down at exit hung once in CI after every test had
// passed (stop 17: LedgerPassTest printed PASSED in 170 ms, then its process sat until ctest's
// timeout); nothing a test checks happens in that teardown, so it is not run.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const int result = RUN_ALL_TESTS();
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(result);
}
