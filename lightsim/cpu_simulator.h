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

#include <array>
#include <memory>

#include "core/volume.h"
#include "lightsim/simulator.h"
#include "lightsim/wavefront.h"

namespace eik {

// Diagnostics of the CPU twin that SimulationStats does not carry.
struct CpuRunDiagnostics {
  // The flux carried out of the grid by exiting patches, by the face they left through
  // (exitFace): 0: −x, 1: +x, 2: −y, 3: +y, 4: −z, 5: +z (W, RGB). Sums to stats.flux_out.
  std::array<glm::dvec3, 6> flux_out_by_face{};
};

// The face of the grid box a patch at midpoint m (outside the box) heading along d left through:
// the face where the backward ray m − t·d enters the box, or, if that ray misses it (a path bent
// outside the box), the face the point lies farthest beyond (relative to the box's extent).
int exitFace(const glm::dvec3& m, const glm::dvec3& d, const GridSpec& grid);

class CpuSimulator : public Simulator {
 public:
  // Copies what it needs of the volume (n, ∇n, σa; see VolumeSampler): the volume may go away.
  // Throws InputError when `ior` or `ior_grad` is missing or malformed.
  explicit CpuSimulator(const Volume& volume);
  // The same, taking the `interfaces` field's data where the sampler keeps it as it is
  // (VolumeSampler(const Volume&, std::vector<float>*)); null: copies it.
  CpuSimulator(const Volume& volume, std::vector<float>* interfaces_data);

  // Runs one bake. Throws InputError for a bad light or bad options (validateOptions). A light that
  // misses the volume gives all-zero fields and stats.initial_patches = 0 (lightMissedVolume).
  BakeResult run(const LightSpec& light, const SimulationOptions& options) override;
  // The same, also filling `diagnostics` (when not null).
  BakeResult run(const LightSpec& light, const SimulationOptions& options, CpuRunDiagnostics* diagnostics);

  const VolumeSampler& sampler() const { return sampler_; }

