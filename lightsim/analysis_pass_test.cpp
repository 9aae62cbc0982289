// Tests of the analysis pass (analysis_pass.h, ALGORITHM.md step 5 and the per-patch work of steps
// 2–4) on OSMesa/llvmpipe: a list taken mid-flight through an absorbing glass sphere, updated on the
// GPU, then analysed, against the CPU twin's stepPatch patch by patch: the output counts (the
// pyramid's base) exactly, and the fates, deposit voxels and ledger entries.
#include "lightsim/analysis_pass.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <vector>

#include "lightsim/atlas.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/patch_textures.h"
#include "lightsim/step_targets.h"
#include "lightsim/test_scenes.h"
#include "lightsim/wavefront.h"

namespace eik {
namespace {

// The fate code of shaders/lightsim/fate_codes.glsl for the twin's result.
int fateCode(const PatchStepResult& r) {
  switch (r.fate) {
    case PatchFate::Keep: return 1;
    case PatchFate::Split: return r.split.u && r.split.v ? 2 : r.split.u ? 3 : 4;
    case PatchFate::Exited: return 5;
    case PatchFate::KilledFlux: return 6;
    case PatchFate::Folded: return 7;
    case PatchFate::KilledDepth: return 8;
    case PatchFate::Received: return 9;
    case PatchFate::Blocked: return 10;
    case PatchFate::Trapped: return 11;
  }
  return 0;
}

// Voxel (i, j, k) of a flat index (GridSpec::index).
glm::ivec3 voxelOf(long long index, glm::ivec3 dims) {
  const long long i = index % dims.x, j = index / dims.x % dims.y,
                  k = index / (static_cast<long long>(dims.x) * dims.y);
  return {static_cast<int>(i), static_cast<int>(j), static_cast<int>(k)};
}

float outputCount(const PatchStepResult& r) {
  return r.fate == PatchFate::Keep ? 1.0f : r.fate == PatchFate::Split ? static_cast<float>(r.split.count()) : 0.0f;
}

void expectAnalysisMatchesTheCpuTwin(DepositMode mode) {
  test_scenes::MidFlightList list;
  list.options.deposit = mode;
  std::vector<PatchStepResult> want;
  for (Patch p : list.patches) want.push_back(stepPatch(p, list.ctx));

  test_scenes::GpuStep passes(list);
  passes.update(list.options.integrator);
  passes.analyse(mode);
  const std::size_t count = passes.count;
  const int side = passes.a.side();
  const AtlasLayout& atlas = passes.atlas;
  const gpu::StepTargets& targets = passes.targets;
  const std::vector<float> counts = targets.pyramid.base().download(1);
  const std::vector<float> depositA = targets.depositA.download(4), depositB = targets.depositB.download(4);
  const std::vector<float> ledgerA = targets.ledgerA.download(4), ledgerB = targets.ledgerB.download(4);

  int fatesOff = 0, voxelsOff = 0, splits = 0, dead = 0;
  double worstAbsorbed = 0.0, worstReflected = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const glm::ivec2 t = mortonTexel(static_cast<std::uint32_t>(k));
    const std::size_t texel =
        static_cast<std::size_t>(t.y) * static_cast<std::size_t>(side) + static_cast<std::size_t>(t.x);
    const PatchStepResult& r = want[k];
    ASSERT_EQ(counts[texel], outputCount(r)) << k;
    fatesOff += static_cast<int>(ledgerA[texel * 4 + 3]) != fateCode(r) ? 1 : 0;
    splits += r.fate == PatchFate::Split ? 1 : 0;
    dead += outputCount(r) == 0.0f ? 1 : 0;
    // Deposit: the atlas texel of the voxel of the new midpoint (x < 0: none).
    const glm::ivec2 wantTexel = r.voxel >= 0 ? atlas.texel(voxelOf(r.voxel, list.volume.grid.dims)) : glm::ivec2(-1);
    const float* dA = &depositA[texel * 4];
    const float* dB = &depositB[texel * 4];
    const glm::ivec2 gotTexel =
        dA[3] < 0.0f ? glm::ivec2(-1) : glm::ivec2(static_cast<int>(dA[3]), static_cast<int>(dB[3]));
    voxelsOff += gotTexel != wantTexel ? 1 : 0;
    // Ledger entries: flux absorbed (step 2) and reflected (step 3), relative to the patch's flux.
    const double flux = glm::length(list.patches[k].flux);
    const glm::dvec3 absorbed(ledgerA[texel * 4], ledgerA[texel * 4 + 1], ledgerA[texel * 4 + 2]);
    const glm::dvec3 reflected(ledgerB[texel * 4], ledgerB[texel * 4 + 1], ledgerB[texel * 4 + 2]);
    worstAbsorbed = std::max(worstAbsorbed, glm::length(absorbed - r.absorbed) / flux);
    worstReflected = std::max(worstReflected, glm::length(reflected - r.reflected) / flux);
  }
  std::printf(
      "%zu patches, %d splits, %d dead; %d fates and %d deposit voxels differ; worst ledger error "
      "(of the patch flux): absorbed %.2e, reflected %.2e\n",
      count, splits, dead, fatesOff, voxelsOff, worstAbsorbed, worstReflected);
  EXPECT_GT(splits, 0);
  // Float (GPU) and double (CPU) may take a different one of two deaths, or put a midpoint on a
  // voxel face into the other voxel: rarely.
  EXPECT_LE(fatesOff, static_cast<int>(count / 1000));
  EXPECT_LE(voxelsOff, static_cast<int>(count / 1000));
  // 1e-5 of the patch's flux on llvmpipe; NVIDIA's float arithmetic: 7.4e-5 (absorbed).
  EXPECT_LT(worstAbsorbed, 1e-5 * test_scenes::gpuArithmeticSlack());
  EXPECT_LT(worstReflected, 1e-5 * test_scenes::gpuArithmeticSlack());
}

TEST(AnalysisPassTest, AccumulateModeMatchesTheCpuTwinPatchForPatch) {
  expectAnalysisMatchesTheCpuTwin(DepositMode::Accumulate);
}

TEST(AnalysisPassTest, MaxModeMatchesTheCpuTwinPatchForPatch) { expectAnalysisMatchesTheCpuTwin(DepositMode::Max); }

}  // namespace
}  // namespace eik
