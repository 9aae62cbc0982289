// The display pass on the GPU against core/tonemap.h's toDisplay on the CPU (what headless PNG
// output uses): the same numbers for every tone mapper, several exposures and radiances spanning
// black, negative (clamped), the sRGB toe, mid-grey and far over white.
#include "viewer/display_pass.h"

#include <gtest/gtest.h>

#include <vector>

#include "gl/context.h"
#include "gl/framebuffer.h"

namespace eik {
namespace {

TEST(DisplayPass, MatchesTheCpuToneMappingOfHeadlessPng) {
  gl::GlContext context;
  gl::ShaderLibrary shaders;
  DisplayPass pass(shaders);
  const std::vector<float> values = {-1.0f, 0.0f, 1e-4f, 0.002f, 0.01f, 0.05f, 0.18f, 0.5f,
                                     0.9f,  1.0f, 1.5f,  3.0f,   10.0f, 100.f, 1e4f,  0.3f};
  const glm::ivec2 size(4, 4);  // one value a pixel in R, others shifted in G and B
  std::vector<float> hdr;
  for (std::size_t i = 0; i < values.size(); ++i) {
    hdr.push_back(values[i]);
    hdr.push_back(values[(i + 5) % values.size()]);
    hdr.push_back(values[(i + 11) % values.size()]);
    hdr.push_back(1.0f);
  }
  gl::Texture2D texture(size, gl::TextureFormat::RGBA32F, hdr, 4);
  gl::Framebuffer target(size, {gl::TextureFormat::RGBA32F});
  int checked = 0;
  for (ToneMapper mapper : {ToneMapper::Linear, ToneMapper::Reinhard, ToneMapper::Aces}) {
    for (float ev : {-2.0f, 0.0f, 1.5f}) {
      target.bind();
      pass.draw(texture, size, ev, mapper);
      std::vector<float> out = target.readRGBA(0);
      for (int p = 0; p < size.x * size.y; ++p) {
        glm::vec3 expected = toDisplay(glm::vec3(hdr[4 * p], hdr[4 * p + 1], hdr[4 * p + 2]), ev, mapper);
        for (int c = 0; c < 3; ++c, ++checked)
          EXPECT_NEAR(out[4 * p + c], expected[c], 2e-5f)
              << "pixel " << p << " channel " << c << " ev " << ev << " mapper " << static_cast<int>(mapper);
        EXPECT_EQ(out[4 * p + 3], 1.0f);
      }
    }
  }
  EXPECT_EQ(checked, 3 * 3 * 16 * 3);
}

TEST(DisplayPass, StretchesASmallerImageOverTheViewportWithNearestTexels) {
  gl::GlContext context;
  gl::ShaderLibrary shaders;
  DisplayPass pass(shaders);
  // 2×1 image: left texel 0.5 grey, right texel 1 (linear tone mapping, no exposure).
  std::vector<float> hdr = {0.5f, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
  gl::Texture2D texture(glm::ivec2(2, 1), gl::TextureFormat::RGBA32F, hdr, 4);
  gl::Framebuffer target(glm::ivec2(6, 3), {gl::TextureFormat::RGBA32F});
  target.bind();
  pass.draw(texture, glm::ivec2(6, 3), 0.0f, ToneMapper::Linear);
  std::vector<float> out = target.readRGBA(0);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 6; ++x)
      EXPECT_NEAR(out[4 * (y * 6 + x)], x < 3 ? linearToSrgb(0.5f) : 1.0f, 2e-5f) << x << "," << y;
}

}  // namespace
}  // namespace eik
