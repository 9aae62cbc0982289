// The CPU twin's track deposits: a step's patch-steps spread into the voxels with the trilinear
// track kernel (track_deposit.h; ALGORITHM.md step 4, "Track deposits"), in SIMD through Google
// Highway, dispatched at run time to the widest vectors the CPU has (AVX-512, AVX2, SSE4, or
// Highway's portable 128-bit emulation), so one binary runs everywhere and uses what is there.
//
// Data layout: a voxel's two sums (irradiance and the luminance-weighted direction sum, double) are
// one 64-byte cache line, each padded to four lanes, so a deposit into a voxel is one aligned line:
// one fused multiply-add of eight lanes on AVX-512, two on AVX2.
//
// Deterministic: the voxels are split into slabs of z-slices, each slab's thread adds the sub-paths
// in patch order, so the sums do not depend on the thread count. They do depend, in the last bits,
// on the SIMD target (fused multiply-adds round once where separate ones round twice).
#pragma once

#include <cstdint>
#include <string>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/receiver.h"

namespace eik {

// The deposit targets of one voxel: irradiance (W/m², RGB) and the luminance-weighted direction
// sum, in double (accumulate) or the strongest patch so far (max). One cache line, lanes
// [E_r, E_g, E_b, 0, D_x, D_y, D_z, 0] (the padding stays 0).
struct alignas(64) DepositSum {
  glm::dvec3 irradiance{0.0};
  double pad_irradiance = 0.0;
  glm::dvec3 direction{0.0};
  double pad_direction = 0.0;
};
static_assert(sizeof(DepositSum) == 64, "a voxel's sums are one cache line");

// The largest decay rate κ = ln(Φ_start/Φ_end) of a step's flux: e^(−50) leaves nothing that counts.
constexpr double kMaxTrackDecay = 50.0;

// Up to this decay over a step (κ, every channel) the mean of its two ends is deposited along it:
// it is off the exponential by at most κ/2 at the ends, ≤ 0.025 % in a voxel's hat average (a thin
// smoke's steps, a Fresnel loss of 0.1 %), at half the cost.
constexpr double kMeanTrackDecay = 1e-3;

// The track deposits of one step: for each patch-step i with results[i].track (and not rolled
// back), its lattice of sub-paths from results[i].from to patches[i].x, added to `sums` (one per
// voxel of `grid`). `by_slab` is scratch space kept between calls.
void applyTrackDeposits(std::span<const Patch> patches, std::span<const PatchStepResult> results,
                        const GridSpec& grid, const ReceiverMap* receiver, std::span<DepositSum> sums,
                        std::vector<std::vector<std::uint32_t>>& by_slab);

// The SIMD targets this build has code for and this CPU runs, best first ("AVX3", "AVX2", "SSE4",
// "EMU128"; Highway's names), and the one the deposits run on now.
std::vector<std::string> trackDepositTargets();
std::string trackDepositTarget();
// Runs the deposits on the named target from now on (one of trackDepositTargets()); "" or "best":
// the best one again. Throws InputError for a name that is not in the list. The environment
// variable EIKONAL_SIMD, read at the first deposit, picks one the same way (benchmarks: a target's
// share); a name not in the list leaves the best (trackDepositTarget and the stats say which).
void setTrackDepositTarget(const std::string& name);

}  // namespace eik
