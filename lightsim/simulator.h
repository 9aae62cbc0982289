// The wavefront light simulator (thesis §4.2, §6.2; lightsim/ALGORITHM.md is the specification):
// one interface, two back ends that are siblings — the GPU particle system (OpenGL 3.3 fragment
// shaders, gpu_simulator.h) and its CPU twin (cpu_simulator.h), which the tests use to check the
// GPU path and which serves as a fallback. makeSimulator (make_simulator.h) picks one.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/grid.h"
#include "core/progress.h"
#include "core/receiver_map.h"
#include "core/volume.h"

namespace eik {

struct Patch;          // lightsim/wavefront.h
class VolumeSampler;   // lightsim/wavefront.h

struct LightSpec {
  enum class Type { Directional, Point, Spot };
  Type type = Type::Directional;
  glm::dvec3 direction{0.0, -1.0, 0.0};  // directional: unit direction the light travels; spot: its axis
  glm::dvec3 position{0.0};              // point, spot
  // Directional: irradiance on a plane facing the light (W/m², RGB). Point: radiant intensity
  // (W/sr, RGB); spot: on its axis. docs/programs.md --power.
  glm::dvec3 power{1.0};
  double inner_cone_deg = 0.0, outer_cone_deg = 45.0;  // spot: its cone (core/scene.h spotAttenuation)
  // Directional: the disc's angular diameter (soft shadows). A run takes the light as a point at
  // infinity; a bake samples the disc (lightsim/sun_disc.h) and sums the runs.
  double angular_diameter_deg = 0.0;
  // Point, spot: the radius of the ball that shines (soft shadows); a run takes the light as a
  // point; a bake samples the ball (lightsim/sun_disc.h) and sums the runs.
  double radius = 0.0;
  nlohmann::json toJson() const;         // as a SCENE.json light
  // The fraction of `power` a point or spot light sends along the unit direction `dir` (1 but off
  // a spot's axis).
  double attenuation(const glm::dvec3& dir) const;
};

enum class DepositMode { Accumulate, Max };
enum class Integrator { Euler, RK2, RK4 };
// How a patch with an edge over the split length is divided (ALGORITHM.md step 5, wavefront.h).
enum class SplitRule { Quad, Axis };
// What becomes of a patch that should split beyond max_depth (ALGORITHM.md step 5).
enum class DepthLimit { Keep, Kill };

// How an `accumulate` deposit is spread (ALGORITHM.md step 4):
//  - Track: the flux times the path length of each sub-path of the patch (lattice ≤ ½ voxel), with
//    the trilinear hat of each voxel, exactly along the path (lightsim/track_deposit.h): flux-exact,
//    flat in free air at any angle. The CPU twin's default.
//  - Point: all of Φ·Δs/V at the voxel of the patch's midpoint (the first release; the GPU path).
enum class DepositKernel { Track, Point };

// A receiver plane (lightsim/receiver.h): the ground, with its own map of planar irradiance.
struct ReceiverSpec {
  std::string name = "ground";
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0, 1.0, 0.0};  // unit, facing the light
  double half_extent = 1e30;         // the plane is the square of this half side around `point`
  double pitch_voxels = 0.25;        // texel edge in voxels of the volume
};

