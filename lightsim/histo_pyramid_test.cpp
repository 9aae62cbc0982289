// Tests of lightsim/histo_pyramid: Morton slots, and the GPU pyramid (OSMesa) — the total and the
// traversal of shaders/lightsim/histo_pyramid.glsl checked for every output slot against the CPU
// reference (histo_pyramid_cpu.h, tested in histo_pyramid_cpu_test.cpp), for random and edge-case
// count patterns, live counts that are not powers of two, stale data beyond the live slots, and a
// producer that renders into the base. Also prints build/traverse times for 512² and 1024².
#include "lightsim/histo_pyramid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/stopwatch.h"
#include "gl/context.h"
#include "gl/framebuffer.h"
#include "gl/shader_library.h"
#include "gl/vertex_array.h"
#include "lightsim/histo_pyramid_cpu.h"

namespace eik {
namespace {

// ---------------------------------------------------------------------------------------------
// Slots (no GL).

TEST(HistoPyramidSlots, MortonRoundTripAndOrder) {
  EXPECT_EQ(hpSlotTexel(0), glm::ivec2(0, 0));
  EXPECT_EQ(hpSlotTexel(1), glm::ivec2(1, 0));
  EXPECT_EQ(hpSlotTexel(2), glm::ivec2(0, 1));
  EXPECT_EQ(hpSlotTexel(3), glm::ivec2(1, 1));
  EXPECT_EQ(hpSlotTexel(4), glm::ivec2(2, 0));
  EXPECT_EQ(hpSlotTexel((1u << 24) - 1), glm::ivec2(4095, 4095));
  for (std::uint32_t s = 0; s < 70000; s += 7) EXPECT_EQ(hpTexelSlot(hpSlotTexel(s)), s);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const std::uint32_t s = hpTexelSlot({x, y});
      EXPECT_LT(s, 4096u);
      EXPECT_EQ(hpSlotTexel(s), glm::ivec2(x, y));
    }
  }
}

TEST(HistoPyramidSlots, LiveBoxIsTheSmallestPowerOfTwoCover) {
  EXPECT_EQ(hpLiveBox(0), glm::ivec2(0, 0));
  EXPECT_EQ(hpLiveBox(1), glm::ivec2(1, 1));
  EXPECT_EQ(hpLiveBox(2), glm::ivec2(2, 1));
  EXPECT_EQ(hpLiveBox(5), glm::ivec2(4, 2));
  glm::ivec2 tight{0};
  for (std::uint32_t n = 1; n <= 5000; ++n) {
    tight = glm::max(tight, hpSlotTexel(n - 1) + 1);
    const glm::ivec2 box = hpLiveBox(n);
    ASSERT_TRUE(std::has_single_bit(unsigned(box.x)) && std::has_single_bit(unsigned(box.y))) << n;
    ASSERT_TRUE(box.x >= tight.x && box.y >= tight.y) << n;          // covers slots 0 .. n − 1
    ASSERT_TRUE(box.x / 2 < tight.x || box.y == box.x * 2) << n;     // no narrower power of two
    ASSERT_TRUE(box.y / 2 < tight.y || box.y == 1) << n;             // no lower power of two
  }
  EXPECT_EQ(hpLiveBox(std::uint64_t{1} << 24), glm::ivec2(4096, 4096));
}

TEST(HistoPyramidSlots, BaseSizeFor) {
  EXPECT_EQ(hpBaseSizeFor(0), 1);
  EXPECT_EQ(hpBaseSizeFor(1), 1);
  EXPECT_EQ(hpBaseSizeFor(2), 2);
  EXPECT_EQ(hpBaseSizeFor(4), 2);
  EXPECT_EQ(hpBaseSizeFor(5), 4);
  EXPECT_EQ(hpBaseSizeFor(1000), 32);
  EXPECT_EQ(hpBaseSizeFor(std::uint64_t{1} << 24), 4096);
}

// ---------------------------------------------------------------------------------------------
// GPU.

class HistoPyramidGl : public ::testing::Test {
 protected:
  // OSMesa (llvmpipe) unless EIKONAL_GL names another back end (EIKONAL_GL=egl: a GPU).
  gl::GlContext context_{gl::ContextOptions{.backend = gl::glBackendFromEnvironment(gl::GlBackend::OSMesa), .debug = true}};
  gl::ShaderLibrary library_;
  gl::FullscreenTriangle triangle_;

