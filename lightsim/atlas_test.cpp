// Tests of the flat-3D atlas layout (atlas.h): the voxel ↔ texel mapping for non-square tilings,
// and the error for a grid too large for GL_MAX_TEXTURE_SIZE. No GL needed.
#include "lightsim/atlas.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <utility>

#include "core/error.h"

namespace eik {
namespace {

TEST(AtlasLayoutTest, RoundTripForNonSquareTilings) {
  for (glm::ivec3 dims : {glm::ivec3(5, 3, 7), glm::ivec3(4, 9, 2), glm::ivec3(16, 16, 16), glm::ivec3(3, 2, 1),
                          glm::ivec3(7, 1, 13), glm::ivec3(1, 1, 1), glm::ivec3(33, 20, 48)}) {
    const AtlasLayout layout = AtlasLayout::plan(dims, 16384);
    SCOPED_TRACE(testing::Message() << dims.x << "x" << dims.y << "x" << dims.z << " → tiles " << layout.tiles.x << "x"
                                    << layout.tiles.y);
    EXPECT_GE(layout.tiles.x * layout.tiles.y, dims.z);
    EXPECT_LT((layout.tiles.y - 1) * layout.tiles.x, dims.z);  // no empty row
    EXPECT_EQ(layout.size, layout.tiles * glm::ivec2(dims.x, dims.y));
    std::set<std::pair<int, int>> seen;
    for (int k = 0; k < dims.z; ++k) {
      for (int j = 0; j < dims.y; ++j) {
        for (int i = 0; i < dims.x; ++i) {
          const glm::ivec2 t = layout.texel({i, j, k});
          ASSERT_GE(t.x, 0);
          ASSERT_GE(t.y, 0);
          ASSERT_LT(t.x, layout.size.x);
          ASSERT_LT(t.y, layout.size.y);
          ASSERT_EQ(layout.voxel(t), glm::ivec3(i, j, k));
          ASSERT_TRUE(seen.insert({t.x, t.y}).second) << "two voxels on one texel";
        }
      }
    }
    // Texels of the unused tiles map to no voxel.
    int unused = 0;
    for (int y = 0; y < layout.size.y; ++y) {
      for (int x = 0; x < layout.size.x; ++x) unused += layout.voxel({x, y}).x < 0 ? 1 : 0;
    }
    EXPECT_EQ(static_cast<std::size_t>(unused) + seen.size(), layout.texelCount());
  }
  // A tiling that is not the square-ish one because of the limit: 8 slices of 10x4 within 40 texels.
  const AtlasLayout narrow = AtlasLayout::plan({10, 4, 8}, 40);
  EXPECT_LE(narrow.size.x, 40);
  EXPECT_LE(narrow.size.y, 40);
  EXPECT_EQ(narrow.voxel(narrow.texel({9, 3, 7})), glm::ivec3(9, 3, 7));
}

TEST(AtlasLayoutTest, TooLargeIsAnInputError) {
  try {
    AtlasLayout::plan({4096, 4096, 4096}, 16384, "big.vol.json", "llvmpipe");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("big.vol.json"), std::string::npos) << what;
    EXPECT_NE(what.find("volume too large for the GPU"), std::string::npos) << what;
    EXPECT_NE(what.find("4096x4096x4096"), std::string::npos) << what;
    EXPECT_NE(what.find("GL_MAX_TEXTURE_SIZE (16384)"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace eik
