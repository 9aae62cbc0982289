// Tests of the GPU patch list layout (patch_textures.h): Morton placement, the same as the
// histogram pyramid's slots (histo_pyramid.h), live boxes and list sides. No GL needed.
#include "lightsim/patch_textures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "lightsim/histo_pyramid.h"

namespace eik {
namespace {

TEST(PatchListLayoutTest, MortonOrderMatchesThePyramid) {
  for (std::uint32_t k = 0; k < 70000; k += 7) {
    const glm::ivec2 t = mortonTexel(k);
    ASSERT_EQ(mortonIndex(t), k);
    ASSERT_EQ(t, hpSlotTexel(k));
  }
  for (std::size_t n : {0u, 1u, 2u, 3u, 4u, 5u, 8u, 9u, 16u, 17u, 1000u, 4096u, 4097u}) {
    const glm::ivec2 box = mortonBox(n);
    EXPECT_EQ(box, hpLiveBox(n)) << n;
    for (std::uint32_t k = 0; k < n; ++k) {
      const glm::ivec2 t = mortonTexel(k);
      ASSERT_TRUE(t.x < box.x && t.y < box.y) << n << " " << k;
    }
    if (n > 0) {
      EXPECT_LE(static_cast<std::size_t>(box.x) * static_cast<std::size_t>(box.y), 4 * std::max<std::size_t>(n, 2));
    }
  }
  EXPECT_EQ(patchSideFor(0), 1);
  EXPECT_EQ(patchSideFor(17), 8);
  EXPECT_EQ(patchSideFor(64), 8);
  EXPECT_EQ(patchSideFor(65, 4), 16);
}

}  // namespace
}  // namespace eik
