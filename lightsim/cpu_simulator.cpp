// The CPU twin: ALGORITHM.md steps 1–6, one patch at a time in stepPatch, the list in run().
//
// Where it goes beyond the thesis (ALGORITHM.md steps 3 and 5 specify these rules; the GPU path
// follows them in shaders/lightsim/fate.glsl and fresnel.glsl):
//  - Step 5, `folded`: only in `max` mode. A fold (N·d ≤ 0) is a caustic the light passes
//    through; what is singular there is E = Φ/A, which only the `max` deposit uses. The
//    `accumulate` deposit Φ·Δs/V does not involve the area, so the patch simply goes on. Killing
//    it loses the light behind every caustic: every refracted ray of a ball lens touches the
//    caustic surface before it reaches the axis, and on the 64³ glass sphere (directional light)
//    the kills took 28 % of all the flux in (0.726 of 2.56 W, nearly everything through the
//    sphere) before it reached the plane below.
//  - Step 3, leaving a boundary layer: boundaryReflectance (wavefront.h): no reflection when the
//    index on leaving is within boundary_off of the index on entering, and the Fresnel angle taken
//    on the lower-index side. Without these rules the sphere above reflected 0.44 W instead of
//    ≈ 0.13 W.
//  - Step 5, split: an edge > split_voxels·h·(1 + 10⁻⁴) (splitThreshold), so that rounding
//    does not split initial patches whose edges are exactly one voxel; and by default only along
//    the axes whose edges are too long (SplitRule::Axis, 1×2 splits: wavefront.h splitAxes).
#include "lightsim/cpu_simulator.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <future>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "core/uninitialized.h"
#include "lightsim/interface_crossing.h"
#include "lightsim/receiver.h"
#include "lightsim/track_deposit.h"
#include "lightsim/track_deposit_cpu.h"
#include "core/stopwatch.h"

