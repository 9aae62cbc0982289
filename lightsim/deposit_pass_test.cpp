// Tests of the deposit pass (deposit_pass.h, ALGORITHM.md step 4) on OSMesa/llvmpipe: hand-made
// patches through the analysis pass (which computes each patch's deposit) and the deposit pass into
// the flat-3D atlas, read back as fields: the right voxels, the accumulate sums and directions, and
// the max mode's strongest patch.
#include "lightsim/deposit_pass.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

#include "gl/context.h"
#include "gl/shader_library.h"
#include "gl/volume_textures.h"
#include "lightsim/analysis_pass.h"
#include "lightsim/atlas.h"
#include "lightsim/grid_uniforms.h"
#include "lightsim/patch_textures.h"
#include "lightsim/step_targets.h"
#include "lightsim/step_uniforms.h"
#include "lightsim/test_scenes.h"
#include "lightsim/wavefront.h"

namespace eik {
namespace {

using test_scenes::voxelValue;

// A square patch of edge `edge` centred at `centre`, facing +z (corners counter-clockwise seen
// from −z), in a medium of index n.
Patch squarePatch(glm::dvec3 centre, double edge, glm::dvec3 flux, double n = 1.0) {
  Patch p;
  const double a = 0.5 * edge;
  p.x = {centre + glm::dvec3(-a, -a, 0), centre + glm::dvec3(a, -a, 0), centre + glm::dvec3(a, a, 0),
         centre + glm::dvec3(-a, a, 0)};
  for (auto& w : p.w) w = glm::dvec3(0, 0, n);
  p.flux = flux;
  p.area0 = edge * edge;
  return p;
}

struct DepositFixture {
  gl::GlContext& gl = test_scenes::glContext();  // first: everything below needs it current
  Volume volume;
  gl::ShaderLibrary library;
  gl::VolumeTextures textures;
  AtlasLayout layout;
  gpu::GridUniforms grid;

  explicit DepositFixture(glm::ivec3 dims, double h = 0.1)
      : volume(test_scenes::uniformVolume(test_scenes::boxGrid(dims, h), 1.25)),
        textures(volume),
        layout(AtlasLayout::plan(dims, gl.info().maxTextureSize)),
        grid(gpu::GridUniforms::from(volume.grid)) {}

