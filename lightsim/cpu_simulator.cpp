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
#include <limits>
#include <string>
#include <vector>

#include "core/parallel.h"
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

PatchStepResult stepPatch(Patch& patch, const StepContext& ctx) {
  PatchSamples samples = samplePatch(patch, *ctx.sampler);
  return stepPatch(patch, samples, ctx);
}

PatchStepResult stepPatch(Patch& patch, PatchSamples& samples, const StepContext& ctx) {
  const VolumeSampler& sampler = *ctx.sampler;
  const SimulationOptions& options = *ctx.options;
  const GridSpec& grid = sampler.grid();
  const double h = sampler.h();
  PatchStepResult result;

  const glm::dvec3 m_old = patch.midpoint();
  const glm::dvec3 d_old = patch.direction();
  const double n_m_old = samples.n_mid;
  const double ds = ctx.dt / n_m_old;  // Δs_m = Δt/n(m) (Eq. 4.11)

  // 1. Update (§6.2.2, Eq. 6.1/6.2 or RK2/RK4), then |w| = n(x_new).
  for (int c = 0; c < 4; ++c)
    advanceCorner(patch.x[c], patch.w[c], samples.corner[c], ctx.dt, options.integrator, sampler);

  // 2. Absorption at the old midpoint: Φ ← Φ·exp(−σa(m)·Δs_m) (Beer–Lambert).
  if (sampler.hasAbsorption()) {
    const glm::dvec3 sigma = sampler.sigmaA(m_old);
    const glm::dvec3 transmitted = glm::exp(-sigma * ds);
    result.absorbed = patch.flux * (1.0 - transmitted);
    patch.flux *= transmitted;
  }

  // 3. Fresnel at boundary layers (docs/physics.md; fresnelReflectance, wavefront.h).
  const glm::dvec3 m_new = patch.midpoint();
  const glm::dvec3 d_new = patch.direction();
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

  // 4. Deposit record (§6.2.3): the voxel of the new midpoint, only inside the grid.
  const glm::dvec3 N = patch.areaVector();
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

  // 5. Analysis (§6.2.4).
  if (maxChannel(patch.flux) < fluxKillThreshold(ctx.flux_ref, options, patch.depth)) {
    result.fate = PatchFate::KilledFlux;
  } else if (!insideBox(m_new, grid.bounds_min, grid.bounds_max) &&
             !rayHitsBox(m_new, d_new, grid.bounds_min, grid.bounds_max)) {
    result.fate = PatchFate::Exited;
  } else if (options.deposit == DepositMode::Max && !(glm::dot(N, d_new) > 0.0)) {
    result.fate = PatchFate::Folded;  // orientation flipped: a caustic singularity
  } else if ((result.split = splitAxes(patch, splitThreshold(grid, options), options.split_rule)).any()) {
    const bool keep = options.at_max_depth == DepthLimit::Keep &&
                      patch.longestEdge() <= kMaxUnsplitEdge * splitThreshold(grid, options);
    result.fate = patch.depth < options.max_depth ? PatchFate::Split : keep ? PatchFate::Keep : PatchFate::KilledDepth;
  } else {
    result.fate = PatchFate::Keep;
  }
  return result;
}