namespace eik {

namespace {

// The right-hand side of the wavefront ray equation in time t (Eq. 4.12/4.13):
// dx/dt = w/n², dw/dt = ∇n/n, with n and ∇n sampled at x.
struct Derivative {
  glm::dvec3 dx, dw;
};
inline Derivative rayRhs(const glm::dvec4& s, const glm::dvec3& w) {
  const double n = s.x;
  return {w / (n * n), glm::dvec3(s.y, s.z, s.w) / n};
}
inline Derivative rayRhs(const glm::dvec3& x, const glm::dvec3& w, const VolumeSampler& sampler) {
  return rayRhs(sampler.iorAndGradient(x), w);
}

// Voxel containing p, or −1 outside the grid.
inline long long containingVoxel(const GridSpec& grid, const glm::dvec3& p) {
  const glm::dvec3 c = glm::floor(grid.toVoxel(p));
  if (!(c.x >= 0.0 && c.y >= 0.0 && c.z >= 0.0 && c.x < grid.dims.x && c.y < grid.dims.y && c.z < grid.dims.z))
    return -1;
  return static_cast<long long>(grid.index(static_cast<int>(c.x), static_cast<int>(c.y), static_cast<int>(c.z)));
}

inline double maxChannel(const glm::dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

}  // namespace

void advanceCorner(glm::dvec3& x, glm::dvec3& w, glm::dvec4& sample, double dt, Integrator integrator,
                   const VolumeSampler& sampler) {
  switch (integrator) {
    case Integrator::Euler: {
      // Eq. 6.1: x ← x + Δt·w/n²; Eq. 6.2: w ← w + Δt·∇n/n (both with n, ∇n at the old x).
      const Derivative k = rayRhs(sample, w);
      x += dt * k.dx;
      w += dt * k.dw;
      break;
    }
    case Integrator::RK2: {  // midpoint
      const Derivative k1 = rayRhs(sample, w);
      const Derivative k2 = rayRhs(x + (0.5 * dt) * k1.dx, w + (0.5 * dt) * k1.dw, sampler);
      x += dt * k2.dx;
      w += dt * k2.dw;
      break;
    }
    case Integrator::RK4: {  // classical
      const Derivative k1 = rayRhs(sample, w);
      const Derivative k2 = rayRhs(x + (0.5 * dt) * k1.dx, w + (0.5 * dt) * k1.dw, sampler);
      const Derivative k3 = rayRhs(x + (0.5 * dt) * k2.dx, w + (0.5 * dt) * k2.dw, sampler);
      const Derivative k4 = rayRhs(x + dt * k3.dx, w + dt * k3.dw, sampler);
      x += (dt / 6.0) * (k1.dx + 2.0 * k2.dx + 2.0 * k3.dx + k4.dx);
      w += (dt / 6.0) * (k1.dw + 2.0 * k2.dw + 2.0 * k3.dw + k4.dw);
      break;
    }
  }
  // |w| = n along an exact ray: renormalise to n at the new position (ALGORITHM.md step 1).
  sample = sampler.iorAndGradient(x);
  w = renormalised(w, sample.x);
}

PatchSamples samplePatch(const Patch& patch, const VolumeSampler& sampler) {
  PatchSamples s;
  for (int c = 0; c < 4; ++c) s.corner[c] = sampler.iorAndGradient(patch.x[c]);
  s.n_mid = sampler.ior(patch.midpoint());
  return s;
}

bool straightSteps(const VolumeSampler& sampler, const SimulationOptions& options) {
  if (!sampler.sharp() || !(options.straight_step_voxels > options.step_voxels))
    return false;
  for (const InterfaceSlot& slot : sampler.interfaces().slots)
    if (slot.graded) return false;
  return true;
}

StepContext makeStepContext(const VolumeSampler& sampler, const SimulationOptions& options, double flux_ref) {
  StepContext ctx;
  ctx.sampler = &sampler;
  ctx.options = &options;
  ctx.dt = timeStep(sampler.grid(), options);
  ctx.step_dt = straightSteps(sampler, options) ? options.straight_step_voxels * voxelEdge(sampler.grid()) : ctx.dt;
  ctx.retake_at_interfaces = ctx.step_dt > ctx.dt && options.volume_deposits;
  ctx.reflected_step_dt = ctx.step_dt;
  if (ctx.step_dt > ctx.dt && (!sampler.hasAbsorption() || sampler.absorptionPerMaterial()))
    ctx.reflected_step_dt = kReflectedStepFactor * ctx.step_dt;
  // A path of time t has length t/n (|dx/dt| = 1/n): at most this far from where it starts.
  ctx.straight_reach = ctx.step_dt / std::min(1.0, sampler.minIor());
  ctx.flux_ref = flux_ref;
  ctx.voxel_volume = sampler.grid().voxelVolume();
  propagationBox(sampler.grid(), options, ctx.box_lo, ctx.box_hi);
  ctx.torn_light_to_receiver = tornLightPassesToReceiver(sampler, options);
  return ctx;
}

bool tornLightPassesToReceiver(const VolumeSampler& sampler, const SimulationOptions& options) {
  return options.receiver.has_value() && !options.on_leave &&
         (!sampler.hasAbsorption() || (sampler.absorptionPerMaterial() && !sampler.airBox()));
}

PatchStepResult stepPatch(Patch& patch, const StepContext& ctx) {
  PatchSamples samples = samplePatch(patch, *ctx.sampler);
  return stepPatch(patch, samples, ctx);
}

namespace {

// A step that would tear a patch (its edges past this many split lengths after crossing an
// interface) is undone and the patch split before it crosses (ALGORITHM.md "Sharp interfaces").
constexpr double kTearFactor = 2.0;
// Total internal reflections (all corners together) after which a patch counts as trapped and stops,
// its flux counted as unfinished (light still travelling, as at the step limit): on a voxelised
// sphere the rays that enter at grazing incidence can meet the far side just past the critical
// angle and circle inside it for ever, and in a block light can bounce between its faces.
constexpr int kMaxTotalReflections = 16;

bool oneMedium(const Patch& p) {
  return p.medium[0] == p.medium[1] && p.medium[1] == p.medium[2] && p.medium[2] == p.medium[3];
}

// The sub-path lattice of a patch-step carrying `flux` (track_deposit.h): ≤ ½ voxel between
// neighbours along u and v, or ≤ 1 voxel for dim light (trackSpacing).
glm::ivec2 subPathLattice(const Patch& before, const Patch& after, const glm::dvec3& flux, double h,
                          double dim_irradiance) {
  auto longest = [](const Patch& p, int a, int b, int c, int d) {
    return std::max(glm::length(p.x[b] - p.x[a]), glm::length(p.x[c] - p.x[d]));
  };
  const double u = std::max(longest(before, 0, 1, 2, 3), longest(after, 0, 1, 2, 3));
  const double v = std::max(longest(before, 1, 2, 3, 0), longest(after, 1, 2, 3, 0));
  const double spacing = trackSpacing(maxChannel(flux), std::min(before.area(), after.area()), dim_irradiance);
  return {trackLattice(u / h, spacing), trackLattice(v / h, spacing)};
}

// Step 1 with sharp interfaces: every corner crosses the interfaces on its way. Returns the
// patch's flux transmittance Π (1 − R_c)^¼ and whether any corner met an interface; `blocked`
// counts the corners an opaque surface stopped, `transmitted` the corners that refracted.
struct SharpUpdate {
  double transmittance = 1.0;
  bool met_interface = false;
  int blocked = 0;
  int transmitted_mask = 0;
  int met_mask = 0;        // corners that met an interface (refracted, reflected or were stopped)
  int reflections = 0;     // total internal reflections, all corners
  int reflected_mask = 0;  // corners that were totally reflected
  glm::dvec3 optical_depth{0.0};  // ¼ Σ_c ∫σa ds (σa per material; else 0)
};
SharpUpdate updateCornersSharp(Patch& patch, PatchSamples& samples, const StepContext& ctx, double dt) {
  SharpUpdate u;
  for (int c = 0; c < 4; ++c) {
    const CornerCrossings cc = advanceCornerSharp(patch.x[c], patch.w[c], patch.medium[c], samples.corner[c], dt,
                                                  ctx.options->integrator, *ctx.sampler);
    const bool met = cc.transmitted > 0 || cc.reflected > 0 || cc.blocked;
    u.met_interface |= met;
    if (met) u.met_mask |= 1 << c;
    u.reflections += cc.reflected;
    if (cc.reflected > 0) u.reflected_mask |= 1 << c;
    u.blocked += cc.blocked ? 1 : 0;
    if (cc.transmitted > 0) u.transmitted_mask |= 1 << c;
    if (cc.transmittance != 1.0) u.transmittance *= std::pow(cc.transmittance, 0.25);  // (1 without a crossing)
    u.optical_depth += 0.25 * cc.optical_depth;
  }
  return u;
}

// The time of a sharp volume's ordinary step for this patch: a straight step (ctx.step_dt) where
// they apply and, with absorption, either σa is per material (each corner's path is absorbed piece
// by piece, exactly) or nothing absorbs within its reach of the corners (then step 2's σa at the
// midpoint is 0 along the whole step, as it is); else Δt.
double sharpStepTime(const Patch& patch, const StepContext& ctx) {
  if (!(ctx.step_dt > ctx.dt)) return ctx.dt;
  if (!ctx.sampler->hasAbsorption() || ctx.sampler->absorptionPerMaterial())
    return patch.bounce > 0 ? ctx.reflected_step_dt : ctx.step_dt;
  if (!ctx.absorbers) return ctx.dt;
  glm::dvec3 lo = patch.x[0], hi = patch.x[0];
  for (int c = 1; c < 4; ++c) lo = glm::min(lo, patch.x[c]), hi = glm::max(hi, patch.x[c]);
  return ctx.absorbers->quiet(lo - ctx.straight_reach, hi + ctx.straight_reach) ? ctx.step_dt : ctx.dt;
}

// How far back reflectedPatch looks for the interface a patch's corners crossed: they crossed it
// over up to four of its ordinary steps (a reflected wavefront's are longer), plus two voxels.
double reflectionReach(const Patch& patch, const StepContext& ctx) {
  return 4.0 * (patch.bounce > 0 ? ctx.reflected_step_dt : ctx.step_dt) + 2.0 * ctx.sampler->h();
}

// A patch meets an interface with some corners and not yet with the others. It will tear — the
// others pass the object by (its silhouette), or meet another surface — unless each of them finds
// the surface just crossed ahead on its straight ray, within a few patch sizes. The ray is looked at
// in pieces (findInterfaceOnChord): asked at its end only, a corner above a wall thinner than the
// reach found nothing and every patch that reached a thin glass wall tore (split to the depth limit
// and died: a slab of 1.9 voxels baked with the command's defaults took 28 times the patch-steps
// and killed 1 % of the light).
bool willTear(const Patch& patch, int met_mask, const VolumeSampler& sampler, double reach) {
  int slot = -1;
  for (int c = 0; c < 4; ++c) {
    if (met_mask & (1 << c)) continue;
    InterfaceHit hit;
    const glm::dvec3 d = glm::normalize(patch.w[c]);
    if (!findInterfaceOnChord(sampler, patch.x[c], patch.x[c] + reach * d, patch.medium[c], hit)) return true;
    if (slot >= 0 && hit.slot != slot) return true;
    slot = hit.slot;
  }
  return false;
}

// The light a patch torn at the depth limit carries past the object (ALGORITHM.md "Sharp
// interfaces", torn at the depth limit): its corners fan out over both sides of a silhouette, and
// those that pass the object by go on straight. Each corner in air that did not meet the surface
// and whose straight ray from where it was meets no interface before it leaves the propagation box
// or reaches the receiver's plane carries a quarter of the patch's flux straight to the receiver:
// the direct light at the edge of the object's shadow, which the map lacked where these patches
// died (the image's ring 0.995–1 of the 128³ sphere at 7 % of exact optics). The share (0 to 1)
// and, when it is not 0, `footprint`: the patch's as it was, on the plane (a patch at the depth
// limit is a fraction of a texel: where in it the passing part lies does not show). Only where
// tornLightPassesToReceiver.
double passingShare(const Patch& before, int met_mask, const StepContext& ctx, std::array<glm::dvec2, 4>& footprint) {
  const ReceiverMap* receiver = ctx.receiver;
  const VolumeSampler& sampler = *ctx.sampler;
  if (!receiver || !ctx.torn_light_to_receiver) return 0.0;
  int passing = 0;
  for (int c = 0; c < 4; ++c) {
    if (before.medium[c] != -1) return 0.0;  // not in air: its straight ray is not the light's
    if (met_mask & (1 << c)) continue;
    const glm::dvec3 x = before.x[c], d = glm::normalize(before.w[c]);
    const double facing = glm::dot(d, receiver->normal);
    const double above = glm::dot(x - receiver->point, receiver->normal);
    if (!(facing < 0.0) || !(above > 0.0)) continue;
    double t_end = -above / facing;  // to the plane
    for (int a = 0; a < 3; ++a)      // …or out of the box, whichever comes first
      if (d[a] != 0.0) t_end = std::min(t_end, ((d[a] > 0.0 ? ctx.box_hi[a] : ctx.box_lo[a]) - x[a]) / d[a]);
    InterfaceHit hit;
    if (t_end > 0.0 && findInterfaceOnChord(sampler, x, x + t_end * d, -1, hit)) continue;
    ++passing;
  }
  if (passing == 0 || !patchFootprint(before, *receiver, footprint)) return 0.0;
  return 0.25 * passing;
}

// Straight steps merged (ALGORITHM.md "Free flight"): where the quiet map refuses even a flight's
// first piece (a patch within a brick or two of an interface) and every ray is straight between
// interfaces (straight steps apply: sharp materials of constant n), the ordinary straight steps the
// patch would take are looked at ahead. A corner's straight step crosses nothing when it ends in its
// own material (findInterface asks no more), and every piece of it too where a long step is looked
// at in pieces (findInterfaceOnChord), so as long as every corner ends each of the next k steps, and
// their pieces, in its own material, those k steps move the corners exactly as one step of k times the time
// does, and the steps between have nothing to do (no crossing, no tear; no split within t_max, the
// edges' bound, and none for a patch that is due to split now; a Fresnel, absorption or exit test
// only where they would anyway). The steps' ends
// are asked for their material one by one, except along pieces of the path the quiet map finds
// quiet (no interface there: every end in it is in the corners' material), and no further once the
// midpoint has left the propagation box (the patch then exits). The patch flies those k steps at
// once (k ≥ 2, at most kMaxMergedSteps); 0: it takes its ordinary step.
constexpr int kMaxMergedSteps = 64;
template <typename QuietBetween>
double mergedStepsTime(const Patch& patch, const std::array<glm::dvec3, 4>& v, const StepContext& ctx, double t_max,
                       bool split_due, QuietBetween&& quiet_between) {
  const VolumeSampler& sampler = *ctx.sampler;
  if (!ctx.options->merge_straight_steps || !(ctx.step_dt > ctx.dt) || patch.reflected != 0 || split_due ||
      (sampler.hasAbsorption() && !sampler.absorptionPerMaterial()))
    return 0.0;
  const double step = patch.bounce > 0 ? ctx.reflected_step_dt : ctx.step_dt;
  const int most = static_cast<int>(std::min<double>(kMaxMergedSteps, std::floor(t_max / step)));
  if (most < 2) return 0.0;
  // A long step's chord is looked at in pieces (findInterfaceOnChord): so are its ends here.
  std::array<int, 4> pieces;
  for (int c = 0; c < 4; ++c)
    pieces[static_cast<std::size_t>(c)] = chordPieces(step * glm::length(v[static_cast<std::size_t>(c)]), sampler.h());
  int k = 0;
  int next_try = 1;  // when to look for a quiet piece next: after 1, 3, 7, 15, … steps in noisy space
  while (k < most) {
    // A quiet piece ahead: the longest of 1, 2, 4, … steps from here.
    if (k == next_try) {
      int quiet = 0;
      for (int piece = 1; k + piece <= most && quiet_between(k * step, (k + piece) * step); piece *= 2) quiet = piece;
      next_try = 2 * k + 1;
      if (quiet > 0) {
        k += quiet;
        next_try = k;
        continue;
      }
    }
    const double t = (k + 1) * step;
    glm::dvec3 mid(0.0);
    for (int c = 0; c < 4; ++c) {
      const std::size_t ci = static_cast<std::size_t>(c);
      for (int j = 1; j < pieces[ci]; ++j) {
        const double tj = (k + static_cast<double>(j) / pieces[ci]) * step;
        if (sampler.materialAt(patch.x[c] + tj * v[ci]) != patch.medium[c]) return k >= 2 ? k * step : 0.0;
      }
      const glm::dvec3 end = patch.x[c] + t * v[ci];
      if (sampler.materialAt(end) != patch.medium[c]) return k >= 2 ? k * step : 0.0;
      mid += 0.25 * end;
    }
    ++k;
    if (!insideBox(mid, ctx.box_lo, ctx.box_hi)) break;
  }
  return k >= 2 ? k * step : 0.0;
}

// Free flight (ALGORITHM.md "Free flight"): the time of one straight step for the whole patch,
// or 0 when it takes an ordinary step of Δt. Every corner moves on its straight ray
// x_c + t·w_c/n_c², so the patch swept from t0 to t1 lies in the box of its corners at t0 and t1
// (a bilinear patch of linearly moving corners stays in their convex hull); the step is taken only
// where the boxes of its pieces are quiet. Its length: doubled from 2Δt while the path stays
// quiet, then refined by bisection, and
// bounded so that no edge grows past the split length (or past its length now, if longer) and by
// ctx.flight_cap.
double freeFlightTime(const Patch& patch, const PatchSamples& samples, const StepContext& ctx, double threshold) {
  if (ctx.sampler->sharp()) {
    if (!oneMedium(patch) || patch.crossed != 0 || patch.reflect_pending != 0.0) return 0.0;
  } else if (patch.n_in != 0.0) {
    return 0.0;  // inside a boundary layer: its Fresnel exit is decided step by step
  }
  std::array<glm::dvec3, 4> v;
  for (int c = 0; c < 4; ++c) {
    const glm::dvec4& s = samples.corner[static_cast<std::size_t>(c)];
    if (s.y != 0.0 || s.z != 0.0 || s.w != 0.0 || !(s.x > 0.0)) return 0.0;
    v[static_cast<std::size_t>(c)] = patch.w[c] / (s.x * s.x);  // dx/dt, Eq. 6.1
  }
  // The longest an edge may grow to: the split length, or its length now if longer; at the depth
  // limit, a kept patch as far as it would go on unsplit (stepPatch's analysis).
  const bool kept = ctx.options->at_max_depth == DepthLimit::Keep && patch.depth >= ctx.options->max_depth;
  double t_max = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 4; ++c) {
    // A path of length ℓ takes time ℓ·n (|dx/dt| = 1/n).
    t_max = std::min(t_max, ctx.flight_cap * samples.corner[static_cast<std::size_t>(c)].x);
    const int d = (c + 1) % 4;
    // The edge e(t) = e₀ + t·Δv stays within L while |Δv|²t² + 2(e₀·Δv)t + |e₀|² − L² ≤ 0: up to the
    // larger root (an edge that shrinks first, through a focus, may fly past it).
    const glm::dvec3 e0 = patch.x[d] - patch.x[c];
    const glm::dvec3 dv = v[static_cast<std::size_t>(d)] - v[static_cast<std::size_t>(c)];
    const double a = glm::dot(dv, dv);
    if (!(a > 0.0)) continue;
    const double edge2 = glm::dot(e0, e0);
    const double limit = kept ? kMaxUnsplitEdge * splitThreshold(ctx.sampler->grid(), *ctx.options)
                              : std::max(threshold, std::sqrt(edge2));
    const double b = glm::dot(e0, dv);
    const double disc = std::max(0.0, b * b - a * (edge2 - limit * limit));
    t_max = std::min(t_max, (-b + std::sqrt(disc)) / a);
  }
  const double dt = ctx.dt;
  if (!(t_max >= 2.0 * dt)) return 0.0;
  // Whether the patch swept from time t0 to t1 is quiet: it lies in the box of its corners at t0
  // and t1. The flight's path is covered piece by piece, each piece's box checked once: the
  // doubling pieces [2^k·2Δt, 2^(k+1)·2Δt] and the bisection's [good, mid] hug a path that passes
  // a curved surface, where one box from 0 to t would take the surface in.
  auto quietBetween = [&](double t0, double t1) {
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (int c = 0; c < 4; ++c) {
      const glm::dvec3 start = patch.x[c] + t0 * v[static_cast<std::size_t>(c)];
      const glm::dvec3 end = patch.x[c] + t1 * v[static_cast<std::size_t>(c)];
      lo = glm::min(lo, glm::min(start, end));
      hi = glm::max(hi, glm::max(start, end));
    }
    return ctx.quiet->quiet(lo, hi);
  };
  double good = 0.0, bad = 0.0;
  for (double t = 2.0 * dt;; t *= 2.0) {
    const double tt = std::min(t, t_max);
    if (!quietBetween(good, tt)) {
      bad = tt;
      break;
    }
    good = tt;
    if (tt >= t_max) break;
  }
  // A patch longer than the split length (it crossed an interface unsplit) splits at its next look.
  const bool split_due = !kept && patch.longestEdge() > threshold;
  if (good == 0.0) return mergedStepsTime(patch, v, ctx, t_max, split_due, quietBetween);
  if (bad > 0.0)
    for (int i = 0; i < 3; ++i) {
      const double mid = 0.5 * (good + bad);
      (quietBetween(good, mid) ? good : bad) = mid;
    }
  return good;
}

}  // namespace

PatchStepResult stepPatch(Patch& patch, PatchSamples& samples, const StepContext& ctx) {
  const VolumeSampler& sampler = *ctx.sampler;
  const SimulationOptions& options = *ctx.options;
  const GridSpec& grid = sampler.grid();
  const double h = sampler.h();
  const double threshold = splitThreshold(grid, options) * (patch.bounce > 0 ? kReflectedSplitFactor : 1.0);
  const bool sharp = sampler.sharp();
  const bool track = options.deposit == DepositMode::Accumulate && options.deposit_kernel == DepositKernel::Track;
  PatchStepResult result;

  const Patch before = patch;
  const glm::dvec3 m_old = patch.midpoint();
  const glm::dvec3 d_old = patch.direction();
  const double n_m_old = samples.n_mid;
  // Free flight: one straight step of this time across quiet space (0: a step of Δt).
  const double flight = ctx.quiet && track ? freeFlightTime(patch, samples, ctx, threshold) : 0.0;
  // Δs_m = Δt/n(m) (Eq. 4.11); a sharp volume's ordinary step may be a straight step.
  double step_dt = flight > 0.0 ? flight : sharp ? sharpStepTime(patch, ctx) : ctx.dt;
  double ds = step_dt / n_m_old;

  // 1. Update (§6.2.2, Eq. 6.1/6.2 or RK2/RK4), then |w| = n(x_new); with sharp interfaces, Snell
  //    and Fresnel where a corner crosses one.
  SharpUpdate crossing;
  if (flight > 0.0) {
    // Straight rays (∇n = 0): Eq. 6.1 is exact for any step, Eq. 6.2 leaves w, n and the samples as
    // they are, and no interface lies in the swept box.
    result.flight = true;
    for (int c = 0; c < 4; ++c) {
      const double n = samples.corner[static_cast<std::size_t>(c)].x;
      patch.x[c] += flight * patch.w[c] / (n * n);
    }
  } else if (sharp) {
    const PatchSamples samples_before = samples;
    crossing = updateCornersSharp(patch, samples, ctx, step_dt);
    if (crossing.met_interface && step_dt > ctx.dt && ctx.retake_at_interfaces && before.bounce == 0) {
      // A straight step's track is its chord, the ray itself only where no corner met an
      // interface: one that did is retaken as a step of Δt (ALGORITHM.md "Straight steps"). Not a
      // reflected wavefront's: like its longer steps, its chords misplace a share R of the light
      // only, and retaken, a step of 8 voxels meets an interface often (the museum's cube took
      // 16 % more patch-steps with longer steps retaken, a third fewer with them not retaken).
      patch = before;
      samples = samples_before;
      step_dt = ctx.dt;
      ds = step_dt / n_m_old;
      crossing = updateCornersSharp(patch, samples, ctx, step_dt);
    }
    // A tear: undo the step and split the patch as it was, so that its parts cross on their own.
    // Either the step stretched it far, or it is the patch's first touch of an interface and some
    // corners will not follow (willTear).
    patch.reflections += crossing.reflections;
    if (crossing.met_interface && oneMedium(before)) {
      const bool stretched = splitAxes(patch, kTearFactor * threshold, options.split_rule).any();
      // Corners totally reflected at this surface in earlier steps have met it already.
      const int met = crossing.met_mask | before.reflected;
      const bool first_touch = met != 0xF;
      const bool tears = stretched || (first_touch && willTear(patch, met, sampler, 4.0 * std::max(patch.longestEdge(), h)));
      if (tears && patch.depth >= options.max_depth) {
        // Torn at the depth limit: its corners now fan out over both sides of an edge or a
        // silhouette, and its interior says nothing about where its light goes. It dies here
        // (its flux counted as killed), before it deposits anything — but for the light of its
        // corners that pass the object by, which goes straight to the receiver (passingShare).
        result.fate = PatchFate::KilledDepth;
        if (const double share = passingShare(before, met, ctx, result.footprint); share > 0.0)
          result.received = before.flux * share;
        return result;
      }
      if (tears) {
        SplitAxes axes = splitAxes(patch, threshold, options.split_rule);
        if (!axes.any()) axes = splitAxes(before, 0.0, options.split_rule);  // a tear ahead: halve it
        patch = before;
        samples = samples_before;
        result.rolled_back = true;
        result.fate = PatchFate::Split;
        result.split = axes;
        return result;
      }
    }
  } else {
    for (int c = 0; c < 4; ++c)
      advanceCorner(patch.x[c], patch.w[c], samples.corner[c], ctx.dt, options.integrator, sampler);
  }

  // 2. Absorption at the old midpoint: Φ ← Φ·exp(−σa(m)·Δs_m) (Beer–Lambert); with σa per
  //    material, Φ ← Φ·exp(−¼ Σ_c ∫σa ds) along the corners' paths, each piece in its material.
  if (sampler.hasAbsorption()) {
    glm::dvec3 optical_depth = crossing.optical_depth;
    if (!(sharp && sampler.absorptionPerMaterial())) {
      optical_depth = sampler.sigmaA(m_old) * ds;
    } else if (flight > 0.0) {
      for (int c = 0; c < 4; ++c)
        optical_depth += 0.25 * sampler.pieceOpticalDepth(patch.medium[c], before.x[c], patch.x[c], flight / samples.corner[c].x);
    }
    const glm::dvec3 transmitted = glm::exp(-optical_depth);
    result.absorbed = patch.flux * (1.0 - transmitted);
    patch.flux *= transmitted;
  }

  // 3. Fresnel: at the sharp interfaces the corners crossed, or at the boundary layer of a
  //    smoothed n (docs/physics.md).
  const glm::dvec3 m_new = patch.midpoint();
  const glm::dvec3 d_new = patch.direction();
  if (sharp) {
    // (After a flight toward a surface the midpoint may lie across a feature thinner than the
    // patch, so it is looked up after every step.)
    samples.n_mid = sampler.materialOptics(sampler.materialAt(m_new), m_new).x;
    patch.t_fresnel = crossing.transmittance;
    if (crossing.transmittance < 1.0) {
      result.reflected = patch.flux * (1.0 - crossing.transmittance);
      patch.flux *= crossing.transmittance;
      patch.reflect_pending = 1.0 - (1.0 - patch.reflect_pending) * crossing.transmittance;
    }
    // A total reflection is through once all four corners have reflected (or the patch flies:
    // no surface is near).
    patch.reflected |= crossing.reflected_mask;
    if (patch.reflected == 0xF || flight > 0.0) patch.reflected = 0;
    patch.crossed |= crossing.transmitted_mask;
    if (patch.crossed == 0xF) {
      // Every corner is through: the reflected wavefront leaves the interface now (bounces).
      const glm::dvec3 reflected_flux = patch.flux * (patch.reflect_pending / (1.0 - patch.reflect_pending));
      Patch reflection;
      if (patch.bounce < options.bounces && patch.reflect_pending > 0.0 && patch.reflect_pending < 1.0 &&
          std::max(reflected_flux.x, std::max(reflected_flux.y, reflected_flux.z)) >=
              fluxKillThreshold(ctx.flux_ref, options, static_cast<int>(patch.depth)) &&
          reflectedPatch(patch, sampler, reflectionReach(patch, ctx), reflection)) {
        result.reflection = std::make_unique<Patch>(reflection);
        result.spawn_reflection = true;
        result.reflection->flux = reflected_flux;
        result.reflection->area0 = result.reflection->area();
        result.reflection->bounce = patch.bounce + 1;
        result.reflection->reflect_pending = 0.0;
        result.reflection->crossed = 0;
        result.reflection->reflected = 0;
        result.reflection->t_fresnel = 1.0;
      }
      patch.crossed = 0;
      patch.reflect_pending = 0.0;
    }
  } else {
    const glm::dvec4 ng = sampler.iorAndGradient(m_new);
    samples.n_mid = ng.x;
    const glm::dvec3 grad(ng.y, ng.z, ng.w);
    const double grad_len = glm::length(grad);
    const double g = grad_len * h;  // index change per voxel
    patch.t_fresnel = 1.0;
    if (patch.n_in == 0.0 && g > options.boundary_on) {
      patch.n_in = n_m_old;
      patch.cos_in = std::fabs(glm::dot(d_old, grad / grad_len));
    } else if (patch.n_in != 0.0 && g < options.boundary_off) {
      const double cos_out = grad_len > 0.0 ? std::fabs(glm::dot(d_new, grad / grad_len)) : -1.0;
      const double reflectance = boundaryReflectance(patch.n_in, patch.cos_in, ng.x, cos_out, options.boundary_off);
      result.reflected = patch.flux * reflectance;
      patch.flux *= 1.0 - reflectance;
      patch.t_fresnel = 1.0 - reflectance;
      patch.n_in = 0.0;
    }
  }

  // The receiver: the patch's midpoint crossed the plane in this step, or it left the box towards it.
  const ReceiverMap* receiver = ctx.receiver;
  const bool inside = insideBox(m_new, ctx.box_lo, ctx.box_hi);
  bool reached = false;
  if (receiver) {
    const double above_old = glm::dot(m_old - receiver->point, receiver->normal);
    const double above_new = glm::dot(m_new - receiver->point, receiver->normal);
    const bool crossed_plane = above_old > 0.0 && above_new <= 0.0;
    const bool heading_there = !inside && !rayHitsBox(m_new, d_new, ctx.box_lo, ctx.box_hi) && above_new > 0.0 &&
                               glm::dot(d_new, receiver->normal) < 0.0;
    reached = (crossed_plane || heading_there) && patchFootprint(patch, *receiver, result.footprint);
  }

  // 4. Deposit record (§6.2.3).
  const glm::dvec3 N = patch.areaVector();
  if (track) {
    result.track = true;
    result.from = before.x;
    result.track_flux = 0.5 * (before.flux + patch.flux);  // the flux along the step, on average
    result.track_start = before.flux;
    result.track_end = patch.flux;
    result.lattice = subPathLattice(before, patch, result.track_flux, h, ctx.dim_irradiance);
    result.clip_to_receiver = reached;
  } else {
    result.voxel = containingVoxel(grid, m_new);
    if (result.voxel >= 0) {
      if (options.deposit == DepositMode::Accumulate) {
        result.deposit = patch.flux * (ds / ctx.voxel_volume);
        result.deposit_dir = (luminance(patch.flux) * ds) * d_new;
      } else {
        const double area = glm::length(N);
        result.deposit = area > 0.0 ? patch.flux / area : glm::dvec3(0.0);
        result.deposit_dir = d_new;
        result.max_key = luminance(result.deposit);
      }
    }
  }

  // 5. Analysis (§6.2.4).
  if (reached) {
    result.fate = PatchFate::Received;
    result.received = patch.flux;
  } else if (crossing.blocked >= 2) {
    result.fate = PatchFate::Blocked;
  } else if (patch.reflections > kMaxTotalReflections) {
    result.fate = PatchFate::Trapped;  // by total internal reflection (a whispering gallery, a block)
  } else if (maxChannel(patch.flux) < fluxKillThreshold(ctx.flux_ref, options, patch.depth)) {
    result.fate = PatchFate::KilledFlux;
  } else if (!inside && !rayHitsBox(m_new, d_new, ctx.box_lo, ctx.box_hi)) {
    result.fate = PatchFate::Exited;
  } else if (options.deposit == DepositMode::Max && !(glm::dot(N, d_new) > 0.0)) {
    result.fate = PatchFate::Folded;  // orientation flipped: a caustic singularity
  } else if ((result.split = splitAxes(patch, threshold, options.split_rule)).any()) {
    // With sharp interfaces a patch whose corners are in different materials (part way through an
    // interface) is not split: its new corners would mix the two sides' rays.
    const bool splittable = !sharp || (oneMedium(patch) && crossing.blocked == 0);
    // Kept within kMaxUnsplitEdge of the run's split length, a reflected wavefront's too.
    const bool keep = options.at_max_depth == DepthLimit::Keep &&
                      patch.longestEdge() <= kMaxUnsplitEdge * splitThreshold(grid, options);
    result.fate = splittable && patch.depth < options.max_depth ? PatchFate::Split
                  : keep                                        ? PatchFate::Keep
                                                                : PatchFate::KilledDepth;
  } else {
    result.fate = PatchFate::Keep;
  }
  return result;
}

CpuSimulator::CpuSimulator(const Volume& volume) : sampler_(volume) {}

CpuSimulator::CpuSimulator(const Volume& volume, std::vector<float>* interfaces_data)
    : sampler_(volume, interfaces_data) {}

int exitFace(const glm::dvec3& m, const glm::dvec3& d, const GridSpec& grid) {
  const glm::dvec3 lo = grid.bounds_min, hi = grid.bounds_max;
  // Slab test of the backward ray m − t·d: the face of the largest entry parameter.
  double t_near = -std::numeric_limits<double>::infinity(), t_far = std::numeric_limits<double>::infinity();
  int face = -1;
  bool hits = true;
  for (int a = 0; a < 3 && hits; ++a) {
    const double back = -d[a];
    if (back == 0.0) {
      hits = m[a] >= lo[a] && m[a] <= hi[a];
      continue;
    }
    const double t_lo = (lo[a] - m[a]) / back, t_hi = (hi[a] - m[a]) / back;
    const double t_in = std::min(t_lo, t_hi), t_out = std::max(t_lo, t_hi);
    if (t_in > t_near) {
      t_near = t_in;
      face = 2 * a + (back > 0.0 ? 0 : 1);  // entering through the low face when moving up the axis
    }
    t_far = std::min(t_far, t_out);
  }
  if (hits && face >= 0 && t_near <= t_far && t_near >= 0.0) return face;
  double worst = -1.0;
  const glm::dvec3 e = grid.extent();
  for (int a = 0; a < 3; ++a) {
    const double below = (lo[a] - m[a]) / e[a], above = (m[a] - hi[a]) / e[a];
    if (below > worst) {
      worst = below;
      face = 2 * a;
    }
    if (above > worst) {
      worst = above;
      face = 2 * a + 1;
    }
  }
  return face;
}

BakeResult CpuSimulator::run(const LightSpec& light, const SimulationOptions& options) {
  return run(light, options, nullptr);
}

BakeResult CpuSimulator::run(const LightSpec& light, const SimulationOptions& options, CpuRunDiagnostics* diagnostics) {
  if (diagnostics) *diagnostics = CpuRunDiagnostics{};
  const GridSpec& grid = sampler_.grid();
  const std::size_t voxels = grid.count();
  BakeResult bake;
  SimulationStats& stats = bake.stats;
  stats.backend = "cpu";
  const unsigned threads = workerThreads();
  stats.renderer = "cpu, " + std::to_string(threads) + (threads == 1 ? " thread" : " threads");
  stats.simd = trackDepositTarget();

  Stopwatch phase;
  validateLight(light);
  validateOptions(options);
  StepContext ctx = makeStepContext(sampler_, options, 0.0);
  if (options.free_flight && options.deposit == DepositMode::Accumulate &&
      options.deposit_kernel == DepositKernel::Track) {
    if (quiet_.empty()) quiet_ = sampler_.quietMap();
    ctx.quiet = &quiet_;
    ctx.flight_cap = glm::length(ctx.box_hi - ctx.box_lo);
  }
  if (ctx.step_dt > ctx.dt && sampler_.hasAbsorption() && !sampler_.absorptionPerMaterial()) {
    if (absorbers_.empty()) absorbers_ = sampler_.absorberMap();
    ctx.absorbers = &absorbers_;
  }
  // The receiver's map (its geometry first: the initial patches cover it).
  ReceiverMap receiver;
  std::optional<FootprintSums> receiver_flux;
  std::future<void> receiver_flux_made;  // (destroyed first: waits for the sums before they go)
  if (options.receiver) {
    receiver = options.receiver_geometry ? *options.receiver_geometry
                                         : receiverGeometry(*options.receiver, light, grid, ctx.box_lo, ctx.box_hi);
    receiver.irradiance.clear();
    ctx.receiver = &receiver;
    // The sums start as zeros (12.6 MB at the 128³ sphere's 1024² texels), made on a thread of
    // their own while the initial patches are: filling fresh memory is mostly the kernel zeroing
    // its pages, which had held up this thread.
    // A grey light through a volume that absorbs nothing keeps every flux grey (Fresnel, splits and
    // reflections scale all channels alike): its map is summed and made grey, a third of the memory.
    const bool grey = light.power.x == light.power.y && light.power.y == light.power.z && !sampler_.hasAbsorption();
    receiver_flux_made = std::async(std::launch::async, [&, grey] { receiver_flux.emplace(receiver, grey); });
  }
  double flux_ref = 0.0;
  DirectCells direct;  // cells that go straight to the receiver's map: in closed form, not followed
  std::vector<Patch> initial = initialPatches(light, grid, sampler_, options, &flux_ref, ctx.receiver, &direct);
  std::optional<DirectMapLight> direct_light;
  if (direct.cells > 0) direct_light = directMapLight(receiver, light, initial);
  adjustInitialPatches(initial, sampler_, options, flux_ref);
  if (receiver_flux_made.valid()) receiver_flux_made.get();
  ctx.flux_ref = flux_ref;
  ctx.dim_irradiance = kDimTrackFraction * brightestIrradiance(light, grid);
  stats.initial_patches = initial.size();
  for (const Patch& p : initial) stats.flux_in += p.flux;
  stats.phase_seconds["init"] = phase.seconds();

  const int max_steps = maxSteps(grid, options);
  const bool accumulate = options.deposit == DepositMode::Accumulate;
  const bool volume_deposits = options.volume_deposits;
  const bool track = volume_deposits && accumulate && options.deposit_kernel == DepositKernel::Track;

  // Deposit targets, in double (accumulate) or the strongest patch so far (max); none without
  // volume deposits.
  // Zeroed by both threads (a voxel's sums are a cache line: 147 MB at 132³, which one thread's
  // value-initialisation faulted in alone).
  UninitializedVector<DepositSum> sums;
  if (!initial.empty() && volume_deposits) {
    sums.resize(voxels);
    parallelFor(0, static_cast<std::int64_t>(voxels), [&](std::int64_t v) { sums[static_cast<std::size_t>(v)] = DepositSum{}; }, 1 << 14);
  }
  std::vector<double> best_key(accumulate || sums.empty() ? 0 : voxels, -1.0);

  // The patch lists and their samples: grown without writing the added elements (core/uninitialized.h),
  // which the parallel loops below then write in full, each thread faulting in its own share of
  // the fresh pages (a std::vector's `resize` wrote them all on this thread first).
  // Room for many times the initial patches in each per-patch array: address space costs nothing
  // until a page is touched, and the arrays then neither move nor touch fresh memory (which the
  // kernel zeroes, 2 MiB at a time) each time the wavefront outgrows them.
  const std::size_t capacity = std::max<std::size_t>(8 * initial.size(), std::size_t(1) << 16);
  UninitializedVector<Patch> patches, next;
  UninitializedVector<PatchSamples> samples, next_samples;
  patches.reserve(capacity);
  samples.reserve(capacity);
  next.reserve(capacity);
  next_samples.reserve(capacity);
  patches.resize(initial.size());
  samples.resize(initial.size());
  parallelFor(
      0, static_cast<std::int64_t>(initial.size()),
      [&](std::int64_t i64) {
        const std::size_t i = static_cast<std::size_t>(i64);
        patches[i] = initial[i];
        samples[i] = samplePatch(initial[i], sampler_);
      },
      256);
  std::vector<Patch>().swap(initial);
  std::vector<PatchStepResult> results;
  std::vector<std::vector<std::uint32_t>> slab_lists;
  std::vector<std::uint64_t> offsets;
  std::vector<std::uint32_t> received;  // this step's received patches
  std::vector<std::vector<std::uint32_t>> band_lists;  // …and those whose footprint reaches each band of map rows
  results.reserve(capacity);
  offsets.reserve(capacity + 1);
  double t_update = 0.0, t_deposit = 0.0, t_compact = 0.0;
  const double total_in = luminance(stats.flux_in);

  for (int step = 0; step < max_steps && !patches.empty(); ++step) {
    if (options.cancel && options.cancel->load(std::memory_order_relaxed)) throw BakeCancelled();
    const std::size_t count = patches.size();
    stats.steps = step + 1;
    stats.peak_patches = std::max<std::uint64_t>(stats.peak_patches, count);
    stats.total_patches += count;

    // Steps 1–5 per patch, in parallel (each patch independent: deterministic).
    Stopwatch t;
    results.resize(count);
    parallelFor(
        0, static_cast<std::int64_t>(count),
        [&](std::int64_t i64) {
          const std::size_t i = static_cast<std::size_t>(i64);
          results[i] = stepPatch(patches[i], samples[i], ctx);
        },
        256);
    t_update += t.seconds();

    // Deposits and the ledger, in patch order (deterministic sums).
    t.restart();
    if (track) applyTrackDeposits(patches, results, grid, ctx.receiver, sums, slab_lists);
    offsets.resize(count + 1);
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const PatchStepResult& r = results[i];
      const Patch& p = patches[i];
      const std::size_t bounce = static_cast<std::size_t>(std::max(p.bounce, 0));
      if (bounce >= stats.patch_steps_by_bounce.size()) {
        stats.patch_steps_by_bounce.resize(bounce + 1, 0);
        stats.flux_received_by_bounce.resize(bounce + 1, glm::dvec3(0.0));
      }
      ++stats.patch_steps_by_bounce[bounce];
      stats.flux_absorbed += r.absorbed;
      stats.flux_reflected += r.reflected;
      if (r.rolled_back) ++stats.rollbacks;
      if (r.flight) ++stats.flights;
      if (r.voxel >= 0 && volume_deposits) {
        const std::size_t v = static_cast<std::size_t>(r.voxel);
        if (accumulate) {
          sums[v].irradiance += r.deposit;
          sums[v].direction += r.deposit_dir;
        } else if (r.max_key > best_key[v]) {
          best_key[v] = r.max_key;
          sums[v].irradiance = r.deposit;
          sums[v].direction = r.deposit_dir;
        }
      }
      offsets[i] = total;
      switch (r.fate) {
        case PatchFate::Keep: total += 1; break;
        case PatchFate::Split:
          total += static_cast<std::size_t>(r.split.count());
          ++stats.splits;
          break;
        case PatchFate::KilledFlux:
          ++stats.kills.flux;
          stats.flux_killed += p.flux;
          break;
        case PatchFate::Exited:
          ++stats.kills.exited;
          stats.flux_out += p.flux;
          if (options.on_leave) options.on_leave(p);
          if (diagnostics) diagnostics->flux_out_by_face[exitFace(p.midpoint(), p.direction(), grid)] += p.flux;
          break;
        case PatchFate::Folded:
          ++stats.kills.folded;
          stats.flux_killed += p.flux;
          break;
        case PatchFate::KilledDepth:
          ++stats.kills.depth;
          stats.flux_killed += p.flux - r.received;
          if (r.received != glm::dvec3(0.0)) {  // the light it carried past the object (passingShare)
            stats.flux_received += r.received;
            stats.flux_received_by_bounce[bounce] += r.received;
            received.push_back(static_cast<std::uint32_t>(i));
          }
          break;
        case PatchFate::Trapped:
          ++stats.kills.trapped;
          stats.flux_unfinished += p.flux;
          break;
        case PatchFate::Received:
          ++stats.kills.received;
          stats.flux_received += r.received;
          stats.flux_received_by_bounce[bounce] += r.received;
          received.push_back(static_cast<std::uint32_t>(i));
          if (options.on_leave && !insideBox(p.midpoint(), ctx.box_lo, ctx.box_hi)) options.on_leave(p);
          break;
        case PatchFate::Blocked:
          ++stats.kills.blocked;
          stats.flux_blocked += p.flux;
          break;
      }
      if (r.spawn_reflection) {
        // The reflected wavefront is followed: its flux is no longer lost to reflection.
        total += 1;
        ++stats.reflections;
        stats.flux_reflected -= r.reflection->flux;
      }
    }
    offsets[count] = total;
    // The receiver's footprints, by bands of texel rows in parallel (each band adds the patches in
    // order, so the sums do not depend on the thread count).
    if (!received.empty()) {
      constexpr int kBandRows = FootprintSums::kBandRows;
      const int bands = receiver_flux->bands();
      band_lists.resize(static_cast<std::size_t>(bands));
      for (auto& list : band_lists) list.clear();
      for (const std::uint32_t i : received) {
        // The rows the footprint's box covers, hence the bands that get a share (one more on each
        // side for a coarse level, whose texel rows are found from its own, rounded, coordinates).
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const glm::dvec2& f : results[i].footprint) {
          lo = std::min(lo, f.y);
          hi = std::max(hi, f.y);
        }
        const double r0 = (lo - receiver.origin.y) / receiver.pitch, r1 = (hi - receiver.origin.y) / receiver.pitch;
        if (!(r1 >= 0.0 && r0 < receiver.texels.y)) continue;  // wholly off the map (or not finite)
        const int margin = receiver_flux->level(results[i].footprint) > 0 ? 1 : 0;
        const int b0 = std::max(0, static_cast<int>(std::max(0.0, r0)) / kBandRows - margin);
        const int b1 = std::min(bands - 1, static_cast<int>(std::min(static_cast<double>(receiver.texels.y - 1), r1)) / kBandRows + margin);
        for (int b = b0; b <= b1; ++b) band_lists[static_cast<std::size_t>(b)].push_back(i);
      }
      parallelFor(0, bands, [&](std::int64_t band) {
        for (const std::uint32_t i : band_lists[static_cast<std::size_t>(band)])
          receiver_flux->deposit(results[i].footprint, results[i].received, static_cast<int>(band));
      });
      received.clear();
    }
    t_deposit += t.seconds();

