// The CPU twin's track deposits in SIMD (track_deposit_cpu.h), on every target this build runs
// here, against a brute-force integral of the hats along each sub-path written for the test.
#include "lightsim/track_deposit_cpu.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

#include "core/error.h"
#include "lightsim/test_scenes.h"
#include "lightsim/track_deposit.h"

namespace eik {
namespace {

using test_scenes::ScopedThreads;

// A step's patch-steps made by hand on a grid of four slabs (z 0–31): the corners before (`from`)
// and after (the patch's), the sub-path lattice and the flux from the start to the end of the step.
struct HandStep {
  std::vector<Patch> patches;
  std::vector<PatchStepResult> results;
};

void addStep(HandStep& s, const std::array<glm::dvec3, 4>& from, const glm::dvec3& move, glm::ivec2 lattice,
             const glm::dvec3& flux_start, const glm::dvec3& flux_end) {
  Patch p;
  PatchStepResult r;
  for (int c = 0; c < 4; ++c) p.x[c] = from[c] + move;
  r.track = true;
  r.from = from;
  r.lattice = lattice;
  r.track_start = flux_start;
  r.track_end = flux_end;
  r.track_flux = 0.5 * (flux_start + flux_end);
  s.patches.push_back(p);
  s.results.push_back(std::move(r));
}

// A square of half-width e around c in the plane ⟂ z, tilted by `tilt` along x.
std::array<glm::dvec3, 4> square(glm::dvec3 c, double e, double tilt = 0.0) {
  return {c + glm::dvec3(-e, -e, -tilt), c + glm::dvec3(e, -e, tilt), c + glm::dvec3(e, e, tilt),
          c + glm::dvec3(-e, e, -tilt)};
}

GridSpec handGrid() {
  GridSpec g;
  g.dims = {20, 18, 30};  // four slabs of 8 z-slices, the last one short
  g.bounds_min = {-1.0, -0.9, -1.5};
  g.bounds_max = g.bounds_min + glm::dvec3(g.dims) * 0.1;  // h = 0.1
  return g;
}

HandStep handSteps() {
  HandStep s;
  const glm::dvec3 white(1.0, 1.0, 1.0);
  // Short steps inside one slab and across a slab boundary (z = −0.7 is slice 8's lower face).
  addStep(s, square({0.1, 0.05, -0.9}, 0.13, 0.02), {0.03, -0.02, 0.21}, {3, 2}, 0.5 * white, 0.5 * white);
  addStep(s, square({-0.3, 0.2, -0.75}, 0.08), {0.01, 0.04, 0.1}, {2, 2}, {0.2, 0.3, 0.4}, {0.2, 0.3, 0.4});
  // A flight through every slab, leaving the grid at the top (z > 1.5) and the side (x > 1).
  addStep(s, square({-0.6, -0.4, -1.7}, 0.05), {1.9, 0.9, 3.6}, {1, 2}, white, white);
  // Absorbing glass: the flux falls by e^(−κ) per channel over the step, κ = (0.3, 1, 2.5) (the
  // last beyond the Taylor series' reach, ¼), and a Fresnel-sized loss (κ = 0.04, grey).
  addStep(s, square({0.2, -0.3, 0.1}, 0.1, 0.03), {-0.05, 0.1, 0.45}, {2, 3}, {1.0, 0.8, 0.6},
          {std::exp(-0.3), 0.8 * std::exp(-1.0), 0.6 * std::exp(-2.5)});
  addStep(s, square({0.45, 0.5, 0.9}, 0.06), {0.02, 0.02, -0.12}, {1, 1}, white, 0.96 * white);
  // A step that does not deposit: rolled back.
  addStep(s, square({0.0, 0.0, 0.0}, 0.2), {0.0, 0.0, 0.3}, {4, 4}, white, white);
  s.results.back().rolled_back = true;
  return s;
}

// ∫ K_v(x(t)) Φ(t)·|b − a|/V dt along each sub-path by brute force (midpoint rule, 4·10⁴ samples a
// sub-path), Φ(t) = Φ_start·(Φ_end/Φ_start)^t per channel; the direction sum likewise with
// lum(Φ(t))·(b − a).
std::vector<DepositSum> bruteForce(const HandStep& s, const GridSpec& g) {
  std::vector<DepositSum> sums(g.count());
  const double inv_volume = 1.0 / g.voxelVolume();
  for (std::size_t i = 0; i < s.results.size(); ++i) {
    const PatchStepResult& r = s.results[i];
    if (r.rolled_back) continue;
    const double n_sub = r.lattice.x * r.lattice.y;
    for (int iv = 0; iv < r.lattice.y; ++iv)
      for (int iu = 0; iu < r.lattice.x; ++iu) {
        const double u = (iu + 0.5) / r.lattice.x, v = (iv + 0.5) / r.lattice.y;
        const glm::dvec3 a = bilinear(r.from, u, v), b = bilinear(s.patches[i].x, u, v);
        const double length = glm::length(b - a);
        const int n = 40000;
        for (int k = 0; k < n; ++k) {
          const double t = (k + 0.5) / n;
          glm::dvec3 flux;
          for (int c = 0; c < 3; ++c) flux[c] = r.track_start[c] * std::pow(r.track_end[c] / r.track_start[c], t);
          flux /= n_sub;
          const HatWeights hw = hatWeights(g.toVoxel(a + t * (b - a)), g.dims);
          for (std::size_t j = 0; j < 8; ++j) {
            if (hw.index[j] < 0) continue;
            DepositSum& sum = sums[static_cast<std::size_t>(hw.index[j])];
            sum.irradiance += flux * (length * inv_volume * hw.weight[j] / n);
            sum.direction += (luminance(flux) * hw.weight[j] / n) * (b - a);
          }
        }
      }
  }
  return sums;
}

std::vector<DepositSum> deposit(const HandStep& s, const GridSpec& g) {
  std::vector<DepositSum> sums(g.count());
  std::vector<std::vector<std::uint32_t>> by_slab;
  applyTrackDeposits(s.patches, s.results, g, nullptr, sums, by_slab);
  return sums;
}

// The largest difference of any lane between two sets of sums, over the largest lane of `ref`.
double worstRelative(const std::vector<DepositSum>& got, const std::vector<DepositSum>& ref) {
  double worst = 0.0, scale = 0.0;
  for (std::size_t v = 0; v < ref.size(); ++v)
    for (int c = 0; c < 3; ++c) {
      scale = std::max({scale, std::fabs(ref[v].irradiance[c]), std::fabs(ref[v].direction[c])});
      worst = std::max({worst, std::fabs(got[v].irradiance[c] - ref[v].irradiance[c]),
                        std::fabs(got[v].direction[c] - ref[v].direction[c])});
    }
  return worst / scale;
}

class BestTargetAfterwards : public ::testing::Test {
 protected:
  void TearDown() override { setTrackDepositTarget("best"); }
};

using TrackDepositCpu = BestTargetAfterwards;

TEST_F(TrackDepositCpu, EveryTargetDepositsTheHatIntegralAlongEverySubPath) {
  const GridSpec g = handGrid();
  const HandStep s = handSteps();
  const std::vector<DepositSum> exact = bruteForce(s, g);
  const std::vector<std::string> targets = trackDepositTargets();
  ASSERT_FALSE(targets.empty());
  std::vector<DepositSum> first;
  for (const std::string& target : targets) {
    SCOPED_TRACE(target);
    setTrackDepositTarget(target);
    EXPECT_EQ(trackDepositTarget(), target);
    const std::vector<DepositSum> got = deposit(s, g);
    // What is left is the deposit's own quadrature: 2 Gauss nodes a lattice cell are exact for the
    // hats' cubics, not for a cubic times e^(−κt), whose error is of order κ·Δt/10³ over a piece of
    // Δt (here κ ≤ 2.5, Δt ≤ 0.3: ≤ 7.5·10⁻⁵; measured 3.5·10⁻⁵, 1.2·10⁻⁵ with κ ≤ 1). The brute
    // force (4·10⁴ samples a sub-path; 1.6·10⁵ changes nothing) and the Taylor series of exp
    // (3.4·10⁻⁷) are far below that. A wrong lane, corner, slab cut or decay is of order 1.
    EXPECT_LT(worstRelative(got, exact), 1e-4);
    for (const DepositSum& sum : got) {
      ASSERT_EQ(sum.pad_irradiance, 0.0);  // the padding lanes stay empty
      ASSERT_EQ(sum.pad_direction, 0.0);
    }
    // The targets differ only in rounding (fused multiply-adds), ~10⁻¹⁶ a term.
    if (first.empty()) first = got;
    else EXPECT_LT(worstRelative(got, first), 1e-12);
  }
}

TEST_F(TrackDepositCpu, SameBitsWhateverTheThreadCount) {
  const GridSpec g = handGrid();
  const HandStep s = handSteps();
  for (const std::string& target : trackDepositTargets()) {
    SCOPED_TRACE(target);
    setTrackDepositTarget(target);
    std::vector<DepositSum> one, three;
    {
      ScopedThreads scope(1);
      one = deposit(s, g);
    }
    {
      ScopedThreads scope(3);
      three = deposit(s, g);
    }
    ASSERT_EQ(std::memcmp(one.data(), three.data(), one.size() * sizeof(DepositSum)), 0);
  }
}

// The targets offered are those whose instructions this CPU has, read independently of the
// dispatch from the kernel's /proc/cpuinfo flags (Linux x86 only): Highway's x86 targets need SSE4
// (with SSSE3, CLMUL and AES), AVX2 (with AVX, FMA, BMI1/2, F16C and LZCNT, "abm") and AVX3
// (AVX-512 F, VL, DQ, BW) — a target listed that the CPU lacks would crash the bake — best first,
// the portable one always last, and "best" the first.
TEST_F(TrackDepositCpu, TheTargetsOfferedAreThoseThisCpuRunsBestFirst) {
  const std::vector<std::string> targets = trackDepositTargets();
  ASSERT_FALSE(targets.empty());
  EXPECT_TRUE(targets.back() == "SCALAR" || targets.back() == "EMU128") << targets.back();
  setTrackDepositTarget("best");
  EXPECT_EQ(trackDepositTarget(), targets.front());
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line) && line.rfind("flags", 0) != 0) {
  }
  if (line.empty()) GTEST_SKIP() << "no /proc/cpuinfo flags here";
  std::istringstream words(line);
  std::set<std::string> flags;
  for (std::string w; words >> w;) flags.insert(w);
  auto has = [&](std::initializer_list<const char*> names) {
    return std::all_of(names.begin(), names.end(), [&](const char* n) { return flags.count(n) > 0; });
  };
  const bool sse4 = has({"ssse3", "sse4_1", "sse4_2", "pclmulqdq", "aes"});
  // LZCNT: the kernel lists it as "abm" (AMD's name, with POPCNT), but a guest kernel may leave
  // that flag out while CPUID reports the instruction (the project's 2-core AMD EPYC virtual
  // machine of 2026-12-07: no "abm" in /proc/cpuinfo, CPUID.80000001h:ECX bit 5 set); then CPUID,
  // which is what the program asks, says.
  bool lzcnt = has({"abm"});
#if defined(__x86_64__) || defined(__i386__)
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  lzcnt = lzcnt || (__get_cpuid(0x80000001u, &eax, &ebx, &ecx, &edx) && (ecx & (1u << 5)) != 0);
#endif
  const bool avx2 = sse4 && lzcnt && has({"avx", "avx2", "fma", "bmi1", "bmi2", "f16c"});
  const bool avx3 = avx2 && has({"avx512f", "avx512vl", "avx512dq", "avx512bw"});
  auto offered = [&](const char* name) { return std::find(targets.begin(), targets.end(), name) != targets.end(); };
  EXPECT_EQ(offered("SSE4"), sse4);
  EXPECT_EQ(offered("AVX2"), avx2);
  EXPECT_EQ(offered("AVX3"), avx3);
  // Best first: the widest first, in Highway's order.
  const std::vector<std::string> order = {"AVX3", "AVX2", "SSE4", "SCALAR", "EMU128"};
  auto rank = [&](const std::string& t) { return std::find(order.begin(), order.end(), t) - order.begin(); };
  for (std::size_t i = 1; i < targets.size(); ++i) EXPECT_LT(rank(targets[i - 1]), rank(targets[i]));
}

TEST_F(TrackDepositCpu, AnUnknownTargetIsAClearError) {
  try {
    setTrackDepositTarget("AVX9000");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("AVX9000"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find(trackDepositTargets().front()), std::string::npos);  // names the ones there are
  }
}

}  // namespace
}  // namespace eik
