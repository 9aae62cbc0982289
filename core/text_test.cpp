#include "core/text.h"

#include <gtest/gtest.h>

#include "core/stopwatch.h"

namespace eik {
namespace {

TEST(Text, TrimRemovesEveryKindOfWhitespaceAtBothEndsOnly) {
  EXPECT_EQ(trim(" \t\r\n\f\va b\t\r\n "), "a b");
  EXPECT_EQ(trim(""), "");
  EXPECT_EQ(trim(" \t "), "");
  EXPECT_EQ(trim("x"), "x");
}

TEST(Text, LowerChangesAsciiLettersOnly) {
  EXPECT_EQ(lower("Gzip RAW-42 é"), "gzip raw-42 é");
}

TEST(Stopwatch, CountsUpAndRestartsFromZero) {
  Stopwatch watch;
  const double first = watch.seconds();
  EXPECT_GE(first, 0.0);
  EXPECT_GE(watch.seconds(), first);  // steady clock: never goes back
  const double elapsed = watch.restart();
  EXPECT_GE(elapsed, first);
  EXPECT_LE(watch.seconds(), elapsed + 1.0);  // started again (1 s: generous for a loaded CI core)
}

}  // namespace
}  // namespace eik