struct SimulationOptions {
  DepositMode deposit = DepositMode::Accumulate;
  DepositKernel deposit_kernel = DepositKernel::Track;
  std::optional<ReceiverSpec> receiver;  // the plane that stops the light and gets a map
  // The receiver map's lattice (receiver.h ReceiverMap without irradiance) instead of the one
  // receiverGeometry makes for this light: runs whose maps are summed (a soft sun's directions,
  // spectral bands) share one lattice.
  std::optional<ReceiverMap> receiver_geometry;
  // A directional light's light that meets the receiver's map without meeting the box is put on
  // the map in closed form (directMapLight, receiver.h) instead of as patches that go straight
  // to it; the map is the same to rounding. Off: every such cell is a patch (the tests' reference).
  bool direct_receiver_light = true;
  // Fresnel reflections at sharp interfaces followed as their own wavefronts (0: none; their flux
  // is counted as reflected).
  int bounces = 1;
  Integrator integrator = Integrator::Euler;
  double step_voxels = 0.5;       // Δt = step_voxels·h: the arc length per step in air, in voxels
  double patch_voxels = 1.0;      // initial patch edge, at most this many voxels
  double split_voxels = 1.0;      // split a patch whose longest edge exceeds this many voxels (volumeDefaults)
  SplitRule split_rule = SplitRule::Axis;  // Axis: halve only the long direction (1×2); Quad: 2×2 (thesis)
  // Splits allowed per initial patch (a 1×2 split counts ½). `lightsim` takes 4 for a volume with
  // sharp interfaces (measured on the glass sphere: more accurate on the ground and 5–7× faster
  // than 6, whose extra slivers only tear at the silhouette) and 6 for a smoothed one (volumeDefaults).
  int max_depth = 6;
  // At max_depth a patch that should split is kept unsplit (Keep, default: its flux goes on and is
  // deposited at its midpoint) or killed (Kill, the thesis §6.2.4; its flux is lost).
  DepthLimit at_max_depth = DepthLimit::Keep;
  double flux_threshold = 1e-4;   // kill below this fraction of the largest initial patch flux / 4^depth
  int max_steps = 0;              // 0: 4 × the grid diagonal in steps
  // Free flight (ALGORITHM.md "Free flight"): a patch whose swept box is quiet (quiet_map.h) takes
  // one straight step across it instead of steps of Δt. Needs the track kernel (accumulate);
  // ignored otherwise. With volume deposits the GPU path flies only as far as its track deposit
  // pass reaches (shaders/lightsim/flight.glsl). `lightsim` turns it on (--free-flight); off here so that the
  // twin and the GPU path compare step for step.
  bool free_flight = false;
  // Straight steps (ALGORITHM.md "Straight steps"): in a sharp volume whose materials all have a
  // constant n, with no volume deposits, every corner's ray is straight between interfaces and
  // crosses them exactly, so an ordinary step may be this many voxels instead of step_voxels where
  // nothing absorbs within its reach; only where patches split and tear depends on it. 0 (or ≤
  // step_voxels): off. Both back ends; `lightsim` sets 2 (--straight-step), off here so that the
  // back ends compare step for step.
  double straight_step_voxels = 0.0;
  // Merged straight steps (ALGORITHM.md "Free flight"): where free flight and straight steps both
  // apply, a patch the quiet map will not let fly looks at its next straight steps' ends and takes
  // the ones in which no corner meets an interface as one step: the corners' paths are the same,
  // in fewer patch-steps (half at the 128³ sphere over a floor). Both back ends (the GPU path's
  // flight.glsl mergedStepsTime); off: one straight step at a time.
  bool merge_straight_steps = true;
  // Volume deposits (ALGORITHM.md step 4): the bake's `irradiance` and `light_dir` fields. Off, a
  // bake makes only the receiver's map (and the statistics): the deposits, most of a glass
  // object's bake, are left out where nothing reads them (`lightsim --volume-deposits auto`,
  // viewerReadsVolumeLight in bake.h), and BakeResult's fields are empty.
  bool volume_deposits = true;
  double boundary_on = 0.02;      // |∇n|·h entering a boundary layer (Fresnel tracking)
  double boundary_off = 0.01;     // |∇n|·h leaving it
  ProgressFn progress;            // fraction of the entering flux retired (dead or exited)
  // Set by another thread (the viewer window's background re-bake, viewer/background_bake.h): the
  // run stops at its next step and throws BakeCancelled. Null: never cancelled.
  const std::atomic<bool>* cancel = nullptr;
  // Light from object to object (a scene's bake, lightsim/scene_bake.h "SceneLightChain"):
  //  - initial_patches, when set, is given the initial patches once they are made (and the direct
  //    light is on the receiver's map) and may take some away (those an earlier object shades) and
  //    add others (the light an earlier object sends on), with the volume's sampler for their
  //    corners' materials. Both back ends.
  //  - on_leave, when set, is given every patch as it leaves the box (exited, or headed for the
  //    receiver from outside the box), after the step that took it out, in the order of the patch
  //    list (deterministic). Both back ends (the GPU path reads the patches back).
  std::function<void(std::vector<Patch>& patches, const VolumeSampler& sampler)> initial_patches;
  std::function<void(const Patch& patch)> on_leave;
};

// What `lightsim` takes, unless told otherwise, for a volume with sharp interfaces or a smoothed n
// (its gradient field), and so the viewer's re-bake of a bake that does not record its options and
// the tests that bake as `lightsim` does.
//
// With sharp interfaces the rays are straight between them and the footprint deposits need no finer
// wavefront than the shape of the objects asks for; the grid's box is fitted to them, so its longest
// side N (voxels) measures them. A patch splits once an edge is past N/44 voxels, clamped to
// [1.5, 3] (1.5 up to N = 66, 3 from N = 132), and starts half that wide (at least 1 voxel); at most
// 4 splits. On a fine grid this keeps the patches as wide, against the objects, as on a 64³ one:
// the 128³ glass sphere over its floor (N = 132) bakes in 0.50 M patch-steps instead of 1.03 M
// (patches of 1 voxel split at 1.5), its floor as close to exact optics (mean ring deviation 1.9 %,
// was 2.2 %), while on coarse grids, where the voxels are already that wide, nothing changes
// (BENCHMARKS.md "Patches as wide as the objects ask"); the silhouette's tears still split to a
// tenth of a voxel. A smoothed n bends every ray: patches of 1 voxel, split at 1, 6 times.
struct VolumeDefaults {
  double patch_voxels = 1.0;
  double split_voxels = 1.0;
  int max_depth = 6;
};
inline VolumeDefaults volumeDefaults(bool sharp_interfaces, const GridSpec& grid) {
  if (!sharp_interfaces) return VolumeDefaults{1.0, 1.0, 6};
  const int longest = std::max(grid.dims.x, std::max(grid.dims.y, grid.dims.z));
  const double split = std::clamp(static_cast<double>(longest) / 44.0, 1.5, 3.0);
  return VolumeDefaults{std::max(1.0, 0.5 * split), split, 4};
}

