#include "core/uninitialized.h"

#include <gtest/gtest.h>

#include <array>

namespace eik {
namespace {

struct Corner {
  std::array<double, 3> x{};
  int medium = -1;
};

TEST(UninitializedVector, ResizeLeavesTheAddedElementsUnwritten) {
  // Storage kept by a shrink is handed back by the next growth as it was: nothing writes the added
  // elements (a std::vector would zero them).
  UninitializedVector<float> v;
  v.reserve(8);
  v.assign(8, 7.0f);
  v.resize(2);
  v.resize(8);
  EXPECT_EQ(v[5], 7.0f);
  std::vector<float> ordinary(8, 7.0f);
  ordinary.resize(2);
  ordinary.resize(8);
  EXPECT_EQ(ordinary[5], 0.0f);
}

TEST(UninitializedVector, ConstructsWhatIsGivenAValue) {
  // Values given are written as by std::vector: assign, push_back, the range constructor, and an
  // aggregate's default member initialisers where an element is made from `Corner{}`.
  UninitializedVector<Corner> v(3, Corner{{1.0, 2.0, 3.0}, 4});
  v.push_back(Corner{});
  ASSERT_EQ(v.size(), 4u);
  EXPECT_EQ(v[2].x[1], 2.0);
  EXPECT_EQ(v[2].medium, 4);
  EXPECT_EQ(v[3].medium, -1);
  const std::vector<int> from = {5, 6, 7};
  const UninitializedVector<int> copy(from.begin(), from.end());
  EXPECT_EQ(std::vector<int>(copy.begin(), copy.end()), from);
  const UninitializedVector<int> second = copy;
  EXPECT_EQ(second[2], 7);
}

}  // namespace
}  // namespace eik
