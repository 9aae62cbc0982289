// Helpers shared by the gl/ tests (header only; not part of eikonal_gl): a test pattern and its
// check. Temporary directories and environment variables: core/testing.h.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "gl/context.h"
#include "gl/framebuffer.h"
#include "gl/shader_library.h"
#include "gl/vertex_array.h"

namespace eik::gl::test {

// The expected value of shaders/test/pattern.frag (MODE 2) at pixel (x, y) of a w × h target.
inline void expectedPattern(int x, int y, int w, int h, float cell, float out[4]) {
  float px = static_cast<float>(x) + 0.5f, py = static_cast<float>(y) + 0.5f;
  int cx = static_cast<int>(std::floor(px / cell)), cy = static_cast<int>(std::floor(py / cell));
  float c = static_cast<float>((cx + cy) & 1);
  out[0] = px / static_cast<float>(w);
  out[1] = py / static_cast<float>(h);
  out[2] = 0.25f + 0.5f * c;
  out[3] = 1.0f;
}

// Counts pixels of `pixels` (RGBA, bottom row first) that differ from the pattern by more than
// `tolerance`, reporting the first few.
inline int countPatternMismatches(const std::vector<float>& pixels, int w, int h, float tolerance, float cell = 8.0f) {
  int bad = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float want[4];
      expectedPattern(x, y, w, h, cell, want);
      const float* got = &pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 4];
      for (int c = 0; c < 4; ++c) {
        if (!(std::fabs(got[c] - want[c]) <= tolerance)) {
          if (++bad <= 5) {
            ADD_FAILURE() << "pixel (" << x << ", " << y << ") channel " << c << ": got " << got[c] << ", want "
                          << want[c];
          }
        }
      }
    }
  }
  return bad;
}

// Renders the test pattern into an RGBA32F framebuffer of w × h and checks it pixel by pixel
// (tolerance 1e-6). Also checks the second MRT attachment.
inline void renderAndCheckPattern(int w, int h) {
  ShaderLibrary library;
  Program program = library.program("common/fullscreen.vert", "test/pattern.frag", {{"MODE", "2"}, {"SECOND_TARGET", "1"}});
  Framebuffer target({w, h}, {TextureFormat::RGBA32F, TextureFormat::RGBA32F});
  FullscreenTriangle triangle;
  target.bind();
  program.use();
  program.set("uSize", glm::vec2(static_cast<float>(w), static_cast<float>(h)));
  triangle.draw();
  std::vector<float> pixels = target.readRGBA(0);
  ASSERT_EQ(pixels.size(), static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
  EXPECT_EQ(countPatternMismatches(pixels, w, h, 1e-6f), 0);

  std::vector<float> second = target.readRGBA(1);
  int bad = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float want[4];
      expectedPattern(x, y, w, h, 8.0f, want);
      float c = (want[2] - 0.25f) / 0.5f;
      const float* got = &second[(static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 4];
      if (got[0] != c || got[1] != 1.0f - c || std::fabs(got[2] - 3.14159265f) > 1e-6f || got[3] != -1.0f) ++bad;
    }
  }
  EXPECT_EQ(bad, 0) << "second attachment (MRT) differs";
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glUseProgram(0);
  glBindVertexArray(0);
}

}  // namespace eik::gl::test