  // Runs the test pass (histo_pyramid_test.frag) for every slot of an output list of
  // hpBaseSizeFor(total)² and checks it against the CPU reference, slot by slot.
  void checkTraversal(const HistoPyramid& pyramid, const HistoPyramidCpu& cpu, bool totalFromTexture) {
    const std::uint64_t total = cpu.total();
    const int side = hpBaseSizeFor(std::max<std::uint64_t>(total, 1));
    gl::ShaderDefines defines = pyramid.defines();
    if (totalFromTexture) defines.emplace_back("HP_TEST_TOTAL_FROM_TEXTURE", "1");
    gl::Program program = library_.program("common/fullscreen.vert", "lightsim/histo_pyramid_test.frag", defines);
    gl::Framebuffer target({side, side}, {gl::TextureFormat::RGBA32F});
    target.bind();
    pyramid.bind(0);
    program.use();
    program.setSampler("uPyramid", 0);
    program.set("uTotal", static_cast<int>(total));
    triangle_.draw();
    const std::vector<float> pixels = target.readRGBA(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);

    int bad = 0;
    for (int y = 0; y < side; ++y) {
      for (int x = 0; x < side; ++x) {
        const std::uint32_t k = hpTexelSlot({x, y});
        const float* got = &pixels[hpTexelIndex({x, y}, side) * 4];
        float want[4] = {-1.0f, -1.0f, -1.0f, -1.0f};
        if (k < total) {
          const HistoPyramidEntry e = cpu.find(k);
          want[0] = float(e.texel.x), want[1] = float(e.texel.y), want[2] = float(e.sub), want[3] = 1.0f;
        }
        if (got[0] != want[0] || got[1] != want[1] || got[2] != want[2] || got[3] != want[3]) {
          if (++bad <= 5) {
            ADD_FAILURE() << "slot " << k << " of " << total << ": got (" << got[0] << ", " << got[1] << ", "
                          << got[2] << ", " << got[3] << "), want (" << want[0] << ", " << want[1] << ", "
                          << want[2] << ", " << want[3] << ")";
          }
        }
      }
    }
    EXPECT_EQ(bad, 0) << "base " << pyramid.baseSize() << ", total " << total;
  }

  // Builds from a counts texture, checks the total (both readbacks), every level inside the live
  // part, and the traversal.
  void checkCase(int base, const std::vector<float>& counts, std::size_t live = HistoPyramidLimits::kAllSlots,
                 bool totalFromTexture = false) {
    SCOPED_TRACE("base " + std::to_string(base) + ", live " + std::to_string(std::min(live, counts.size())));
    const HistoPyramidCpu cpu(base, counts, live);
    HistoPyramid pyramid(base, library_);
    gl::Texture2D texture({base, base}, gl::TextureFormat::R32F, counts, 1,
                          gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge});
    pyramid.build(texture, live);
    EXPECT_EQ(pyramid.readTotal(), cpu.total());
    pyramid.requestTotal();
    EXPECT_EQ(pyramid.waitTotal(), cpu.total());
    checkLevels(pyramid, cpu, std::min<std::uint64_t>(live, counts.size()));
    checkTraversal(pyramid, cpu, totalFromTexture);
  }

  // Every node that holds live slots equals the CPU's: mip m texel of node s (level m + 1) holds the
  // values of nodes 4s .. 4s + 3 of level m.
  static void checkLevels(const HistoPyramid& pyramid, const HistoPyramidCpu& cpu, std::uint64_t live) {
    const std::vector<std::vector<float>> mips = pyramid.downloadLevels();
    ASSERT_EQ(int(mips.size()), std::max(cpu.levels(), 1));
    for (int m = 0; m < cpu.levels(); ++m) {
      const int side = cpu.baseSize() >> (m + 1);
      const std::uint64_t nodes = std::max<std::uint64_t>((live + (std::uint64_t{1} << (2 * (m + 1))) - 1) >> (2 * (m + 1)), 1);
      for (std::uint64_t s = 0; s < nodes; ++s) {
        const float* texel = &mips[std::size_t(m)][hpTexelIndex(hpSlotTexel(std::uint32_t(s)), side) * 4];
        for (int i = 0; i < 4; ++i) {
          const glm::ivec2 child = hpSlotTexel(std::uint32_t(4 * s + std::uint64_t(i)));
          ASSERT_EQ(double(texel[i]), double(cpu.at(m, child))) << "mip " << m << " node " << s << " child " << i;
        }
      }
    }
  }
};

TEST_F(HistoPyramidGl, RandomPatternsZeroOneFour) {
  std::mt19937 rng(1234);
  struct Case {
    int base;
    std::size_t live;
  };
  for (Case c : {Case{1, 1}, Case{2, 3}, Case{4, 16}, Case{4, 11}, Case{64, 4096}, Case{64, 3001}, Case{256, 65536},
                 Case{256, 50001}}) {
    checkCase(c.base, hpRandomCounts(c.base, c.live, {0, 1, 4}, {0.3, 0.5, 0.2}, rng), c.live);
  }
}