CpuSimulator::CpuSimulator(const Volume& volume) : sampler_(volume) {}

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

  Stopwatch phase;
  double flux_ref = 0.0;
  std::vector<Patch> patches = initialPatches(light, grid, sampler_, options, &flux_ref);
  stats.initial_patches = patches.size();
  for (const Patch& p : patches) stats.flux_in += p.flux;
  stats.phase_seconds["init"] = phase.seconds();

  StepContext ctx;
  ctx.sampler = &sampler_;
  ctx.options = &options;
  ctx.dt = timeStep(grid, options);
  ctx.flux_ref = flux_ref;
  ctx.voxel_volume = grid.voxelVolume();
  const int max_steps = maxSteps(grid, options);
  const bool accumulate = options.deposit == DepositMode::Accumulate;

  // Deposit targets, in double (accumulate) or the strongest patch so far (max).
  std::vector<glm::dvec3> irradiance(patches.empty() ? 0 : voxels, glm::dvec3(0.0));
  std::vector<glm::dvec3> direction(patches.empty() ? 0 : voxels, glm::dvec3(0.0));
  std::vector<double> best_key(accumulate || patches.empty() ? 0 : voxels, -1.0);

  std::vector<PatchSamples> samples(patches.size());
  parallelFor(
      0, static_cast<std::int64_t>(patches.size()),
      [&](std::int64_t i) { samples[static_cast<std::size_t>(i)] = samplePatch(patches[static_cast<std::size_t>(i)], sampler_); },
      256);
  std::vector<PatchStepResult> results;
  std::vector<std::uint64_t> offsets;
  std::vector<Patch> next;
  std::vector<PatchSamples> next_samples;
  double t_update = 0.0, t_deposit = 0.0, t_compact = 0.0;
  const double total_in = luminance(stats.flux_in);

  for (int step = 0; step < max_steps && !patches.empty(); ++step) {
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

    // Deposit and the ledger, sequentially in patch order (deterministic sums).
    t.restart();
    offsets.resize(count + 1);
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const PatchStepResult& r = results[i];
      const Patch& p = patches[i];
      stats.flux_absorbed += r.absorbed;
      stats.flux_reflected += r.reflected;
      if (r.voxel >= 0) {
        const std::size_t v = static_cast<std::size_t>(r.voxel);
        if (accumulate) {
          irradiance[v] += r.deposit;
          direction[v] += r.deposit_dir;
        } else if (r.max_key > best_key[v]) {
          best_key[v] = r.max_key;
          irradiance[v] = r.deposit;
          direction[v] = r.deposit_dir;
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
          if (diagnostics) diagnostics->flux_out_by_face[exitFace(p.midpoint(), p.direction(), grid)] += p.flux;
          break;
        case PatchFate::Folded:
          ++stats.kills.folded;
          stats.flux_killed += p.flux;
          break;
        case PatchFate::KilledDepth:
          ++stats.kills.depth;
          stats.flux_killed += p.flux;
          break;
      }
    }
    offsets[count] = total;
    t_deposit += t.seconds();

    // Step 6: compaction and expansion by the prefix sum, in index order (the histogram pyramid's
    // order: output slot k of source s with sub-index j = child j of the split).
    t.restart();
    next.resize(total);
    next_samples.resize(total);
    parallelFor(
        0, static_cast<std::int64_t>(count),
        [&](std::int64_t i64) {
          const std::size_t i = static_cast<std::size_t>(i64);
          const std::size_t out = offsets[i];
          const std::size_t n_out = offsets[i + 1] - out;
          if (n_out == 1) {
            next[out] = patches[i];
            next_samples[out] = samples[i];
          } else if (n_out > 1) {
            std::array<std::array<glm::dvec4, 4>, 4> corner_samples;
            std::array<Patch, 4> children;
            const int count = splitPatch(patches[i], sampler_, results[i].split, children, &corner_samples);
            for (int j = 0; j < count; ++j) {
              next[out + j] = children[j];
              next_samples[out + j].corner = corner_samples[j];
              next_samples[out + j].n_mid = sampler_.ior(children[j].midpoint());
            }
          }
        },
        256);
    patches.swap(next);
    samples.swap(next_samples);
    t_compact += t.seconds();

    if (options.progress && total_in > 0.0) {
      const double retired =
          luminance(stats.flux_out + stats.flux_absorbed + stats.flux_reflected + stats.flux_killed) / total_in;
      options.progress(std::min(1.0, retired));
    }
  }
  for (const Patch& p : patches) stats.flux_unfinished += p.flux;

  // Output fields.
  phase.restart();
  bake.irradiance.components = 3;
  bake.irradiance.data.assign(voxels * 3, 0.0f);
  bake.light_dir.components = 3;
  bake.light_dir.data.assign(voxels * 3, 0.0f);
  if (!irradiance.empty()) {
    parallelFor(
        0, static_cast<std::int64_t>(voxels),
        [&](std::int64_t v64) {
          const std::size_t v = static_cast<std::size_t>(v64);
          float* e = bake.irradiance.voxel(v);
          float* d = bake.light_dir.voxel(v);
          for (int c = 0; c < 3; ++c) e[c] = static_cast<float>(irradiance[v][c]);
          const double len = glm::length(direction[v]);
          if (len > 0.0)
            for (int c = 0; c < 3; ++c) d[c] = static_cast<float>(direction[v][c] / len);
        },
        4096);
  }
  stats.phase_seconds["update"] = t_update;
  stats.phase_seconds["deposit"] = t_deposit;
  stats.phase_seconds["compact"] = t_compact;
  stats.phase_seconds["output"] = phase.seconds();
  if (options.progress) options.progress(1.0);
  return bake;
}

}  // namespace eik
