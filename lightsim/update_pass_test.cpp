// Tests of the update pass (update_pass.h, ALGORITHM.md steps 1–3) on OSMesa/llvmpipe: one update of
// a list taken mid-flight through an absorbing glass sphere against the CPU twin's stepPatch (whose
// steps 4 and 5 leave the patch as steps 1–3 made it), patch for patch in list order, to float
// rounding: corners, directions, flux after absorption and Fresnel, and the boundary tracking.
#include "lightsim/update_pass.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <vector>

#include "lightsim/cpu_simulator.h"
#include "lightsim/patch_textures.h"
#include "lightsim/test_scenes.h"
#include "lightsim/wavefront.h"

namespace eik {
namespace {

void expectOneUpdateMatchesTheCpuTwin(Integrator integrator) {
  test_scenes::MidFlightList list;
  list.options.integrator = integrator;
  std::vector<Patch> want = list.patches;
  int entered = 0, left = 0;
  for (Patch& p : want) {
    const bool wasInLayer = p.n_in != 0.0;
    stepPatch(p, list.ctx);
    entered += !wasInLayer && p.n_in != 0.0 ? 1 : 0;
    left += wasInLayer && p.n_in == 0.0 ? 1 : 0;
  }

  test_scenes::GpuStep passes(list);
  passes.update(integrator);
  const std::size_t count = passes.count;
  const std::vector<PatchTexels> got = passes.b.download(count);

  double worstX = 0.0, worstW = 0.0, worstFlux = 0.0;
  const double slack = test_scenes::gpuArithmeticSlack();
  for (std::size_t k = 0; k < count; ++k) {
    const Patch g = unpackPatch(got[k]);
    const Patch& c = want[k];
    for (int i = 0; i < 4; ++i) {
      worstX = std::max(worstX, glm::length(g.x[i] - c.x[i]) / voxelEdge(list.volume.grid));
      worstW = std::max(worstW, glm::length(g.w[i] - c.w[i]));
    }
    worstFlux = std::max(worstFlux, glm::length(g.flux - c.flux) / glm::length(c.flux));
    ASSERT_EQ(g.depth, c.depth) << k;
    EXPECT_NEAR(g.n_in, c.n_in, 1e-4 * slack) << k;
    EXPECT_NEAR(g.cos_in, c.cos_in, 1e-4 * slack) << k;  // NVIDIA: 3.6e-4 at a grazing cos 0.016
    EXPECT_NEAR(g.t_fresnel, c.t_fresnel, 1e-4 * slack) << k;
    EXPECT_NEAR(g.area0, c.area0, (1e-5 * c.area0 + 1e-12) * slack) << k;
  }
  std::printf(
      "%zu patches, %d entered and %d left a boundary layer; worst |Δx| %.2e voxel, |Δw| %.2e, flux "
      "%.2e relative\n",
      count, entered, left, worstX, worstW, worstFlux);
  EXPECT_GT(entered + left, 0);
  // llvmpipe's bounds; NVIDIA: |Δx| 3.5e-4 voxel, |Δw| 9.3e-4, flux 7.4e-5 (gpuArithmeticSlack).
  EXPECT_LT(worstX, 1e-4 * slack);
  EXPECT_LT(worstW, 1e-4 * slack);
  EXPECT_LT(worstFlux, 1e-4 * slack);
}

TEST(UpdatePassTest, EulerStepMatchesTheCpuTwinPatchForPatch) { expectOneUpdateMatchesTheCpuTwin(Integrator::Euler); }

TEST(UpdatePassTest, Rk4StepMatchesTheCpuTwinPatchForPatch) { expectOneUpdateMatchesTheCpuTwin(Integrator::RK4); }

}  // namespace
}  // namespace eik