    // Step 6: compaction and expansion by the prefix sum, in index order (the histogram pyramid's
    // order: output slot k of source s with sub-index j = child j of the split; a reflection last).
    t.restart();
    next.resize(total);
    next_samples.resize(total);
    parallelFor(
        0, static_cast<std::int64_t>(count),
        [&](std::int64_t i64) {
          const std::size_t i = static_cast<std::size_t>(i64);
          const PatchStepResult& r = results[i];
          std::size_t out = offsets[i];
          const std::size_t n_out = offsets[i + 1] - out - (r.spawn_reflection ? 1 : 0);
          if (n_out == 1) {
            next[out] = patches[i];
            next_samples[out] = samples[i];
          } else if (n_out > 1) {
            std::array<std::array<glm::dvec4, 4>, 4> corner_samples;
            std::array<Patch, 4> children;
            const int made = splitPatch(patches[i], sampler_, r.split, children, &corner_samples);
            for (int j = 0; j < made; ++j) {
              next[out + j] = children[j];
              next_samples[out + j].corner = corner_samples[j];
              next_samples[out + j].n_mid = sampler_.ior(children[j].midpoint());
            }
          }
          if (r.spawn_reflection) {
            out += n_out;
            next[out] = *r.reflection;
            next_samples[out] = samplePatch(*r.reflection, sampler_);
            for (int c = 0; c < 4; ++c)
              next_samples[out].corner[c] = sampler_.materialOptics(r.reflection->medium[c], r.reflection->x[c]);
          }
        },
        256);
    patches.swap(next);
    samples.swap(next_samples);
    t_compact += t.seconds();

