// Tests of the ledger pass (ledger_pass.h, the energy ledger of ALGORITHM.md "Bake output") on
// OSMesa/llvmpipe: the entries of one step of a list taken mid-flight through an absorbing glass
// sphere (GPU update and analysis), summed on the GPU and read back, against the CPU twin's sums
// over stepPatch's results: flux absorbed, reflected, exited and killed, the counts, the splits and
// the unfinished flux; and rows folded in by flush() whenever they are full.
#include "lightsim/ledger_pass.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include "lightsim/cpu_simulator.h"
#include "lightsim/test_scenes.h"
#include "lightsim/wavefront.h"

namespace eik {
namespace {

TEST(LedgerPassTest, OneStepSumsTheCpuTwinsLedger) {
  test_scenes::MidFlightList list;
  // The twin's ledger of one step (CpuSimulator::run): the sums over the results, dead patches
  // with their flux after the update.
  glm::dvec3 absorbed(0.0), reflected(0.0), exited(0.0), killed(0.0), trapped(0.0), updated(0.0);
  double exits = 0.0, kills = 0.0, traps = 0.0, splits = 0.0;
  for (Patch p : list.patches) {
    const PatchStepResult r = stepPatch(p, list.ctx);
    absorbed += r.absorbed;
    reflected += r.reflected;
    updated += p.flux;
    if (r.fate == PatchFate::Exited) {
      exited += p.flux;
      exits += 1.0;
    }
    if (r.fate == PatchFate::KilledFlux || r.fate == PatchFate::Folded || r.fate == PatchFate::KilledDepth) {
      killed += p.flux;
      kills += 1.0;
    }
    if (r.fate == PatchFate::Trapped) {  // unfinished light
      trapped += p.flux;
      traps += 1.0;
    }
    if (r.fate == PatchFate::Split) splits += 1.0;
  }

  test_scenes::GpuStep passes(list);
  passes.update(list.options.integrator);
  passes.analyse(list.options.deposit);
  const std::size_t count = passes.count;

  // Two rows: the third add finds them full and folds them into the sums first.
  gpu::LedgerPass ledger(passes.library, 2);
  ledger.reset();
  ledger.addStep(passes.targets, passes.b, count);
  EXPECT_FALSE(ledger.full());
  ledger.addStep(passes.targets, passes.b, count);
  EXPECT_TRUE(ledger.full());
  ledger.addUnfinished(passes.b, count);
  ledger.flush();
  EXPECT_FALSE(ledger.full());

  const double in = glm::length(updated);
  auto expectSum = [&](gpu::LedgerColumn column, const glm::dvec3& want, double wantCount, const char* what) {
    const glm::dvec4 got = ledger.sum(column);
    std::printf("%-10s GPU (%.6f, %.6f, %.6f; %.0f), CPU (%.6f, %.6f, %.6f; %.0f)\n", what, got.x, got.y, got.z, got.w,
                want.x, want.y, want.z, wantCount);
    EXPECT_LT(glm::length(glm::dvec3(got) - want) / in, 1e-5) << what;
    EXPECT_EQ(got.w, wantCount) << what;
  };
  // The step was added twice.
  expectSum(gpu::kAbsorbed, 2.0 * absorbed, 0.0, "absorbed");
  EXPECT_LT(glm::length(glm::dvec3(ledger.sum(gpu::kReflected)) - 2.0 * reflected) / in, 1e-5);
  expectSum(gpu::kExited, 2.0 * exited, 2.0 * exits, "exited");
  const glm::dvec4 gpuKilled = ledger.sum(gpu::kKilledFlux) + ledger.sum(gpu::kFolded) + ledger.sum(gpu::kKilledDepth);
  EXPECT_LT(glm::length(glm::dvec3(gpuKilled) - 2.0 * killed) / in, 1e-5);
  EXPECT_EQ(gpuKilled.w, 2.0 * kills);
  EXPECT_EQ(ledger.sum(gpu::kSplits).w, 2.0 * splits);
  EXPECT_GT(splits, 0.0);
  // The trapped patches of both steps, and the list added as unfinished at the end.
  expectSum(gpu::kUnfinished, updated + 2.0 * trapped, static_cast<double>(count) + 2.0 * traps, "unfinished");

  // reset() forgets everything.
  ledger.reset();
  ledger.flush();
  for (int c = 0; c < gpu::kLedgerColumns; ++c)
    EXPECT_EQ(ledger.sum(static_cast<gpu::LedgerColumn>(c)), glm::dvec4(0.0));
}

}  // namespace
}  // namespace eik