TEST_F(HistoPyramidGl, RandomPatternsZeroToFour) {
  std::mt19937 rng(99);
  for (int base : {4, 64, 256}) {
    const std::size_t n = std::size_t(base) * std::size_t(base);
    checkCase(base, hpRandomCounts(base, n, {0, 1, 2, 3, 4}, {2, 2, 1, 1, 1}, rng));
    checkCase(base, hpRandomCounts(base, n * 2 / 3 + 1, {0, 1, 2, 3, 4}, {2, 2, 1, 1, 1}, rng), n * 2 / 3 + 1, true);
  }
}

TEST_F(HistoPyramidGl, SparseAndLargerCounts) {
  std::mt19937 rng(5);
  // Mostly dead, a few larger counts (the pyramid takes any integer count).
  checkCase(128, hpRandomCounts(128, 128 * 128, {0, 1, 4, 7, 16}, {0.95, 0.02, 0.02, 0.005, 0.005}, rng));
}

TEST_F(HistoPyramidGl, AllDead) {
  for (int base : {1, 4, 64, 256}) {
    const std::vector<float> zeros(std::size_t(base) * std::size_t(base), 0.0f);
    checkCase(base, zeros);
    checkCase(base, zeros, 0);  // no live slot at all
  }
}

TEST_F(HistoPyramidGl, AllSplit) {
  for (int base : {1, 4, 64, 256}) {
    const std::size_t n = std::size_t(base) * std::size_t(base);
    const std::vector<float> fours(n, 4.0f);
    checkCase(base, fours);
    if (n > 2) checkCase(base, fours, n - 2);
  }
}

TEST_F(HistoPyramidGl, SingleLivePatchAtTheLastTexel) {
  for (int base : {2, 4, 64, 256}) {
    std::vector<float> counts(std::size_t(base) * std::size_t(base), 0.0f);
    counts.back() = 1.0f;
    checkCase(base, counts);
    counts.back() = 4.0f;
    checkCase(base, counts, HistoPyramidLimits::kAllSlots, true);
  }
}

TEST_F(HistoPyramidGl, CountsOnlyInTheLastRow) {
  std::mt19937 rng(17);
  for (int base : {4, 64, 256}) {
    std::vector<float> counts(std::size_t(base) * std::size_t(base), 0.0f);
    for (int x = 0; x < base; ++x) counts[hpTexelIndex({x, base - 1}, base)] = float(int(rng() % 5));
    checkCase(base, counts);
  }
}

// A longer list leaves its levels behind; a later build with fewer live slots and garbage (NaN)
// beyond them in the counts must ignore all of it.
TEST_F(HistoPyramidGl, StaleDataBeyondTheLiveSlotsIsIgnored) {
  std::mt19937 rng(3);
  const int base = 64;
  const std::size_t n = base * base;
  HistoPyramid pyramid(base, library_);
  const std::vector<float> first = hpRandomCounts(base, n, {0, 1, 4}, {0.2, 0.5, 0.3}, rng);
  gl::Texture2D texture({base, base}, gl::TextureFormat::R32F, first, 1,
                        gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge});
  pyramid.build(texture);
  ASSERT_EQ(pyramid.readTotal(), HistoPyramidCpu(base, first).total());

  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t live : {std::size_t(1000), std::size_t(37), std::size_t(1), std::size_t(0), std::size_t(2049)}) {
    SCOPED_TRACE("live " + std::to_string(live));
    std::vector<float> counts = hpRandomCounts(base, live, {0, 1, 4}, {0.3, 0.5, 0.2}, rng, nan);
    texture.upload(counts, 1);
    pyramid.build(texture, live);
    const HistoPyramidCpu cpu(base, counts, live);
    EXPECT_EQ(pyramid.readTotal(), cpu.total());
    checkLevels(pyramid, cpu, live);
    checkTraversal(pyramid, cpu, false);
  }
}

// The analysis pass renders counts straight into base() through its own framebuffer, then build().
TEST_F(HistoPyramidGl, ProducerRendersIntoTheBase) {
  std::mt19937 rng(11);
  const int base = 128;
  const std::size_t live = 9000;
  const std::vector<float> counts = hpRandomCounts(base, live, {0, 1, 4}, {0.3, 0.5, 0.2}, rng, 4.0f);
  gl::Texture2D source({base, base}, gl::TextureFormat::R32F, counts, 1,
                       gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge});
  HistoPyramid pyramid(base, library_);
  gl::Framebuffer producer({base, base});
  producer.attach(0, pyramid.base());
  producer.checkComplete();
  producer.clear(0, glm::vec4(std::numeric_limits<float>::quiet_NaN()));  // stale garbage beyond the live box
  gl::Program write = library_.program("common/fullscreen.vert", "lightsim/histo_pyramid_test_counts.frag");
  producer.bind();
  const glm::ivec2 box = hpLiveBox(live);
  glViewport(0, 0, box.x, box.y);  // the live box only, as the simulator draws
  source.bind(0);
  write.use();
  write.setSampler("uCounts", 0);
  triangle_.draw();
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  // Bindings and state the caller had are restored by build().
  glEnable(GL_BLEND);
  pyramid.build(live);
  EXPECT_TRUE(glIsEnabled(GL_BLEND));
  glDisable(GL_BLEND);
  GLint program = -1;
  glGetIntegerv(GL_CURRENT_PROGRAM, &program);
  EXPECT_EQ(GLuint(program), write.id());
  const HistoPyramidCpu cpu(base, counts, live);
  EXPECT_EQ(pyramid.readTotal(), cpu.total());
  checkTraversal(pyramid, cpu, true);
}