    if (options.progress && total_in > 0.0) {
      const double retired = luminance(stats.flux_out + stats.flux_absorbed + stats.flux_reflected + stats.flux_killed +
                                       stats.flux_received + stats.flux_blocked) /
                             total_in;
      options.progress(std::min(1.0, retired));
    }
  }
  for (const Patch& p : patches) stats.flux_unfinished += p.flux;
  // The direct light's cells: in, and received (after the run, so that the progress counts the
  // followed light only).
  stats.flux_in += direct.flux;
  stats.flux_received += direct.flux;
  if (stats.flux_received_by_bounce.empty()) stats.flux_received_by_bounce.resize(1, glm::dvec3(0.0));
  if (stats.patch_steps_by_bounce.empty()) stats.patch_steps_by_bounce.resize(1, 0);
  stats.flux_received_by_bounce[0] += direct.flux;
  // The step's arrays go back to the allocator before the output is made, which then reuses their
  // memory (the 128³ sphere's map, 12 MB, and its file's buffers) instead of touching fresh pages.
  auto release = [](auto& v) { std::remove_reference_t<decltype(v)>().swap(v); };
  release(patches);
  release(next);
  release(samples);
  release(next_samples);
  release(results);
  release(offsets);
  release(slab_lists);
  release(band_lists);

  // Output fields.
  phase.restart();
  bake.irradiance.components = 3;
  bake.light_dir.components = 3;
  if (volume_deposits) {
    bake.irradiance.data.assign(voxels * 3, 0.0f);
    bake.light_dir.data.assign(voxels * 3, 0.0f);
  }
  if (!sums.empty()) {
    parallelFor(
        0, static_cast<std::int64_t>(voxels),
        [&](std::int64_t v64) {
          const std::size_t v = static_cast<std::size_t>(v64);
          float* e = bake.irradiance.voxel(v);
          float* d = bake.light_dir.voxel(v);
          for (int c = 0; c < 3; ++c) e[c] = static_cast<float>(sums[v].irradiance[c]);
          const double len = glm::length(sums[v].direction);
          if (len > 0.0)
            for (int c = 0; c < 3; ++c) d[c] = static_cast<float>(sums[v].direction[c] / len);
        },
        4096);
  }
  if (options.receiver) {
    // Planar irradiance: each texel's flux over its area.
    receiver_flux->irradiance(direct_light ? &*direct_light : nullptr, 1.0 / (receiver.pitch * receiver.pitch),
                              receiver.irradiance);
    receiver.components = receiver_flux->channels();
    bake.receivers.push_back(std::move(receiver));
  }
  stats.phase_seconds["update"] = t_update;
  stats.phase_seconds["deposit"] = t_deposit;
  stats.phase_seconds["compact"] = t_compact;
  stats.phase_seconds["output"] = phase.seconds();
  if (options.progress) options.progress(1.0);
  return bake;
}

}  // namespace eik
