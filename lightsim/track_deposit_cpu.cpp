// The CPU twin's track deposits in SIMD (track_deposit_cpu.h). Highway compiles this file once per
// target (foreach_target.h re-includes it): everything inside eik::HWY_NAMESPACE exists once per
// target and is compiled for it; what is under HWY_ONCE exists once.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "lightsim/track_deposit_cpu.cpp"
// SSSE3 adds nothing to SSE4 for doubles, AVX3_DL nothing to AVX3: not compiled.
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_SSSE3 | HWY_AVX3_DL)
#endif
#include <hwy/foreach_target.h>  // before highway.h
#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#if HWY_ARCH_X86 && (defined(__GNUC__) || defined(__clang__))
#include <cpuid.h>
#endif

#include "core/error.h"
#include "core/parallel.h"
#include "lightsim/track_deposit.h"
#include "lightsim/track_deposit_cpu.h"

HWY_BEFORE_NAMESPACE();
namespace eik {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The lanes of a voxel's sums (DepositSum): irradiance and direction, four each.
constexpr std::size_t kSumLanes = 8;

// sum += w·c over a voxel's eight lanes (one cache line; aligned).
HWY_INLINE void addWeighted(double* HWY_RESTRICT sum, const double* HWY_RESTRICT c, double w) {
  const hn::CappedTag<double, kSumLanes> d;
  const auto vw = hn::Set(d, w);
  for (std::size_t i = 0; i < kSumLanes; i += hn::Lanes(d))
    hn::Store(hn::MulAdd(vw, hn::Load(d, c + i), hn::Load(d, sum + i)), d, sum + i);
}

// sum += w0·c0 + w1·c1: the two Gauss nodes of a piece, each with its own flux.
HWY_INLINE void addWeighted2(double* HWY_RESTRICT sum, const double* HWY_RESTRICT c0, double w0,
                             const double* HWY_RESTRICT c1, double w1) {
  const hn::CappedTag<double, kSumLanes> d;
  const auto v0 = hn::Set(d, w0), v1 = hn::Set(d, w1);
  for (std::size_t i = 0; i < kSumLanes; i += hn::Lanes(d))
    hn::Store(hn::MulAdd(v0, hn::Load(d, c0 + i), hn::MulAdd(v1, hn::Load(d, c1 + i), hn::Load(d, sum + i))), d,
              sum + i);
}

// A decaying flux's sums at one Gauss node t, the lanes of coef (DepositSum's order):
// E·e^(−κt) per channel, and the direction sum D scaled by the luminance of that decayed flux,
// Σ_c share_c·e^(−κ_c t). k4 = (κ_r, κ_g, κ_b, 0), e4 = (E, 0), d4 = (D, 0), share4 = (Φ_c/Σ Φ, 0).
// A step's decay is mostly small (κt ≤ ¼: a few voxels of absorption, a Fresnel loss), where the
// Taylor series of e^(−x) to x⁵ is within 3.4·10⁻⁷ (x⁶/720) at a fraction of Exp's cost.
HWY_INLINE void nodeCoefficients(const double* HWY_RESTRICT k4, const double* HWY_RESTRICT e4,
                                 const double* HWY_RESTRICT d4, const double* HWY_RESTRICT share4, double t,
                                 bool taylor, double* HWY_RESTRICT coef) {
  const hn::CappedTag<double, 4> d;
  const auto vt = hn::Set(d, t);
  auto dot = hn::Zero(d);
  for (std::size_t i = 0; i < 4; i += hn::Lanes(d)) {
    const auto x = hn::Mul(hn::Load(d, k4 + i), vt);
    hn::Vec<decltype(d)> f;
    if (taylor) {
      // 1 − x(1 − x(½ − x(1/6 − x(1/24 − x/120)))), by Horner's rule.
      f = hn::NegMulAdd(x, hn::Set(d, 1.0 / 120.0), hn::Set(d, 1.0 / 24.0));
      f = hn::NegMulAdd(x, f, hn::Set(d, 1.0 / 6.0));
      f = hn::NegMulAdd(x, f, hn::Set(d, 0.5));
      f = hn::NegMulAdd(x, f, hn::Set(d, 1.0));
      f = hn::NegMulAdd(x, f, hn::Set(d, 1.0));
    } else {
      f = hn::Exp(d, hn::Neg(x));
    }
    hn::Store(hn::Mul(hn::Load(d, e4 + i), f), d, coef + i);
    dot = hn::MulAdd(hn::Load(d, share4 + i), f, dot);
  }
  const auto scale = hn::SumOfLanes(d, dot);
  for (std::size_t i = 0; i < 4; i += hn::Lanes(d)) hn::Store(hn::Mul(hn::Load(d, d4 + i), scale), d, coef + 4 + i);
}

// The sub-paths of the patch-steps in `list` (patch order), within slab `slab`'s voxels.
void depositSlab(std::span<const Patch> patches, std::span<const PatchStepResult> results,
                 const GridSpec& grid, const ReceiverMap* receiver, DepositSum* sums,
                 const std::vector<std::uint32_t>& list, int slab, int slab_depth) {
  const double inv_volume = 1.0 / grid.voxelVolume();
  const glm::dvec3 h = grid.voxelSize(), inv_h = 1.0 / h;
  // The receiver's plane in voxel coordinates: height dot(v, plane_normal) + plane_offset.
  const glm::dvec3 plane_normal = receiver ? receiver->normal * h : glm::dvec3(0.0);
  const double plane_offset = receiver ? glm::dot(grid.bounds_min - receiver->point, receiver->normal) : 0.0;
  const long long sy = grid.dims.x, sz = static_cast<long long>(grid.dims.x) * grid.dims.y;
  const long long corner_offset[8] = {0, 1, sy, 1 + sy, sz, 1 + sz, sy + sz, 1 + sy + sz};
  // This slab's slices, z0 ≤ z < z1: a voxel belongs to one slab.
  const int z0 = slab * slab_depth, z1 = std::min(grid.dims.z, z0 + slab_depth);
  const double reach_lo = static_cast<double>(z0) - 0.5, reach_hi = static_cast<double>(z1) + 0.5;
  auto sumAt = [&](long long voxel) { return reinterpret_cast<double*>(sums + voxel); };
  // Whether corner k of a lattice cell is a voxel of this slab (and of the grid).
  auto cornerIn = [&](const TrackCell& c, int k) {
    const int x = c.cell.x + (k & 1), y = c.cell.y + ((k >> 1) & 1), z = c.cell.z + ((k >> 2) & 1);
    return x >= 0 && y >= 0 && z >= z0 && x < grid.dims.x && y < grid.dims.y && z < z1;
  };
  for (const std::uint32_t i : list) {
    const PatchStepResult& r = results[i];
    const Patch& p = patches[i];
    const double sub_paths = static_cast<double>(r.lattice.x * r.lattice.y);
    // A flux that changes along the step (absorption, Fresnel) goes from start to end
    // geometrically, Φ(t) = Φ_start·exp(−κ t) per channel with κ = ln(Φ_start/Φ_end): exact for
    // absorption in one material, where a flight or a straight step may cross several voxels, and
    // like the mean over a step of Δt otherwise. The path is then weighted at each Gauss node.
    double kappa[3] = {0.0, 0.0, 0.0};
    bool decays = false;
    if (r.track_start != r.track_end) {
      for (int c = 0; c < 3; ++c) {
        kappa[c] = r.track_start[c] > 0.0 && r.track_end[c] > 0.0
                       ? std::clamp(std::log(r.track_start[c] / r.track_end[c]), -kMaxTrackDecay, kMaxTrackDecay)
                       : (r.track_start[c] > 0.0 ? kMaxTrackDecay : 0.0);
        decays |= std::fabs(kappa[c]) > kMeanTrackDecay;
      }
    }
    const glm::dvec3 flux = (decays ? r.track_start : r.track_flux) / sub_paths;
    const double lum = luminance(flux);
    // A node's direction sum scales with the luminance of its decayed flux: Σ flux_c f_c / Σ flux_c.
    const glm::dvec3 lum_share = lum > 0.0 ? flux / (3.0 * lum) : glm::dvec3(0.0);
    alignas(32) const double k4[4] = {kappa[0], kappa[1], kappa[2], 0.0};
    alignas(32) const double share4[4] = {lum_share.x, lum_share.y, lum_share.z, 0.0};
    // κt ≤ ¼ at every node (t ≤ 1): the Taylor series serves the whole step.
    const bool taylor = std::max({std::fabs(kappa[0]), std::fabs(kappa[1]), std::fabs(kappa[2])}) <= 0.25;
    // The corners in voxel coordinates: the bilinear patch commutes with the affine map to them, so
    // each sub-path's ends are found there directly; world lengths are voxel spans times h.
    std::array<glm::dvec3, 4> from_voxel, to_voxel;
    for (int c = 0; c < 4; ++c) {
      from_voxel[c] = (r.from[c] - grid.bounds_min) * inv_h;
      to_voxel[c] = (p.x[c] - grid.bounds_min) * inv_h;
    }
    const bool clip = r.clip_to_receiver && receiver;
    for (int iv = 0; iv < r.lattice.y; ++iv)
      for (int iu = 0; iu < r.lattice.x; ++iu) {
        const double u = (iu + 0.5) / r.lattice.x, v = (iv + 0.5) / r.lattice.y;
        glm::dvec3 va = bilinear(from_voxel, u, v), vb = bilinear(to_voxel, u, v);
        // The part of the sub-path within reach of this slab's hats (voxel z-coordinates
        // (z0 − ½, z1 + ½) for slices z0..z1 − 1), the weights scaled by its share of the length:
        // a long flight across many slabs is integrated once, not once a slab. Tested first: most
        // sub-paths of a patch-step that reaches two slabs are in one.
        if (!clip && (std::max(va.z, vb.z) <= reach_lo || std::min(va.z, vb.z) >= reach_hi)) continue;
        double t_b = 1.0;  // the step's parameter at b (short of 1 where the receiver cuts it)
        if (clip) {
          // Height above the receiver's plane, an affine function of the voxel coordinates.
          const double ha = glm::dot(va, plane_normal) + plane_offset;
          const double hb = glm::dot(vb, plane_normal) + plane_offset;
          if (ha <= 0.0) continue;  // this sub-path is already under the plane
          if (hb < 0.0) {
            t_b = ha / (ha - hb);
            vb = va + t_b * (vb - va);
          }
        }
        const glm::dvec3 step = (vb - va) * h;  // b − a, world units
        const double length = glm::length(step);
        if (!(length > 0.0)) continue;
        double share = 1.0;
        double t_a = 0.0;
        if (std::min(va.z, vb.z) < reach_lo || std::max(va.z, vb.z) > reach_hi) {
          const double dz = vb.z - va.z;
          double f0 = 0.0, f1 = 1.0;
          if (dz != 0.0) {
            const double g0 = (reach_lo - va.z) / dz, g1 = (reach_hi - va.z) / dz;
            f0 = std::max(0.0, std::min(g0, g1));
            f1 = std::min(1.0, std::max(g0, g1));
          }
          if (!(f1 > f0)) continue;
          const glm::dvec3 span = vb - va;
          vb = va + f1 * span;
          va = va + f0 * span;
          share = f1 - f0;
          const double t_span = t_b;
          t_b = t_span * f1;
          t_a = t_span * f0;
        }
        // The sums' lanes for this sub-path: Φ·length/V and lum(Φ)·length·d = lum(Φ)·(b − a).
        const glm::dvec3 e = flux * (length * inv_volume * share);
        const glm::dvec3 dsum = (lum * share) * step;
        if (decays) {
          alignas(32) const double e4[4] = {e.x, e.y, e.z, 0.0}, d4[4] = {dsum.x, dsum.y, dsum.z, 0.0};
          // Per Gauss node n: the flux there, Φ·exp(−κ t_n), in both sums.
          forEachTrackCell<true>(
              va, vb, grid.dims,
              [&](const TrackCell& c) {
                alignas(64) double coef[2][kSumLanes];
                for (int n = 0; n < 2; ++n)
                  nodeCoefficients(k4, e4, d4, share4, c.node_t[static_cast<std::size_t>(n)], taylor, coef[n]);
                const bool whole = c.interior && c.cell.z >= z0 && c.cell.z + 1 < z1;
                for (int k = 0; k < 8; ++k) {
                  if (!whole && !cornerIn(c, k)) continue;
                  addWeighted2(sumAt(c.origin + corner_offset[k]), coef[0], c.node_weight[0][static_cast<std::size_t>(k)],
                               coef[1], c.node_weight[1][static_cast<std::size_t>(k)]);
                }
              },
              t_a, t_b);
          continue;
        }
        alignas(64) const double coef[kSumLanes] = {e.x, e.y, e.z, 0.0, dsum.x, dsum.y, dsum.z, 0.0};
        forEachTrackCell(va, vb, grid.dims, [&](const TrackCell& c) {
          // The cell's two slices of voxels, each in this slab or not; within the grid otherwise,
          // as TrackCell::interior says, or checked voxel by voxel.
          const bool whole = c.interior && c.cell.z >= z0 && c.cell.z + 1 < z1;
          for (int k = 0; k < 8; ++k) {
            if (!whole && !cornerIn(c, k)) continue;
            addWeighted(sumAt(c.origin + corner_offset[k]), coef, c.weight[static_cast<std::size_t>(k)]);
          }
        });
      }
  }
}
}  // namespace HWY_NAMESPACE
}  // namespace eik
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace eik {

namespace {

// The dispatch among the compiled targets is ours, not Highway's HWY_EXPORT / HWY_DYNAMIC_DISPATCH:
// those call into libhwy.so (its target choice and CPU detection), and merely loading that library
// costs every process 4–5 ms (a static initialiser of Debian's Highway 1.0.3 measures its timer's
// resolution at start-up; BENCHMARKS.md), paid by `lightsim` and the viewer even where no deposit
// runs. Highway is used header-only: its per-target code (foreach_target.h) and its names.
using DepositSlabFn = decltype(&HWY_STATIC_DISPATCH(depositSlab));

struct CompiledTarget {
  std::int64_t target;  // a HWY_* bit
  DepositSlabFn deposit;
};

// Whether this CPU (and its operating system, which must save the wide registers) runs a target's
// code: the instruction sets Highway compiles each x86 target for (hwy/targets.h; its detection,
// with the compiler's CPU tests and CPUID for the two they lack in Clang).
bool cpuRuns(std::int64_t target) {
#if HWY_ARCH_X86 && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  const bool sse4 = __builtin_cpu_supports("ssse3") && __builtin_cpu_supports("sse4.1") &&
                    __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("pclmul") && __builtin_cpu_supports("aes");
  if (target == HWY_SSE4) return sse4;
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  const bool f16c = __get_cpuid(1, &eax, &ebx, &ecx, &edx) && (ecx & (1u << 29)) != 0;         // CPUID.1:ECX.F16C
  const bool lzcnt = __get_cpuid(0x80000001u, &eax, &ebx, &ecx, &edx) && (ecx & (1u << 5)) != 0;  // CPUID.80000001h:ECX.LZCNT
  const bool avx2 = sse4 && __builtin_cpu_supports("avx") && __builtin_cpu_supports("avx2") &&
                    __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
                    f16c && lzcnt;
  if (target == HWY_AVX2) return avx2;
  if (target == HWY_AVX3)
    return avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
#endif
  return target == HWY_STATIC_TARGET || target == HWY_SCALAR || target == HWY_EMU128;
}

// The compiled targets this CPU runs, best first; the portable fallback last, always.
const std::vector<CompiledTarget>& runnableTargets() {
  static const std::vector<CompiledTarget> list = [] {
    std::vector<CompiledTarget> all;
#if HWY_ARCH_X86
    all.push_back({HWY_AVX3, HWY_CHOOSE_AVX3(depositSlab)});
    all.push_back({HWY_AVX2, HWY_CHOOSE_AVX2(depositSlab)});
    all.push_back({HWY_SSE4, HWY_CHOOSE_SSE4(depositSlab)});
#endif
    if (HWY_STATIC_TARGET != HWY_SCALAR && HWY_STATIC_TARGET != HWY_EMU128)
      all.push_back({HWY_STATIC_TARGET, &HWY_STATIC_DISPATCH(depositSlab)});
    all.push_back({(HWY_TARGETS & HWY_EMU128) ? HWY_EMU128 : HWY_SCALAR, HWY_CHOOSE_FALLBACK(depositSlab)});
    std::vector<CompiledTarget> runs;
    for (const CompiledTarget& t : all) {
      const bool listed = std::any_of(runs.begin(), runs.end(), [&](const CompiledTarget& r) { return r.target == t.target; });
      if (t.deposit && !listed && cpuRuns(t.target)) runs.push_back(t);
    }
    return runs;
  }();
  return list;
}

// The target the deposits run on (its index in runnableTargets(); `chosen` once one is): the best
// one the CPU runs, or the one EIKONAL_SIMD or setTrackDepositTarget picks.
std::atomic<std::size_t> current_index{0};
std::atomic<bool> chosen{false};

// The first deposit's choice: EIKONAL_SIMD's target when it names one, else the best.
void chooseOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (chosen.load()) return;  // setTrackDepositTarget came first
    std::size_t index = 0;
    const std::vector<CompiledTarget>& targets = runnableTargets();
    if (const char* name = std::getenv("EIKONAL_SIMD"); name && *name)
      for (std::size_t i = 0; i < targets.size(); ++i)
        if (std::string(hwy::TargetName(targets[i].target)) == name) index = i;
    current_index.store(index);
    chosen.store(true);
  });
}

}  // namespace

