// Tests of the GPU patch list layout (patch_textures.h): Morton placement, the same as the
// histogram pyramid's slots (histo_pyramid.h), live boxes and list sides. No GL needed.
#include "lightsim/patch_textures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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

// The sharp layout's META packs the interface state into four floats: every field comes back,
// including the largest values each may hold (media 3 bits a corner, crossed and reflected 4 bits,
// reflections clamped to 255, bounce up to 8), all integers below 2²⁴ and so exact in float.
TEST(PatchListLayoutTest, SharpMetaKeepsEveryInterfaceField) {
  for (int variant = 0; variant < 3; ++variant) {
    Patch p;
    p.depth = variant == 0 ? 0.0 : variant == 1 ? 2.5 : 16.0;
    p.medium = variant == 0 ? std::array<int, 4>{-1, -1, -1, -1}
               : variant == 1 ? std::array<int, 4>{0, -1, 3, 1}
                              : std::array<int, 4>{6, 6, 6, 6};
    p.crossed = variant == 0 ? 0 : variant == 1 ? 5 : 15;
    p.reflected = variant == 0 ? 0 : variant == 1 ? 10 : 15;
    p.reflections = variant == 0 ? 0 : variant == 1 ? 7 : 255;
    p.bounce = variant == 0 ? 0 : variant == 1 ? 1 : 8;
    p.reflect_pending = variant == 1 ? 0.25 : 0.0;
    p.t_fresnel = variant == 1 ? 0.5 : 1.0;
    const Patch q = unpackPatch(packPatch(p, PatchLayout::Sharp), PatchLayout::Sharp);
    EXPECT_EQ(q.depth, p.depth) << variant;
    EXPECT_EQ(q.medium, p.medium) << variant;
    EXPECT_EQ(q.crossed, p.crossed) << variant;
    EXPECT_EQ(q.reflected, p.reflected) << variant;
    EXPECT_EQ(q.reflections, p.reflections) << variant;
    EXPECT_EQ(q.bounce, p.bounce) << variant;
    EXPECT_EQ(q.reflect_pending, p.reflect_pending) << variant;
    EXPECT_EQ(q.t_fresnel, p.t_fresnel) << variant;
  }
}

}  // namespace
}  // namespace eik