// What Simulator::run throws when SimulationOptions::cancel was set: the bake was abandoned.
struct BakeCancelled : std::runtime_error {
  BakeCancelled() : std::runtime_error("the bake was cancelled") {}
};

struct KillCounts {
  std::uint64_t flux = 0;     // energy under the threshold
  std::uint64_t exited = 0;   // left the volume, heading away
  std::uint64_t folded = 0;   // orientation flipped (caustic singularity)
  std::uint64_t depth = 0;    // needed a split beyond max_depth (DepthLimit::Kill only)
  std::uint64_t received = 0; // reached the receiver plane
  std::uint64_t blocked = 0;  // stopped by an opaque material
  std::uint64_t trapped = 0;  // trapped by total internal reflection (flux counted as unfinished)
};

struct SimulationStats {
  int steps = 0;
  std::uint64_t initial_patches = 0;
  std::uint64_t peak_patches = 0;
  std::uint64_t total_patches = 0;   // Σ over steps of live patches (patch-steps)
  std::uint64_t splits = 0;
  KillCounts kills;
  // Fluxes in W, RGB. flux_in = out + absorbed + reflected + killed + unfinished + received +
  // blocked; `reflected` is what Fresnel reflection took and no followed wavefront carries.
  glm::dvec3 flux_in{0.0};
  glm::dvec3 flux_out{0.0};          // carried out of the volume by exiting patches
  glm::dvec3 flux_absorbed{0.0};
  glm::dvec3 flux_reflected{0.0};    // Fresnel reflection at boundaries
  glm::dvec3 flux_killed{0.0};       // flux, folded and depth kills
  glm::dvec3 flux_unfinished{0.0};   // still alive at max_steps, or trapped (kills.trapped)
  glm::dvec3 flux_received{0.0};     // absorbed by the receiver plane (its map)
  glm::dvec3 flux_blocked{0.0};      // stopped by opaque materials
  std::uint64_t reflections = 0;     // reflected wavefronts followed (bounces)
  std::uint64_t rollbacks = 0;       // steps undone to split a patch torn by an interface
  std::uint64_t flights = 0;         // patch-steps taken as free flights (longer than Δt)
  // CPU twin: the patch-steps of the wavefronts reflected b times, at index b (index 0: the light
  // that has not been reflected); they sum to total_patches. What each order of --bounces costs.
  // Empty from the GPU path.
  std::vector<std::uint64_t> patch_steps_by_bounce;
  // …and the flux each order put on the receiver (W, RGB; the direct light's cells in order 0): they
  // sum to flux_received. What each order of --bounces brings.
  std::vector<glm::dvec3> flux_received_by_bounce;
  std::map<std::string, double> phase_seconds;   // "init", "update", "analysis", "compact", "deposit", "readback", ...
  // |flux_in − (out + absorbed + reflected + killed + unfinished + received + blocked)| over the
  // largest channel of flux_in, worst channel: 0 for an exact ledger.
  double ledgerResidual() const;
  std::string backend;               // "gl" or "cpu"
  std::string renderer;              // GL renderer string or "cpu, N threads"
  std::string simd;                  // CPU twin: the SIMD target of its track deposits ("AVX3", …)
  nlohmann::json toJson() const;
};

// What a bake adds to a volume (docs/volume-format.md).
struct BakeResult {
  // Empty (no data) when SimulationOptions::volume_deposits is off.
  Field irradiance;   // 3 components, W/m²
  Field light_dir;    // 3 components, unit (0 where no light passed)
  std::vector<ReceiverMap> receivers;  // the receiver's map, when one was given
  SimulationStats stats;
};

class Simulator {
 public:
  virtual ~Simulator() = default;
  // Propagates the light's wavefront through the volume given at construction.
  virtual BakeResult run(const LightSpec& light, const SimulationOptions& options) = 0;
  // Figures of the last run that SimulationStats has no field for, as members to add to the
  // statistics JSON (`lightsim --stats`, --bench): GpuSimulator's "texture_bytes"; none here.
  virtual nlohmann::json lastRunStats() const { return nlohmann::json::object(); }
};

}  // namespace eik