TEST_F(HistoPyramidGl, RejectsBadSizes) {
  EXPECT_THROW(HistoPyramid(0, library_), InputError);
  EXPECT_THROW(HistoPyramid(48, library_), InputError);
  EXPECT_THROW(HistoPyramid(8192, library_), InputError);
  HistoPyramid pyramid(16, library_);
  EXPECT_EQ(pyramid.levels(), 4);
  EXPECT_EQ(pyramid.capacity(), 256u);
  EXPECT_EQ(pyramid.defines(), (gl::ShaderDefines{{"HP_LEVELS", "4"}}));
  gl::Texture2D wrong({8, 8}, gl::TextureFormat::R32F);
  EXPECT_THROW(pyramid.build(wrong), RuntimeError);
}

// Build (copy + reduction) + total readback, and the traversal pass over the live box of the
// output, on this renderer. Printed, not asserted.
TEST(HistoPyramidTiming, BuildAndTraverse) {
  gl::GlContext context(gl::ContextOptions{.backend = gl::glBackendFromEnvironment(gl::GlBackend::OSMesa), .debug = false});
  gl::ShaderLibrary library;
  gl::FullscreenTriangle triangle;
  std::mt19937 rng(2024);
  for (int base : {512, 1024}) {
    const std::size_t n = std::size_t(base) * std::size_t(base);
    // A list that mostly survives (mean count 0.95), so the output fits the same side.
    const std::vector<float> counts = hpRandomCounts(base, n, {0, 1, 4}, {0.25, 0.7, 0.05}, rng);
    HistoPyramid pyramid(base, library);
    gl::Texture2D texture({base, base}, gl::TextureFormat::R32F, counts, 1,
                          gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge});
    gl::Program program = library.program("common/fullscreen.vert", "lightsim/histo_pyramid_test.frag", pyramid.defines());
    gl::Framebuffer target({base, base}, {gl::TextureFormat::RGBA32F});
    double bestBuild = 1e30, bestBaseBuild = 1e30, bestTraverse = 1e30;
    std::uint64_t total = 0;
    for (int rep = 0; rep < 4; ++rep) {
      glFinish();
      Stopwatch watch;
      pyramid.build(texture);
      total = pyramid.readTotal();
      const double buildMs = watch.restart() * 1e3;
      pyramid.build(texture);
      pyramid.requestTotal();  // the asynchronous readback
      (void)pyramid.waitTotal();
      const double baseBuildMs = watch.restart() * 1e3;
      target.bind();
      const glm::ivec2 box = hpLiveBox(std::min<std::uint64_t>(total, n));
      glViewport(0, 0, box.x, box.y);
      pyramid.bind(0);
      program.use();
      program.setSampler("uPyramid", 0);
      program.set("uTotal", static_cast<int>(total));
      triangle.draw();
      glFinish();
      bestBuild = std::min(bestBuild, buildMs);
      bestBaseBuild = std::min(bestBaseBuild, baseBuildMs);
      bestTraverse = std::min(bestTraverse, watch.milliseconds());
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    std::printf("[ timing ] %s: base %d², total %llu: build + readTotal %.2f ms, build + "
                "requestTotal/waitTotal %.2f ms, traverse (%d levels) %.2f ms\n",
                context.info().renderer.c_str(), base, static_cast<unsigned long long>(total), bestBuild,
                bestBaseBuild, pyramid.levels(), bestTraverse);
    // Spot-check the timed output too.
    const HistoPyramidCpu cpu(base, counts);
    EXPECT_EQ(total, cpu.total());
    const std::vector<float> pixels = target.readRGBA(0);
    for (std::uint64_t k : {std::uint64_t{0}, total / 3, total - 1}) {
      const HistoPyramidEntry e = cpu.find(k);
      const float* got = &pixels[hpTexelIndex(hpSlotTexel(std::uint32_t(k)), base) * 4];
      EXPECT_EQ(got[0], float(e.texel.x));
      EXPECT_EQ(got[1], float(e.texel.y));
      EXPECT_EQ(got[2], float(e.sub));
    }
  }
}

}  // namespace
}  // namespace eik
