// The CPU twin of the GPU light simulator (lightsim/ALGORITHM.md, step for step; thesis §6.2).
// It is the reference the GPU path is tested against and the fallback without OpenGL.
//
// Multi-threaded (parallelFor, EIKONAL_THREADS) and deterministic: the same input gives the same
// bits whatever the thread count. Each patch's update, absorption, Fresnel and analysis is a pure
// function of that patch and runs in parallel; everything that combines patches runs in patch
// order: the deposit into the volume (in double precision), the energy ledger sums and the prefix
// sum that compacts and expands the patch list (the CPU form of the histogram pyramid, which gives
// the same order).
#pragma once

#include <span>

#include "core/volume.h"
#include "lightsim/simulator.h"
#include "lightsim/wavefront.h"

namespace eik {

// A diagnostic of the CPU twin: the flux that patch midpoints carry across the plane
// x[axis] = coordinate, counted once per crossing with the patch's flux after that step. Exact
// (no voxel sampling), so tests can check the deposit-free energy flow; see test_scenes.h for the
// bake-level measure.
struct PlaneFluxProbe {
  int axis = 1;                        // 0: x, 1: y, 2: z
  double coordinate = 0.0;
  glm::dvec3 to_positive{0.0};         // crossed towards +axis (W, RGB)
  glm::dvec3 to_negative{0.0};         // crossed towards −axis
};

class CpuSimulator : public Simulator {
 public:
  // Copies what it needs of the volume (n, ∇n, σa; see VolumeSampler): the volume may go away.
  // Throws InputError when `ior` or `ior_grad` is missing or malformed.
  explicit CpuSimulator(const Volume& volume);

  // Runs one bake. Throws InputError for a bad light or bad options (validateOptions). A light that
  // misses the volume gives all-zero fields and stats.initial_patches = 0 (lightMissedVolume).
  BakeResult run(const LightSpec& light, const SimulationOptions& options) override;
  // The same, also filling the probes (their flux sums are reset first).
  BakeResult run(const LightSpec& light, const SimulationOptions& options, std::span<PlaneFluxProbe> probes);

  const VolumeSampler& sampler() const { return sampler_; }

 private:
  VolumeSampler sampler_;
};

// One step of one patch in place: ALGORITHM.md steps 1–5 (update, absorption, Fresnel, deposit
// record, analysis). Exposed so that tests and the GPU path can check single steps.
enum class PatchFate { Keep, Split, KilledFlux, Exited, Folded, KilledDepth };

struct PatchStepResult {
  PatchFate fate = PatchFate::Keep;
  long long voxel = -1;            // voxel the deposit goes to (−1: the midpoint is outside the grid)
  glm::dvec3 deposit{0.0};         // accumulate: Φ·Δs_m/V_voxel; max: E = Φ/A
  glm::dvec3 deposit_dir{0.0};     // accumulate: lum(Φ)·Δs_m·d; max: d
  double max_key = 0.0;            // max: lum(E)
  glm::dvec3 absorbed{0.0};        // Φ·(1 − exp(−σa·Δs_m))
  glm::dvec3 reflected{0.0};       // R·Φ on leaving a boundary layer
  glm::dvec3 old_midpoint{0.0};    // m before the step
};

struct StepContext {
  const VolumeSampler* sampler = nullptr;
  const SimulationOptions* options = nullptr;
  double dt = 0.0;           // Δt
  double flux_ref = 0.0;     // Φ_ref
  double voxel_volume = 0.0;
};

PatchStepResult stepPatch(Patch& patch, const StepContext& context);

// The integrators of step 1 on the right-hand side (w/n², ∇n/n) (Eq. 4.12/4.13; Euler is
// Eq. 6.1/6.2), followed by the renormalisation |w| = n(x_new).
void advanceCorner(glm::dvec3& x, glm::dvec3& w, double dt, Integrator integrator, const VolumeSampler& sampler);

}  // namespace eik