 private:
  VolumeSampler sampler_;
  QuietMap quiet_;  // built by the first run with free flight
  QuietMap absorbers_;  // built by the first run with straight steps in a volume with absorption
};

// One step of one patch in place: ALGORITHM.md steps 1–5 (update, absorption, Fresnel, deposit
// record, analysis). Exposed so that tests and the GPU path can check single steps.
// Trapped: more than kMaxTotalReflections total internal reflections (its flux is unfinished light).
enum class PatchFate { Keep, Split, KilledFlux, Exited, Folded, KilledDepth, Received, Blocked, Trapped };

struct PatchStepResult {
  PatchFate fate = PatchFate::Keep;
  SplitAxes split;                 // the axes a Split halves
  // Point kernel and `max` mode: one deposit at the voxel of the new midpoint.
  long long voxel = -1;            // voxel the deposit goes to (−1: the midpoint is outside the grid)
  glm::dvec3 deposit{0.0};         // accumulate: Φ·Δs_m/V_voxel; max: E = Φ/A
  glm::dvec3 deposit_dir{0.0};     // accumulate: lum(Φ)·Δs_m·d; max: d
  double max_key = 0.0;            // max: lum(E)
  // Track kernel (track_deposit.h): the sub-paths from the old corners to the new ones, each
  // carrying track_flux/(lattice.x·lattice.y), clipped at the receiver plane when the patch reached it.
  // Along the step the flux goes from track_start to track_end, geometrically (exp(−σa s) in one
  // material; applyTrackDeposits), track_flux being their mean, which sets the lattice.
  bool track = false;
  std::array<glm::dvec3, 4> from{};
  glm::dvec3 track_flux{0.0};
  glm::dvec3 track_start{0.0}, track_end{0.0};
  glm::ivec2 lattice{1, 1};
  bool clip_to_receiver = false;
  glm::dvec3 absorbed{0.0};        // Φ·(1 − exp(−σa·Δs_m))
  glm::dvec3 reflected{0.0};       // R·Φ at a boundary layer or a sharp interface, not followed
  // Received: the footprint on the receiver plane ((u, v) coordinates) and the flux it carries.
  std::array<glm::dvec2, 4> footprint{};
  glm::dvec3 received{0.0};
  // Sharp interfaces: the step was undone so that the patch splits before it crosses
  // (ALGORITHM.md "Sharp interfaces"), and the reflected wavefront to follow (bounces).
  bool rolled_back = false;
  bool flight = false;             // a free flight (longer than Δt, straight)
  bool spawn_reflection = false;
  std::unique_ptr<Patch> reflection;  // spawn_reflection: the reflected wavefront (none otherwise)
};

struct StepContext {
  const VolumeSampler* sampler = nullptr;
  const SimulationOptions* options = nullptr;
  double dt = 0.0;           // Δt
  // Straight steps (SimulationOptions::straight_step_voxels): the time of an ordinary step when they
  // apply to the run (straightSteps), else Δt.
  double step_dt = 0.0;
  // …that of a reflected wavefront (bounce ≥ 1), kReflectedStepFactor times a straight step's where
  // they apply and no absorber map decides (wavefront.h), else step_dt; it is not retaken.
  double reflected_step_dt = 0.0;
  // …and, in a volume with absorption, the voxels that absorb (a straight step is taken only where
  // its reach, straight_reach world units around the corners, has σa = 0); none: Δt there.
  const QuietMap* absorbers = nullptr;
  double straight_reach = 0.0;
  // …and with volume deposits, a straight step in which a corner met an interface is retaken as a
  // step of Δt: a track deposit follows the step's chord, which is the ray only where none did.
  bool retake_at_interfaces = false;
  double flux_ref = 0.0;     // Φ_ref
  // Track deposits: patch-steps under this irradiance take the dim light's sub-path lattice
  // (track_deposit.h trackSpacing; kDimTrackFraction of brightestIrradiance). 0: none does.
  double dim_irradiance = 0.0;
  double voxel_volume = 0.0;
  glm::dvec3 box_lo{0.0}, box_hi{0.0};  // propagationBox
  const ReceiverMap* receiver = nullptr; // the receiver's geometry (no data), or none
  bool torn_light_to_receiver = false;   // tornLightPassesToReceiver (with a receiver)
  // Free flight (SimulationOptions::free_flight): the quiet bricks, or none (steps of Δt only), and
  // the longest flight (world units: the propagation box's diagonal).
  const QuietMap* quiet = nullptr;
  double flight_cap = 0.0;
};

// Whether straight steps apply to a run (SimulationOptions::straight_step_voxels): a sharp volume
// whose materials all have a constant n (none graded) and the option above Δt. With absorption,
// only steps whose reach has σa = 0 (StepContext::absorbers); with volume deposits, only steps in
// which no corner meets an interface (StepContext::retake_at_interfaces).
bool straightSteps(const VolumeSampler& sampler, const SimulationOptions& options);

// The constants of a run: Δt, the voxel volume, the propagation box (no receiver).
StepContext makeStepContext(const VolumeSampler& sampler, const SimulationOptions& options, double flux_ref);
// Whether a patch torn at the depth limit gives the receiver the light its corners carry past the
// object (ALGORITHM.md "Sharp interfaces"; stepPatch's passingShare, analysis.frag's): with a
// receiver, not in a scene's chain of boxes (on_leave: that light may meet another object), and
// not where σa is a field only or the air holds smoke (the air may absorb along the way).
bool tornLightPassesToReceiver(const VolumeSampler& sampler, const SimulationOptions& options);

PatchStepResult stepPatch(Patch& patch, const StepContext& context);

// What the CPU twin carries from one step to the next so as not to sample the same points twice:
// iorAndGradient at the four corners and n at the midpoint (the values at the end of a step are
// those at the start of the next). Caching changes no bit of the result.
struct PatchSamples {
  std::array<glm::dvec4, 4> corner{};
  double n_mid = 1.0;
};
PatchSamples samplePatch(const Patch& patch, const VolumeSampler& sampler);
// stepPatch with the samples at the patch's current corners and midpoint; updates them.
PatchStepResult stepPatch(Patch& patch, PatchSamples& samples, const StepContext& context);

// The integrators of step 1 on the right-hand side (w/n², ∇n/n) (Eq. 4.12/4.13; Euler is
// Eq. 6.1/6.2), followed by the renormalisation |w| = n(x_new). `sample` holds iorAndGradient(x)
// on entry and iorAndGradient(x_new) on return.
void advanceCorner(glm::dvec3& x, glm::dvec3& w, glm::dvec4& sample, double dt, Integrator integrator,
                   const VolumeSampler& sampler);

}  // namespace eik
