// Tests of lightsim/live_count (OSMesa, or EIKONAL_GL): the count uploaded and read back, the
// pyramid's total taken on the GPU, the read as a snapshot (a later build does not change a
// pending read), the misuse refused, and a pass that reads liveCount() in GLSL.
#include "lightsim/live_count.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "gl/framebuffer.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "gl/vertex_array.h"
#include "lightsim/histo_pyramid.h"
#include "lightsim/test_scenes.h"

namespace eik::gpu {
namespace {

class LiveCountTest : public ::testing::Test {
 protected:
  gl::GlContext& gl_ = test_scenes::glContext();
  gl::ShaderLibrary library_;

  // A pyramid of side² slots built from random counts in {0, 1, 2, 4, 5} (what one patch can
  // take), returning their sum.
  std::uint64_t buildRandom(HistoPyramid& pyramid, unsigned seed) {
    const int side = pyramid.baseSize();
    std::vector<float> counts(static_cast<std::size_t>(side) * static_cast<std::size_t>(side));
    std::mt19937 rng(seed);
    const float choices[] = {0.0f, 1.0f, 2.0f, 4.0f, 5.0f};
    std::uint64_t sum = 0;
    for (float& c : counts) {
      c = choices[rng() % 5];
      sum += static_cast<std::uint64_t>(c);
    }
    const gl::Texture2D texture({side, side}, gl::TextureFormat::R32F, counts, 1,
                                gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge});
    pyramid.build(texture);
    return sum;
  }
};

TEST_F(LiveCountTest, ASetCountReadsBack) {
  LiveCount live;
  for (std::uint64_t n : {std::uint64_t{0}, std::uint64_t{1}, std::uint64_t{12345}, std::uint64_t{1} << 24}) {
    live.set(n);
    live.request();
    EXPECT_TRUE(live.pending());
    EXPECT_EQ(live.wait(), n);
    EXPECT_FALSE(live.pending());
  }
  // Over 2^24 float cannot count exactly: refused, not rounded.
  EXPECT_THROW(live.set((std::uint64_t{1} << 24) + 1), std::logic_error);
}

TEST_F(LiveCountTest, TakesThePyramidsTotalAndReadsASnapshot) {
  HistoPyramid pyramid(64, library_);
  LiveCount live;
  const std::uint64_t first = buildRandom(pyramid, 1);
  live.takeTotal(pyramid);
  live.request();
  // Rebuilt with other counts and taken again before the wait: the pending read still holds the
  // first total (it was queued before), and the next read the second.
  const std::uint64_t second = buildRandom(pyramid, 2);
  ASSERT_NE(first, second);
  live.takeTotal(pyramid);
  EXPECT_EQ(live.wait(), first);
  live.request();
  EXPECT_EQ(live.wait(), second);
  EXPECT_EQ(pyramid.readTotal(), second);
}

TEST_F(LiveCountTest, RefusesAReadThatIsNotPendingOrTwoAtOnce) {
  LiveCount live;
  EXPECT_THROW(live.wait(), std::logic_error);
  live.request();
  EXPECT_THROW(live.request(), std::logic_error);
  EXPECT_EQ(live.wait(), 0u);
}

// A pass that includes lightsim/live_count.glsl sees the count the texel holds
// (shaders/lightsim/live_count_test.frag: 1 where a fragment's Morton slot is below liveCount()).
TEST_F(LiveCountTest, ShadersSkipTheSlotsPastTheCount) {
  const gl::Program program = library_.program("common/fullscreen.vert", "lightsim/live_count_test.frag");
  gl::Framebuffer target({16, 16}, {gl::TextureFormat::R32F});
  gl::FullscreenTriangle triangle;
  LiveCount live;
  for (std::uint64_t n : {std::uint64_t{0}, std::uint64_t{37}, std::uint64_t{256}}) {
    live.set(n);
    target.bind();
    program.use();
    live.bind(program, 0);
    triangle.draw();
    const std::vector<float> got = target.read(0, 1);
    int wrong = 0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        wrong += got[static_cast<std::size_t>(y * 16 + x)] != (hpTexelSlot({x, y}) < n ? 1.0f : 0.0f);
    EXPECT_EQ(wrong, 0) << "count " << n;
  }
}

}  // namespace
}  // namespace eik::gpu