  // The analysis pass (which computes each patch's deposit) and the deposit pass on `patches` as
  // the updated list, with the same list as the one before the update (so m_old = m).
  void deposit(const std::vector<Patch>& patches, DepositMode mode, float dt, Field& irradiance, Field& dir) {
    std::vector<PatchTexels> packed;
    for (const Patch& p : patches) packed.push_back(packPatch(p));
    const int side = patchSideFor(packed.size(), 2);
    PatchTextures list(side);
    list.upload(packed);
    gpu::StepTargets targets(side, library);
    gpu::StepUniforms step;
    step.dt = dt;
    step.splitLength = 1.0f;
    step.maxDepth = 8.0f;
    gpu::LiveCount live;
    live.set(packed.size());
    gpu::AnalysisPass(library, mode, layout, textures.layout().glslDefines())
        .run(list, list, live, packed.size(), targets, textures, grid, step);
    AtlasTargets atlas(layout, mode);
    gpu::DepositPass(library, layout, mode).run(targets.depositA, targets.depositB, packed.size(), atlas, 1e-3f);
    atlas.toFields(irradiance, dir);
  }
  std::size_t index(glm::ivec3 v) const { return volume.grid.index(v.x, v.y, v.z); }
  glm::dvec3 centre(glm::ivec3 v) const { return volume.grid.center(v.x, v.y, v.z); }
};

TEST(DepositTest, AccumulateLandsInTheRightVoxels) {
  DepositFixture fx({5, 3, 7});  // 7 slices of 5x3: a 3x3 tiling with two empty tiles
  const double n = 1.25, dt = 0.05, V = 0.001;
  const glm::ivec3 a(1, 2, 0), b(4, 0, 6), c(2, 1, 3);
  std::vector<Patch> patches = {
      squarePatch(fx.centre(a), 0.02, {1, 2, 3}, n),
      squarePatch(fx.centre(b) + glm::dvec3(0.03, -0.02, 0.04), 0.02, {0.5, 0.5, 0.5}, n),
      squarePatch(fx.centre(c), 0.02, {2, 0, 1}, n),
      squarePatch(fx.centre(c) + glm::dvec3(0.01, 0.01, -0.01), 0.02, {1, 1, 1}, n),  // same voxel as the last
      squarePatch(glm::dvec3(-0.05, 0.1, 0.1), 0.02, {9, 9, 9}, n),                   // outside: no deposit
  };
  patches[2].w = {glm::dvec3(n, 0, 0), glm::dvec3(n, 0, 0), glm::dvec3(n, 0, 0), glm::dvec3(n, 0, 0)};  // along +x
  Field e, d;
  fx.deposit(patches, DepositMode::Accumulate, static_cast<float>(dt), e, d);
  const double ds = dt / n;  // Δs_m = Δt / n(m)
  auto expectNear = [](glm::dvec3 got, glm::dvec3 want, const char* what) {
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(got[i], want[i], 1e-4 * (1.0 + std::fabs(want[i]))) << what << " [" << i << "]";
  };
  expectNear(voxelValue(e, fx.index(a)), glm::dvec3(1, 2, 3) * ds / V, "irradiance a");
  expectNear(voxelValue(d, fx.index(a)), glm::dvec3(0, 0, 1), "dir a");
  expectNear(voxelValue(e, fx.index(b)), glm::dvec3(0.5) * ds / V, "irradiance b");
  expectNear(voxelValue(e, fx.index(c)), glm::dvec3(3, 1, 2) * ds / V, "irradiance c (two patches)");
  // Direction sum lum(Φ)·Δs·d: (1·(1,0,0) + 1·(0,0,1)) normalised.
  expectNear(voxelValue(d, fx.index(c)), glm::normalize(glm::dvec3(1, 0, 1)), "dir c");
  // Nothing else anywhere.
  double rest = 0.0;
  for (std::size_t i = 0; i < fx.volume.grid.count(); ++i) {
    if (i == fx.index(a) || i == fx.index(b) || i == fx.index(c)) continue;
    rest += glm::length(voxelValue(e, i)) + glm::length(voxelValue(d, i));
  }
  EXPECT_EQ(rest, 0.0);
}

TEST(DepositTest, MaxKeepsTheStrongestPatch) {
  DepositFixture fx({4, 6, 3});
  const glm::ivec3 v(2, 3, 1);
  // E = Φ/A: 1/0.0004 = 2500 for the first, (2,2,2)/0.0009 ≈ 2222 for the second, 6/0.0001 for the
  // third (green only) — the strongest by lum(E) = (r+g+b)/3.
  std::vector<Patch> patches = {
      squarePatch(fx.centre(v), 0.02, {1, 1, 1}), squarePatch(fx.centre(v) + glm::dvec3(0.01, 0, 0), 0.03, {2, 2, 2}),
      squarePatch(fx.centre(v) + glm::dvec3(0, 0.01, 0.01), 0.01, {0, 6, 0}),
      squarePatch(fx.centre({0, 0, 0}), 0.02, {0, 0, 0}),  // E = 0 still records its direction
  };
  patches[2].w = {glm::dvec3(0, 1, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 1, 0)};
  Field e, d;
  fx.deposit(patches, DepositMode::Max, 0.05f, e, d);
  const glm::dvec3 got = voxelValue(e, fx.index(v));
  EXPECT_NEAR(got.x, 0.0, 1e-3);
  EXPECT_NEAR(got.y, 6.0 / 0.0001, 1.0);
  EXPECT_NEAR(got.z, 0.0, 1e-3);
  EXPECT_NEAR(voxelValue(d, fx.index(v)).y, 1.0, 1e-6);
  EXPECT_EQ(voxelValue(e, fx.index({0, 0, 0})), glm::dvec3(0.0));
  EXPECT_NEAR(voxelValue(d, fx.index({0, 0, 0})).z, 1.0, 1e-6);
}

}  // namespace
}  // namespace eik