std::vector<std::string> trackDepositTargets() {
  std::vector<std::string> names;
  for (const CompiledTarget& t : runnableTargets()) names.emplace_back(hwy::TargetName(t.target));
  return names;
}

std::string trackDepositTarget() {
  chooseOnce();
  return hwy::TargetName(runnableTargets()[current_index.load()].target);
}

void setTrackDepositTarget(const std::string& name) {
  const std::vector<CompiledTarget>& targets = runnableTargets();
  for (std::size_t i = 0; i < targets.size(); ++i)
    if (name.empty() || name == "best" || name == hwy::TargetName(targets[i].target)) {
      current_index.store(i);
      chosen.store(true);
      return;
    }
  std::string known;
  for (const std::string& n : trackDepositTargets()) known += (known.empty() ? "" : ", ") + n;
  throw InputError("SIMD target \"" + name + "\": not one this build runs here (" + known + ")");
}

void applyTrackDeposits(std::span<const Patch> patches, std::span<const PatchStepResult> results,
                        const GridSpec& grid, const ReceiverMap* receiver, std::span<DepositSum> sums,
                        std::vector<std::vector<std::uint32_t>>& by_slab) {
  chooseOnce();
  const DepositSlabFn deposit = runnableTargets()[current_index.load()].deposit;
  const std::size_t count = results.size();
  const glm::dvec3 h = grid.voxelSize();
  // Slabs of z-slices, and the patches whose hats reach each one (in patch order). The slabs do
  // not depend on the thread count: a sub-path is cut to each slab's reach, and where it is cut
  // changes the last bits of its sums.
  constexpr int slab_depth = 8;
  const int slabs = (grid.dims.z + slab_depth - 1) / slab_depth;
  by_slab.resize(static_cast<std::size_t>(slabs));
  for (auto& list : by_slab) list.clear();
  for (std::size_t i = 0; i < count; ++i) {
    const PatchStepResult& r = results[i];
    if (!r.track || r.rolled_back) continue;
    double zlo = std::numeric_limits<double>::infinity(), zhi = -zlo;
    for (int c = 0; c < 4; ++c) {
      zlo = std::min(zlo, std::min(r.from[c].z, patches[i].x[c].z));
      zhi = std::max(zhi, std::max(r.from[c].z, patches[i].x[c].z));
    }
    // Hats reach one voxel centre beyond the path: slices whose centre is within h of [zlo, zhi].
    const int k0 = std::max(0, static_cast<int>(std::floor((zlo - grid.bounds_min.z) / h.z - 1.5)));
    const int k1 = std::min(grid.dims.z - 1, static_cast<int>(std::floor((zhi - grid.bounds_min.z) / h.z + 0.5)));
    for (int slab = k0 / slab_depth; slab <= k1 / slab_depth && slab < slabs; ++slab)
      by_slab[static_cast<std::size_t>(slab)].push_back(static_cast<std::uint32_t>(i));
  }
  parallelFor(0, slabs, [&](std::int64_t slab) {
    deposit(patches, results, grid, receiver, sums.data(), by_slab[static_cast<std::size_t>(slab)], static_cast<int>(slab),
            slab_depth);
  });
}

}  // namespace eik
#endif  // HWY_ONCE
