// The bake against exact optics (docs/testing.md): sharp interfaces, track deposits and receiver
// maps checked against the independent tracer of tests/reference (exact analytic shapes, exact
// Fresnel, every bounce) and against closed forms, never against a trace through the same voxels.
// Sizes are the suite's: the 128³ figures of the issue are in BENCHMARKS.md (scripts/bench_exact_optics.sh).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <sstream>
#include <vector>

#include "lightsim/cpu_simulator.h"
#include "lightsim/gpu_simulator.h"
#include "lightsim/interface_crossing.h"
#include "lightsim/receiver.h"
#include "lightsim/scene_bake.h"
#include "lightsim/spectral_bake.h"
#include "lightsim/sun_disc.h"
#include "lightsim/test_scenes.h"
#include "tests/reference/exact_optics.h"
#include "tests/reference/map_binning.h"

namespace eik {
namespace {

using namespace test_scenes;

// ---------------------------------------------------------------------------------------------
// The glass sphere over a floor: R = 1, n = 1.5, centre 1.5 above the plane y = 0, the sun
// straight down with irradiance 1. The paraxial focus (f = nR/(2(n − 1)) = 1.5 from the centre)
// lies on the floor: a sharp caustic core, spherical aberration around it, the shadow's edge at
// r = 1, and what the sphere reflects lands beyond it.

struct Rings {
  static constexpr int kCount = 9;
  static constexpr double kEdges[kCount + 1] = {0.0, 0.1, 0.2, 0.3, 0.4, 0.6, 0.9, 1.0, 1.1, 1.3};
  double irradiance[kCount] = {};
  double encircled_02 = 0.0, encircled_1 = 0.0;
  double shadow_radius = 0.0;  // where the mean irradiance first climbs past ½ going out from 0.9
};

// Rings of the receiver map around the caustic's centre, from the texels whose centres fall in them.
Rings ringsOf(const ReceiverMap& map) {
  Rings rings;
  double flux[Rings::kCount] = {}, area[Rings::kCount] = {};
  constexpr int kFine = 80;
  double fine_sum[kFine] = {}, fine_count[kFine] = {};
  const double a = map.pitch * map.pitch;
  for (int j = 0; j < map.texels.y; ++j)
    for (int i = 0; i < map.texels.x; ++i) {
      const glm::dvec3 c = map.texelCenter(i, j);
      const double r = std::hypot(c.x, c.z);
      const double e = map.rgb(static_cast<std::size_t>(j) * map.texels.x + i).x;
      if (r < 0.2) rings.encircled_02 += e * a;
      if (r < 1.0) rings.encircled_1 += e * a;
      for (int k = 0; k < Rings::kCount; ++k)
        if (r >= Rings::kEdges[k] && r < Rings::kEdges[k + 1]) flux[k] += e * a, area[k] += a;
      const int f = static_cast<int>((r - 0.9) / 0.0025);
      if (f >= 0 && f < kFine) fine_sum[f] += e, fine_count[f] += 1.0;
    }
  for (int k = 0; k < Rings::kCount; ++k) rings.irradiance[k] = flux[k] / area[k];
  for (int f = 0; f + 1 < kFine; ++f) {
    const double lo = fine_sum[f] / fine_count[f], hi = fine_sum[f + 1] / fine_count[f + 1];
    if (lo < 0.5 && hi >= 0.5) {
      rings.shadow_radius = 0.9 + 0.0025 * (f + 0.5 + (0.5 - lo) / (hi - lo));
      break;
    }
  }
  return rings;
}

// The tracer on the sphere over the floor: 4·10⁶ rays over the floor's square (a ring of width
// 0.1 near r = 1 gets some 10⁵ of them: ±0.3 %), rings of 0.01, and the map `receiver` may ask for.
reference::ReceiverTally traceSphereOnFloor(reference::Receiver receiver = {}) {
  reference::DirectionalBeam beam;
  beam.beam_center = {0.0, 1.5, 0.0};
  beam.beam_radius = 1.6 * std::sqrt(2.0);
  receiver.ring_width = 0.01;
  receiver.max_radius = 2.0;
  reference::TraceOptions options;
  options.rays = 4'000'000;
  return reference::trace({reference::Solid::sphere({0.0, 1.5, 0.0}, 1.0, 1.5)}, beam, receiver, options);
}

// The tracer's answer, once for all resolutions.
const reference::ReceiverTally& exactSphereOnFloor() {
  static const reference::ReceiverTally tally = traceSphereOnFloor();
  return tally;
}

struct SphereBake {
  Rings rings;
  double mean_deviation = 0.0, worst_deviation = 0.0;  // over the rings 0.1 ≤ r < 1.3
  // The same against the exact answer binned into the map's own texels and measured like the map
  // (texel centres): at the shadow's edge (r = 1, E jumps twentyfold) a texel-centre ring mixes in
  // its neighbour's light whatever the bake (+20 % in the ring 0.9–1 at a 64³ map's pitch).
  double mean_vs_texels = 0.0, worst_vs_texels = 0.0;
  SimulationStats stats;
  ReceiverMap map;
  Field irradiance;
};

// The exact tracer's flux binned into `map`'s texels, as a map of planar irradiance.
ReceiverMap exactThroughMap(const ReceiverMap& map) {
  reference::Receiver receiver;
  reference::binLikeMap(map, receiver);
  return reference::irradianceLikeMap(map, traceSphereOnFloor(receiver));
}

// How the bake steps: Δt everywhere; free flight across quiet space (with the volume's deposits);
// or as `lightsim` bakes a clear object over a ground by default: free flight, straight steps of 2
// voxels, the receiver map only (ALGORITHM.md "Straight steps").
enum class Stepping { Dt, Flight, Straight };
enum class Backend { Cpu, Gl };

// The bake on the CPU twin or the GPU path (OSMesa/llvmpipe here).
std::unique_ptr<Simulator> simulatorFor(const Volume& volume, Backend backend) {
  if (backend == Backend::Cpu) return std::make_unique<CpuSimulator>(volume);
  glContext();
  return std::make_unique<GpuSimulator>(volume);
}

// The initial patch edge and the split length, in voxels, when not lightsim's (volumeDefaults).
struct PatchSize {
  double patch_voxels = 1.0;
  double split_voxels = 1.5;
};

SphereBake measureSphereBake(int res, const BakeResult& bake);

// The patch size and depth `lightsim` takes for a volume with sharp interfaces on `grid` (volumeDefaults).
SimulationOptions lightsimSharpOptions(const GridSpec& grid) {
  SimulationOptions options;
  const VolumeDefaults defaults = volumeDefaults(true, grid);
  options.max_depth = defaults.max_depth;
  options.patch_voxels = defaults.patch_voxels;
  options.split_voxels = defaults.split_voxels;
  return options;
}

SphereBake bakeSphereOnFloor(int res, Stepping stepping = Stepping::Flight, Backend backend = Backend::Cpu,
                             std::optional<PatchSize> patch_size = std::nullopt) {
  const Volume volume = sharpVolume("procedural:sphere,r=1,center=0:1.5:0,ior=1.5", res, std::nullopt, 2.0);
  const std::unique_ptr<Simulator> sim = simulatorFor(volume, backend);
  LightSpec light;  // straight down, irradiance 1
  SimulationOptions options = lightsimSharpOptions(volume.grid);
  if (patch_size) {
    options.patch_voxels = patch_size->patch_voxels;
    options.split_voxels = patch_size->split_voxels;
  }
  options.free_flight = stepping != Stepping::Dt;  // lightsim's default: on
  if (stepping == Stepping::Straight) {
    options.volume_deposits = false;
    options.straight_step_voxels = 2.0;
  }
  ReceiverSpec floor;
  floor.half_extent = 1.6;
  options.receiver = floor;
  return measureSphereBake(res, sim->run(light, options));
}

// A bake of the sphere over the floor (its map in world coordinates) against exact optics.
SphereBake measureSphereBake(int res, const BakeResult& bake) {
  SphereBake result;
  result.stats = bake.stats;
  result.map = bake.receivers.at(0);
  result.irradiance = bake.irradiance;
  result.rings = ringsOf(bake.receivers.at(0));
  const reference::ReceiverTally& exact = exactSphereOnFloor();
  int counted = 0;
  for (int k = 1; k < Rings::kCount; ++k) {
    const double want = exact.ringIrradiance(Rings::kEdges[k], Rings::kEdges[k + 1]);
    const double deviation = std::abs(result.rings.irradiance[k] / want - 1.0);
    std::printf("%d³: ring %.1f–%.1f: bake %.4f exact %.4f (%+.2f %%)\n", res, Rings::kEdges[k], Rings::kEdges[k + 1],
                result.rings.irradiance[k], want, 100.0 * (result.rings.irradiance[k] / want - 1.0));
    result.mean_deviation += deviation;
    result.worst_deviation = std::max(result.worst_deviation, deviation);
    ++counted;
  }
  result.mean_deviation /= counted;
  const ReceiverMap& map = bake.receivers.at(0);
  EXPECT_EQ(map.texels.x, map.texels.y);  // the tracer's map is square (the scene is symmetric)
  const ReceiverMap exact_map = exactThroughMap(map);
  const Rings through = ringsOf(exact_map);
  // Beyond r = 1.3 (the map's corners, past the sphere's box: where the light lands straight from
  // the sun, in closed form, plus what the ball's outside mirrors there) the map's mean against the
  // exact tracer's through the same texels. Tolerance 0.5 %: the tracer's Monte Carlo noise over
  // these ~10⁴ texels is under 0.1 %, the mirrored light (0.2 % of the floor's there) is followed
  // to one bounce as in the tracer; a closed form that missed cos θ, a texel area or a cell would be
  // off by far more.
  double bake_sum = 0.0, exact_sum = 0.0;
  int outside = 0;
  for (int j = 0; j < map.texels.y; ++j)
    for (int i = 0; i < map.texels.x; ++i) {
      const glm::dvec3 c = map.texelCenter(i, j);
      if (std::hypot(c.x, c.z) <= 1.3) continue;
      const std::size_t t = static_cast<std::size_t>(j) * map.texels.x + i;
      bake_sum += map.rgb(t).x;
      exact_sum += exact_map.rgb(t).x;
      ++outside;
    }
  std::printf("%d³: beyond r = 1.3 (%d texels): bake %.5f, exact through the map %.5f\n", res, outside,
              bake_sum / outside, exact_sum / outside);
  EXPECT_GT(outside, 1000);
  EXPECT_NEAR(bake_sum / exact_sum, 1.0, 5e-3);
  for (int k = 1; k < Rings::kCount; ++k) {
    const double deviation = std::abs(result.rings.irradiance[k] / through.irradiance[k] - 1.0);
    result.mean_vs_texels += deviation / counted;
    result.worst_vs_texels = std::max(result.worst_vs_texels, deviation);
  }
  constexpr int edge_ring = 6;  // 0.9–1.0, just inside the shadow's edge
  static_assert(Rings::kEdges[edge_ring] == 0.9 && Rings::kEdges[edge_ring + 1] == 1.0);
  std::printf("%d³: against exact optics through the map's texels: mean %.2f %%, worst %.2f %%; the ring %.1f–%.1f "
              "through them %+.2f %% of exact\n",
              res, 100.0 * result.mean_vs_texels, 100.0 * result.worst_vs_texels, Rings::kEdges[edge_ring],
              Rings::kEdges[edge_ring + 1],
              100.0 * (through.irradiance[edge_ring] / exact.ringIrradiance(Rings::kEdges[edge_ring], Rings::kEdges[edge_ring + 1]) - 1.0));
  std::printf("%d³: mean deviation %.2f %%, worst %.2f %%, shadow radius %.4f, flux r<0.2 %.4f (exact %.4f), r<1 %.4f "
              "(exact %.4f); %llu patch-steps\n",
              res, 100.0 * result.mean_deviation, 100.0 * result.worst_deviation, result.rings.shadow_radius,
              result.rings.encircled_02, exact.encircledFlux(0.2), result.rings.encircled_1, exact.encircledFlux(1.0),
              static_cast<unsigned long long>(bake.stats.total_patches));
  return result;
}

// Relative L2 difference of two equally sized float arrays.
double relativeL2(const std::vector<float>& a, const std::vector<float>& b) {
  double diff = 0.0, norm = 0.0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    diff += (static_cast<double>(a[i]) - b[i]) * (static_cast<double>(a[i]) - b[i]);
    norm += static_cast<double>(b[i]) * b[i];
  }
  return a.size() == b.size() && norm > 0.0 ? std::sqrt(diff / norm) : 1.0;
}

// Free flight (ALGORITHM.md): quiet space crossed in one straight step gives the bake of steps of
// Δt, in far fewer steps. Both are checked against exact optics above; here against each other.
TEST(ExactOpticsSphere, FreeFlightBakesTheSameCausticInFewerSteps) {
  const SphereBake stepped = bakeSphereOnFloor(32, Stepping::Dt), flown = bakeSphereOnFloor(32, Stepping::Flight);
  EXPECT_EQ(stepped.stats.flights, 0u);
  EXPECT_GT(flown.stats.flights, 0u);
  // Measured 3.5× fewer patch-steps at 32³ and 6.1× at 64³ (the air above and beside the sphere,
  // the glass inside it, the way down to the floor; at 32³ the band of noisy voxels around the
  // surface is a larger part of the sphere).
  EXPECT_LT(flown.stats.total_patches, stepped.stats.total_patches / 3 * 2);
  // What changes: where a step ends, so where the patches split and meet the sphere. Measured
  // relative L2 4.0e-5 (map) and 3.8e-3 (field); 1 % would be a visible change of the caustic.
  const double map = relativeL2(flown.map.rgbValues(), stepped.map.rgbValues());
  const double field = relativeL2(flown.irradiance.data, stepped.irradiance.data);
  std::printf("free flight against steps of Δt, 32³: map %.2e, field %.2e relative L2; %llu against %llu patch-steps\n", map,
              field, static_cast<unsigned long long>(flown.stats.total_patches),
              static_cast<unsigned long long>(stepped.stats.total_patches));
  EXPECT_LT(map, 0.01);
  EXPECT_LT(field, 0.01);
  for (int k = 0; k < Rings::kCount; ++k)
    EXPECT_NEAR(flown.rings.irradiance[k] / stepped.rings.irradiance[k], 1.0, 0.01) << "ring " << k;
  EXPECT_LT(flown.stats.ledgerResidual(), 1e-9);
  EXPECT_NEAR(flown.stats.flux_received.x, stepped.stats.flux_received.x, 1e-3 * stepped.stats.flux_received.x);
}

// The caustic of a bake at 32³ and 48³ against exact optics: within the issue's bounds, and closer at
// the finer grid.
void expectConvergesToExactOptics(const SphereBake& coarse, const SphereBake& fine) {
  const reference::ReceiverTally& exact = exactSphereOnFloor();
  // The issue's bound at 64³ is 10 % mean deviation (5 % at 128³); 48³ is measured at 2.4 %, 32³
  // at 5.1 % (lightsim's defaults: splits past 1.5 voxels, depth 4). The error must fall with
  // resolution: the discretisation converges.
  EXPECT_LT(fine.mean_deviation, 0.10);
  EXPECT_LT(fine.mean_deviation, coarse.mean_deviation);
  // The dim ring 0.9–1.0 (E ≈ 0.05) read by texel centres: the texels centred just inside the
  // shadow's edge hold some of the bright floor beyond it (E ≈ 1.04), so the exact answer through
  // the same texels reads that ring 26 % bright at 48³; the bake, measured 21–24 %, follows it.
  EXPECT_LT(fine.worst_deviation, 0.3);
  // Against the exact answer measured through the same texels: the issue's bounds at 128³ are 5 %
  // mean and 10 % in every ring (BENCHMARKS.md); at 48³ measured 1.5–1.8 % and 6.3–6.6 %. Before the
  // patches torn at the silhouette at the depth limit gave the receiver the light of their corners
  // that pass the sphere by (cpu_simulator.cpp passingShare), they died with it, the ring 0.9–1.0
  // lacked the bright floor's light at the shadow's edge and read 15.8–16.3 % under this answer
  // (3.3–3.4 % mean): these bounds fail without it.
  EXPECT_LT(fine.mean_vs_texels, 0.025);
  EXPECT_LT(fine.worst_vs_texels, 0.09);
  // The shadow's edge stays at the sphere's radius (the smoothed boundary put it 8 % out):
  // ±0.01 is 0.24 voxel at 48³.
  EXPECT_NEAR(fine.rings.shadow_radius, 1.0, 0.01);
  EXPECT_NEAR(coarse.rings.shadow_radius, 1.0, 0.01);
  // Encircled flux: the caustic's core within 10 %, everything under the sphere within 3 %.
  EXPECT_NEAR(fine.rings.encircled_02 / exact.encircledFlux(0.2), 1.0, 0.10);
  EXPECT_NEAR(fine.rings.encircled_1 / exact.encircledFlux(1.0), 1.0, 0.03);
  // The energy ledger closes, and almost all of the light reaches the floor or leaves upwards.
  const SimulationStats& s = fine.stats;
  // The twin's ledger is summed in double; the GPU's from float per-patch entries (measured 1.2e-7
  // at 48³).
  EXPECT_LT(s.ledgerResidual(), s.backend == "gl" ? 1e-5 : 1e-9);
  // Flux lost to kills (patches torn at the silhouette beyond the depth limit, light trapped by
  // total internal reflection) and the step limit: measured 0.33 % of the sphere's own flux πR².
  EXPECT_LT(s.flux_killed.x + s.flux_unfinished.x, 0.01 * std::numbers::pi);
}

TEST(ExactOpticsSphere, CausticOnTheFloorConvergesToExactOptics) {
  expectConvergesToExactOptics(bakeSphereOnFloor(32), bakeSphereOnFloor(48));
}

// `lightsim SCENE.json` (scene_bake.h): an object baked as the scene places it. The volume holds a
// sphere of radius 2/3 off its origin; the scene scales it by 1.5, turns it 20° about x and 40°
// about y and moves it so that it stands as the sphere above: radius 1, centre (0, 1.5, 0). The sun
// and the floor are given in the world and carried into the bake frame, where the sun comes in 20°
// off the volume's vertical. The map, put back into the world, must be the exact caustic as closely
// as the unplaced bake's at the same voxels per radius: a light or floor not carried into the
// volume's axes moves the caustic by 0.55 (tan 20° · 1.5), an unscaled bake makes the shadow 2/3
// wide, either far beyond these bounds.
SphereBake bakePlacedSphereOnFloor(int res) {
  SceneObjectSpec placement;
  placement.scale = glm::dvec3(1.5);
  placement.rotate_deg = {20.0, 40.0, 0.0};
  const glm::dvec3 centre_in_volume(0.3, 0.2, -0.1);
  placement.translate = glm::dvec3(0.0, 1.5, 0.0) - glm::dvec3(objectToWorld(placement) * glm::dvec4(centre_in_volume, 1.0));
  const Volume volume = sharpVolume("procedural:sphere,r=0.6666667,center=0.3:0.2:-0.1,ior=1.5", res, std::nullopt, 2.0);
  const BakeFrame frame = BakeFrame::of(placement);
  const Volume at_world_scale = volumeAtWorldScale(volume, frame.scale);
  CpuSimulator sim(at_world_scale);
  LightSpec sun;  // straight down in the world, irradiance 1
  ReceiverSpec floor;
  floor.half_extent = 1.6;
  SimulationOptions options = lightsimSharpOptions(at_world_scale.grid);
  options.receiver = frame.receiver(floor);
  LightSpec light = frame.light(sun);
  EXPECT_NEAR(glm::degrees(std::acos(-light.direction.y)), 20.0, 1e-9) << "the sun as the volume sees it";
  BakeResult bake = sim.run(light, options);
  bakeToVolumeFrame(bake, light, frame.scale);
  // The map back in the world: world = T · R · s · volume.
  ReceiverMap& map = bake.receivers.at(0);
  const glm::dmat4 to_world = objectToWorld(placement);
  map.point = glm::dvec3(to_world * glm::dvec4(map.point, 1.0));
  map.u = glm::normalize(glm::dmat3(to_world) * map.u);
  map.v = glm::normalize(glm::dmat3(to_world) * map.v);
  map.normal = glm::normalize(glm::dmat3(to_world) * map.normal);
  map.origin *= frame.scale;
  map.pitch *= frame.scale;
  return measureSphereBake(res, bake);
}

TEST(ExactOpticsSphere, APlacedVolumeBakesTheCausticWhereTheSceneStandsIt) {
  const SphereBake coarse = bakePlacedSphereOnFloor(32);
  const SphereBake placed = bakePlacedSphereOnFloor(48);
  // It converges as the unplaced bake does (8.3 → 4.4 %): measured 8.3 % at 32³, 4.7 % at 48³.
  EXPECT_LT(placed.mean_deviation, coarse.mean_deviation);
  EXPECT_NEAR(coarse.rings.shadow_radius, 1.0, 0.01);
  // The unplaced bake's bounds at 48³ (expectConvergesToExactOptics: measured 4.4 % mean, 24 %
  // worst in the ring 0.9–1.0 read by texel centres; 1.5 % and 6.3 % through the map's texels, here
  // 1.1 % and 5.0 %; the shadow's edge within 0.24 voxel).
  EXPECT_LT(placed.mean_deviation, 0.05);
  EXPECT_LT(placed.worst_deviation, 0.3);
  EXPECT_LT(placed.mean_vs_texels, 0.025);
  EXPECT_NEAR(placed.rings.shadow_radius, 1.0, 0.01);
  EXPECT_NEAR(placed.rings.encircled_1 / exactSphereOnFloor().encircledFlux(1.0), 1.0, 0.03);
}

// ---------------------------------------------------------------------------------------------
// The sun's disc (sun_disc.h): the sphere over the floor under a vertical sun of angular diameter
// θ, baked from kDefaultSunSamples directions over the disc (the runs sharing one map lattice) and
// summed. The shadow's edge becomes a penumbra: a floor point at offset x·(α·L) from the geometric
// edge (α = θ/2, L = 1.5 the height of the sphere's silhouette, the equator) sees the fraction
// f(x) = ½ + (x·sqrt(1 − x²) + asin x)/π of the disc (a straight edge across a uniform disc; the
// edge's curvature, radius 1 against a penumbra of 0.1, is neglected), so the width between the 20 %
// and 80 % levels is 2·x₈₀·α·L with f(x₈₀) = 0.8. Measured on the ring-averaged profile between
// the light inside the shadow (r 0.90–0.93) and outside it (r 1.10–1.15). θ = 6° here (the
// penumbra 0.08, 14 texels of the map at 0.125 voxel); the sun's 0.53° casts one 12 times narrower,
// the same code.
struct Penumbra {
  double width = 0.0;       // between the 20 % and 80 % levels
  double centre = 0.0;      // where the profile crosses 50 %
};
// Where penumbraOf looks: the profile from `from` on (0.36 in bins of 0.004), the shadow's level
// over the radii [inside_lo, inside_hi), the light's over [outside_lo, outside_hi).
struct PenumbraWindow {
  double from = 0.85, inside_lo = 0.90, inside_hi = 0.93, outside_lo = 1.10, outside_hi = 1.15;
};
Penumbra penumbraOf(const ReceiverMap& map, const PenumbraWindow& window = {}) {
  const double kFrom = window.from, kBin = 0.004;
  constexpr int kBins = 90;
  std::vector<double> sum(kBins, 0.0), count(kBins, 0.0);
  double inside = 0.0, n_inside = 0.0, outside = 0.0, n_outside = 0.0;
  for (int j = 0; j < map.texels.y; ++j)
    for (int i = 0; i < map.texels.x; ++i) {
      const glm::dvec3 c = map.texelCenter(i, j);
      const double r = std::hypot(c.x, c.z);
      const double e = map.rgb(static_cast<std::size_t>(j) * map.texels.x + i).y;
      if (r >= window.inside_lo && r < window.inside_hi) inside += e, n_inside += 1.0;
      if (r >= window.outside_lo && r < window.outside_hi) outside += e, n_outside += 1.0;
      const int b = static_cast<int>((r - kFrom) / kBin);
      if (b >= 0 && b < kBins) sum[b] += e, count[b] += 1.0;
    }
  inside /= n_inside;
  outside /= n_outside;
  auto crossing = [&](double level) {
    const double target = inside + level * (outside - inside);
    for (int b = 0; b + 1 < kBins; ++b) {
      const double lo = sum[b] / count[b], hi = sum[b + 1] / count[b + 1];
      if (lo < target && hi >= target) return kFrom + kBin * (b + 0.5 + (target - lo) / (hi - lo));
    }
    return 0.0;
  };
  return {crossing(0.8) - crossing(0.2), crossing(0.5)};
}

// The options of a soft-shadow bake of the sphere over the floor: as lightsim bakes a clear object
// over a ground (free flight, straight steps, the map only), the floor's map at an eighth of a
// voxel over [−half_extent, half_extent]².
SimulationOptions softShadowOptions(const Volume& volume, double half_extent) {
  SimulationOptions options = lightsimSharpOptions(volume.grid);
  options.free_flight = true;
  options.straight_step_voxels = 2.0;
  options.volume_deposits = false;
  ReceiverSpec floor;
  floor.half_extent = half_extent;
  floor.pitch_voxels = 0.125;
  options.receiver = floor;
  return options;
}

ReceiverMap bakeSphereUnderTheSunsDisc(int res, double angular_diameter_deg, double height = 1.5) {
  char spec[96];
  std::snprintf(spec, sizeof spec, "procedural:sphere,r=1,center=0:%g:0,ior=1.5", height);
  const Volume volume = sharpVolume(spec, res, std::nullopt, 2.0);
  CpuSimulator sim(volume);
  SimulationOptions options = softShadowOptions(volume, 1.6);
  const ReceiverSpec floor = *options.receiver;
  LightSpec sun;  // straight down, irradiance 1
  sun.angular_diameter_deg = angular_diameter_deg;
  glm::dvec3 lo, hi;
  propagationBox(volume.grid, options, lo, hi);
  options.receiver_geometry = receiverGeometry(floor, sun, volume.grid, lo, hi);
  BandSum sum;
  double power = 0.0;
  for (const LightSpec& direction : sunDiscSamples(sun, kDefaultSunSamples)) {
    power += direction.power.y;
    sum.add(sim.run(direction, options));
  }
  EXPECT_NEAR(power, 1.0, 1e-12);  // the directions share the irradiance
  return sum.finish().receivers.at(0);
}

// The width between the 20 % and 80 % levels of the penumbra a disc of angular diameter θ casts
// from an edge at height L: 2·x₈₀·(θ/2)·L with f(x₈₀) = 0.8 (above; bisection).
double geometricPenumbra(double theta_deg, double height) {
  double x80 = 0.0;
  for (double a = 0.0, b = 1.0; b - a > 1e-12; x80 = 0.5 * (a + b)) {
    const double m = 0.5 * (a + b);
    (0.5 + (m * std::sqrt(1.0 - m * m) + std::asin(m)) / std::numbers::pi < 0.8 ? a : b) = m;
  }
  return 2.0 * x80 * glm::radians(0.5 * theta_deg) * height;
}

TEST(ExactOpticsSoftSun, TheSunsDiscCastsThePenumbraOfGeometry) {
  constexpr double kTheta = 6.0, kHeight = 1.5;
  const double geometric = geometricPenumbra(kTheta, kHeight);
  const Penumbra coarse = penumbraOf(bakeSphereUnderTheSunsDisc(32, kTheta));
  const Penumbra soft = penumbraOf(bakeSphereUnderTheSunsDisc(48, kTheta));
  const Penumbra hard = penumbraOf(bakeSphereUnderTheSunsDisc(48, 0.0));
  std::printf("penumbra 20-80 %%: %.4f at 32³, %.4f at 48³ (geometric %.4f), its middle at r = %.4f; the point-like "
              "sun's edge %.4f wide\n",
              coarse.width, soft.width, geometric, soft.width > 0 ? soft.centre : 0.0, hard.width);
  // The issue's bound: within 10 % of the geometric width, at both resolutions.
  EXPECT_NEAR(coarse.width / geometric, 1.0, 0.10);
  EXPECT_NEAR(soft.width / geometric, 1.0, 0.10);
  // Centred on the sharp shadow's edge (r = 1: the disc is symmetric), within a texel (0.0056).
  EXPECT_NEAR(soft.centre, hard.centre, 0.006);
  // Without the disc the edge is a texel or two wide: the penumbra is the disc's.
  EXPECT_LT(hard.width, 0.3 * geometric);
}

// The sun's own 0.53°: the same penumbra, 12 times narrower, made wide enough to measure by
// standing the sphere high over the floor (its equator L = 18.5 up): 2·x₈₀·α·L = 0.084, 15
// texels at 48³ (measured 0.0843 at 32³ and 0.0841 at 48³). The light the sphere focuses 1.5 below its centre has spread over 11 times its width by
// the floor (a smooth percent of the sun there), and the penumbra itself reaches α·L = 0.086 to
// either side of the edge, so the shadow's and the light's levels are taken further out
// (r 0.80–0.85 and 1.15–1.20).
TEST(ExactOpticsSoftSun, TheRealSunsHalfDegreeCastsThePenumbraOfGeometry) {
  constexpr double kTheta = 0.53, kHeight = 18.5;
  const double geometric = geometricPenumbra(kTheta, kHeight);
  PenumbraWindow window;
  window.from = 0.78;
  window.inside_lo = 0.80;
  window.inside_hi = 0.85;
  window.outside_lo = 1.15;
  window.outside_hi = 1.20;
  const Penumbra coarse = penumbraOf(bakeSphereUnderTheSunsDisc(32, kTheta, kHeight), window);
  const Penumbra soft = penumbraOf(bakeSphereUnderTheSunsDisc(48, kTheta, kHeight), window);
  const Penumbra hard = penumbraOf(bakeSphereUnderTheSunsDisc(48, 0.0, kHeight), window);
  std::printf("the sun's 0.53°: penumbra 20-80 %%: %.4f at 32³, %.4f at 48³ (geometric %.4f), its middle at r = %.4f; "
              "the point-like sun's edge %.4f wide\n",
              coarse.width, soft.width, geometric, soft.centre, hard.width);
  // The issue's bound: within 10 % of the geometric width, at both resolutions.
  EXPECT_NEAR(coarse.width / geometric, 1.0, 0.10);
  EXPECT_NEAR(soft.width / geometric, 1.0, 0.10);
  EXPECT_NEAR(soft.centre, hard.centre, 0.006);
  EXPECT_LT(hard.width, 0.3 * geometric);
}

// A point light with a radius (sun_disc.h ballLightPoints): a ball of radius ρ = 0.3 at height 6
// over the floor, above the sphere (R = 1, centre 1.5). Every floor point sees it as a uniform
// disc of radius ρ, so the shadow's edge is a penumbra as under the sun's disc, of angular radius
// ρ/D_S seen from the silhouette: the cone from the light's centre touches the sphere at
// D_S = sqrt(4.5² − 1) from it, at β = asin(1/4.5) off the vertical, and meets the floor at
// D_F = 6/cos β, r = 6 tan β = 1.368; across the ray the penumbra spans 2·x₈₀·ρ·(D_F − D_S)/D_S
// between its 20 % and 80 % levels (x₈₀ as for the sun), on the floor 1/cos β as much: 0.122.
// Measured between the light just inside the shadow (r 1.20–1.25, where the sphere's focused light
// has not reached) and just outside (1.48–1.53), against the point light's sharp edge.
ReceiverMap bakeSphereUnderABallLight(int res, double light_radius) {
  const Volume volume = sharpVolume("procedural:sphere,r=1,center=0:1.5:0,ior=1.5", res, std::nullopt, 2.0);
  CpuSimulator sim(volume);
  SimulationOptions options = softShadowOptions(volume, 1.8);
  const ReceiverSpec floor = *options.receiver;
  LightSpec lamp;
  lamp.type = LightSpec::Type::Point;
  lamp.position = {0.0, 6.0, 0.0};
  lamp.power = glm::dvec3(36.0);  // 1 W/m² straight below at the floor, as the sun above
  lamp.radius = light_radius;
  glm::dvec3 lo, hi;
  propagationBox(volume.grid, options, lo, hi);
  LightSpec centre = lamp;
  centre.radius = 0.0;
  options.receiver_geometry = receiverGeometry(floor, centre, volume.grid, lo, hi);
  BandSum sum;
  for (const LightSpec& point : sunDiscSamples(lamp, kDefaultSunSamples)) sum.add(sim.run(point, options));
  return sum.finish().receivers.at(0);
}

TEST(ExactOpticsSoftLight, ABallLightCastsThePenumbraOfGeometry) {
  constexpr double kRho = 0.3, kHeight = 6.0, kCentre = 1.5;
  const double d = kHeight - kCentre, beta = std::asin(1.0 / d);
  const double d_s = std::sqrt(d * d - 1.0), d_f = kHeight / std::cos(beta);
  // The disc's angular radius ρ/D_S seen from the silhouette, D_F − D_S on to the floor, 1/cos β
  // across it.
  const double geometric = geometricPenumbra(2.0 * glm::degrees(kRho / d_s), d_f - d_s) / std::cos(beta);
  const PenumbraWindow window{1.15, 1.20, 1.25, 1.48, 1.53};
  const Penumbra coarse = penumbraOf(bakeSphereUnderABallLight(32, kRho), window);
  const Penumbra soft = penumbraOf(bakeSphereUnderABallLight(48, kRho), window);
  const Penumbra hard = penumbraOf(bakeSphereUnderABallLight(48, 0.0), window);
  std::printf("ball light's penumbra 20-80 %%: %.4f at 32³, %.4f at 48³ (geometric %.4f), its middle at r = %.4f "
              "(the cone's edge %.4f); the point light's edge %.4f wide\n",
              coarse.width, soft.width, geometric, soft.centre, kHeight * std::tan(beta), hard.width);
  // The issue's bound for the sun's penumbra, 10 % of the geometric width, at both resolutions
  // (measured 0.1254 at 32³ and 0.1253 at 48³, +2.9 %: the 16 points' steps, the edge's curvature).
  EXPECT_NEAR(coarse.width / geometric, 1.0, 0.10);
  EXPECT_NEAR(soft.width / geometric, 1.0, 0.10);
  // Centred on the point light's sharp edge within two texels (0.005 each): the disc is symmetric
  // to first order (its far side is nearer the silhouette than its near side, by ρ/D_S ≈ 7 %).
  EXPECT_NEAR(soft.centre, hard.centre, 0.01);
  EXPECT_NEAR(hard.centre, kHeight * std::tan(beta), 0.01);
  EXPECT_LT(hard.width, 0.3 * geometric);
}

// ---------------------------------------------------------------------------------------------
// Every light of a scene, summed (lightsim SCENE.json): the sphere over the floor under two suns,
// straight down (E = 1) and 30° off the vertical in the x-y plane (E = 0.6), baked as lightsim bakes
// a scene's lights: a run each on one map lattice that covers both lights' regions
// (receiverGeometry of the lights), summed (BandSum). The tilted sun's shadow (centred 1.5·tan 30° =
// 0.87 off) and its caustic fall across the rings about the first sun's caustic; the exact answer
// is the tracer's for each sun, added.
const reference::ReceiverTally& exactTiltedSunOnFloor() {
  static const reference::ReceiverTally tally = [] {
    reference::DirectionalBeam beam;
    beam.direction = {std::sin(glm::radians(30.0)), -std::cos(glm::radians(30.0)), 0.0};
    beam.beam_center = {0.0, 1.5, 0.0};
    beam.beam_radius = 2.6;  // every floor point within r = 1.3 of the origin sees the beam
    beam.irradiance = 0.6;
    reference::Receiver receiver;
    receiver.ring_width = 0.01;
    receiver.max_radius = 2.0;
    reference::TraceOptions options;
    options.rays = 6'000'000;
    return reference::trace({reference::Solid::sphere({0.0, 1.5, 0.0}, 1.0, 1.5)}, beam, receiver, options);
  }();
  return tally;
}

struct TwoSunsBake {
  double mean = 0.0, worst = 0.0;  // over the rings 0.1 ≤ r < 1.3
  ReceiverMap map;
  glm::ivec2 first_sun_texels{0};  // the lattice the first sun alone bakes on
  SimulationStats stats;
};

TwoSunsBake bakeSphereUnderTwoSuns(int res) {
  const Volume volume = sharpVolume("procedural:sphere,r=1,center=0:1.5:0,ior=1.5", res, std::nullopt, 2.0);
  CpuSimulator sim(volume);
  SimulationOptions options = lightsimSharpOptions(volume.grid);
  options.free_flight = true;
  ReceiverSpec floor;
  floor.half_extent = 4.0;  // wider than the first sun's region (its shadow and as much again around it)
  options.receiver = floor;
  LightSpec overhead, tilted;
  tilted.direction = {std::sin(glm::radians(30.0)), -std::cos(glm::radians(30.0)), 0.0};
  tilted.power = glm::dvec3(0.6);
  glm::dvec3 lo, hi;
  propagationBox(volume.grid, options, lo, hi);
  TwoSunsBake out;
  out.first_sun_texels = receiverGeometry(floor, overhead, volume.grid, lo, hi).texels;
  options.receiver_geometry = receiverGeometry(floor, std::vector<LightSpec>{overhead, tilted}, volume.grid, lo, hi);
  BandSum sum;
  sum.add(sim.run(overhead, options));
  sum.add(sim.run(tilted, options));
  const BakeResult bake = sum.finish();
  out.stats = bake.stats;
  out.map = bake.receivers.at(0);
  const Rings rings = ringsOf(out.map);
  for (int k = 1; k < Rings::kCount; ++k) {
    const double want = exactSphereOnFloor().ringIrradiance(Rings::kEdges[k], Rings::kEdges[k + 1]) +
                        exactTiltedSunOnFloor().ringIrradiance(Rings::kEdges[k], Rings::kEdges[k + 1]);
    const double deviation = std::abs(rings.irradiance[k] / want - 1.0);
    std::printf("two suns %d³: ring %.1f–%.1f: bake %.4f exact %.4f (%+.2f %%)\n", res, Rings::kEdges[k],
                Rings::kEdges[k + 1], rings.irradiance[k], want, 100.0 * (rings.irradiance[k] / want - 1.0));
    out.mean += deviation / (Rings::kCount - 1);
    out.worst = std::max(out.worst, deviation);
  }
  std::printf("two suns %d³: mean deviation %.2f %%, worst %.2f %%; map %d × %d texels (the first sun's alone %d × %d)\n",
              res, 100.0 * out.mean, 100.0 * out.worst, out.map.texels.x, out.map.texels.y, out.first_sun_texels.x,
              out.first_sun_texels.y);
  return out;
}

TEST(ExactOpticsSceneLights, TwoSunsOnTheSphereAddUpToTheTracersOfEach) {
  const TwoSunsBake coarse = bakeSphereUnderTwoSuns(32);
  const TwoSunsBake fine = bakeSphereUnderTwoSuns(48);
  // The one-sun bake's bounds at 48³ (expectConvergesToExactOptics: 5 % mean, 20 % worst), and
  // converging: measured 1.46 % mean and 2.78 % worst at 32³, 1.13 % and 1.56 % at 48³. A bake that
  // dropped the second sun would be off by its share, 0.6·cos 30° = 0.52 of the light outside the
  // shadows (tens of per cent); bakes on lattices of their own could not be summed texel for texel.
  EXPECT_LT(fine.mean, 0.05);
  EXPECT_LT(fine.worst, 0.20);
  EXPECT_LT(fine.mean, coarse.mean + 0.005);
  // The lattice covers the tilted sun's shadow too: wider along x than the first sun's alone.
  EXPECT_GT(fine.map.texels.x, fine.first_sun_texels.x);
  // Summed, the two runs' ledgers still close: in = received + absorbed + escaped + … (BandSum).
  EXPECT_LT(fine.stats.ledgerResidual(), 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Light from object to object (scene_bake.h SceneLightChain): two equal glass spheres (R = 1,
// n = 1.5), one above the other, under the vertical sun over the floor y = 0. The upper one
// (centre y = 4.5) focuses the sun near y = 3 (paraxial f = 1.5 from its centre), half a unit over
// the lower one (centre y = 1.5), which stands wholly in the upper one's shadow and gets only that
// converged and diverging light, and focuses it on: the paraxial focus of the upper sphere lies at
// the lower one's focal distance, so the lower one sends it on roughly parallel onto the floor. The
// floor under them, D + Σ (map_k − D) as the viewer draws it, against the exact tracer of the two
// spheres.
constexpr double kUpperY = 4.5, kLowerY = 1.5;

const reference::ReceiverTally& exactStackedSpheres() {
  static const reference::ReceiverTally tally = [] {
    reference::DirectionalBeam beam;
    beam.beam_center = {0.0, 6.0, 0.0};
    beam.beam_radius = 1.6 * std::sqrt(2.0);
    reference::Receiver receiver;
    receiver.ring_width = 0.01;
    receiver.max_radius = 2.0;
    reference::TraceOptions options;
    options.rays = 4'000'000;
    return reference::trace({reference::Solid::sphere({0.0, kUpperY, 0.0}, 1.0, 1.5),
                             reference::Solid::sphere({0.0, kLowerY, 0.0}, 1.0, 1.5)},
                            beam, receiver, options);
  }();
  return tally;
}

struct StackedBake {
  ReceiverMap floor;                     // D + Σ (map_k − D), in the world
  std::vector<SimulationStats> stats;    // upper, lower
  SceneLightChain::Exchange lower;       // what the lower sphere took in and left out
};

// Both spheres baked as `lightsim SCENE.json` bakes them (chained), or each on its own in the sun;
// the upper one of glass, or of air (n = 1: its box hands the sun on unchanged).
StackedBake bakeStackedSpheres(int res, bool chained, double upper_ior = 1.5, Backend backend = Backend::Cpu) {
  const Volume volume = sharpVolume("procedural:sphere,r=1,center=0:0:0,ior=1.5", res);
  const Volume upper = sharpVolume("procedural:sphere,r=1,center=0:0:0,ior=" + std::to_string(upper_ior), res);
  LightSpec sun;  // straight down, irradiance 1
  ReceiverSpec floor;
  floor.half_extent = 1.6;
  SimulationOptions options = lightsimSharpOptions(volume.grid);
  options.free_flight = true;
  options.straight_step_voxels = 2.0;
  options.volume_deposits = false;
  std::vector<SceneLightChain::Object> boxes(2);
  const double heights[2] = {kUpperY, kLowerY};
  for (int k = 0; k < 2; ++k) {
    SceneObjectSpec placement;
    placement.translate = {0.0, heights[k], 0.0};
    boxes[k].frame = BakeFrame::of(placement);
    propagationBox(volume.grid, options, boxes[k].lo, boxes[k].hi);
    boxes[k].h = voxelEdge(volume.grid);
  }
  SceneLightChain chain(boxes, sun, floor);
  EXPECT_EQ(chain.order(), (std::vector<std::size_t>{0, 1})) << "the upper sphere first";
  EXPECT_FALSE(chain.overlap(0, 1));
  StackedBake out;
  std::vector<ReceiverMap> maps;
  const std::unique_ptr<Simulator> lower_sim = simulatorFor(volume, backend), upper_sim = simulatorFor(upper, backend);
  for (const std::size_t k : chain.order()) {
    SimulationOptions object_options = options;
    object_options.receiver = boxes[k].frame.receiver(floor);
    if (chained) chain.attach(k, object_options);
    BakeResult bake = (k == 0 ? upper_sim : lower_sim)->run(boxes[k].frame.light(sun), object_options);
    if (chained) chain.correctMap(k, bake);
    out.stats.push_back(bake.stats);
    ReceiverMap map = bake.receivers.at(0);
    map.point += boxes[k].frame.origin;  // the frames only translate
    maps.push_back(map);
  }
  out.lower = chain.exchange(1);
  std::printf("%d³: the lower sphere took in %zu patches (%.4f W) and left out %zu cells (%.4f W)\n", res,
              out.lower.taken_in, out.lower.flux_in.x, out.lower.left_out, out.lower.flux_left_out.x);
  // The vertical sun sees both boxes alike: the two maps cover the same texels.
  EXPECT_EQ(maps[0].texels, maps[1].texels);
  EXPECT_NEAR(glm::length(maps[0].point + maps[0].origin.x * maps[0].u + maps[0].origin.y * maps[0].v -
                          (maps[1].point + maps[1].origin.x * maps[1].u + maps[1].origin.y * maps[1].v)),
              0.0, 1e-9);
  out.floor = maps[1];
  for (std::size_t i = 0; i < out.floor.irradiance.size(); ++i)
    out.floor.irradiance[i] = maps[0].irradiance[i] + maps[1].irradiance[i] - 1.0f;  // D = 1: the sun on the floor
  return out;
}

// Mean and worst deviation of the floor's rings (r < 1.3) from the exact tracer's: |bake − exact|
// over the exact ring's irradiance, or over the sun's (1) where the ring lies in shadow (the ring
// 0.6–0.9 gets 2·10⁻⁴ of the sun: a relative figure there would weigh rounding as an error).
std::pair<double, double> stackedDeviation(const StackedBake& bake, int res, const char* what) {
  const Rings rings = ringsOf(bake.floor);
  const reference::ReceiverTally& exact = exactStackedSpheres();
  double mean = 0.0, worst = 0.0;
  for (int k = 0; k < Rings::kCount; ++k) {
    const double want = exact.ringIrradiance(Rings::kEdges[k], Rings::kEdges[k + 1]);
    const double deviation = std::abs(rings.irradiance[k] - want) / std::max(want, 1.0);
    std::printf("%s %d³: ring %.1f–%.1f: bake %.4f exact %.4f (%.2f %%)\n", what, res, Rings::kEdges[k],
                Rings::kEdges[k + 1], rings.irradiance[k], want, 100.0 * deviation);
    mean += deviation / Rings::kCount;
    worst = std::max(worst, deviation);
  }
  std::printf("%s %d³: mean deviation %.2f %%, worst %.2f %%\n", what, res, 100.0 * mean, 100.0 * worst);
  return {mean, worst};
}

TEST(ExactOpticsSceneChain, TwoSpheresOneAboveTheOtherFocusTheSunInTurn) {
  const StackedBake coarse = bakeStackedSpheres(32, true);
  const StackedBake fine = bakeStackedSpheres(48, true);
  const auto [mean32, worst32] = stackedDeviation(coarse, 32, "chained");
  const auto [mean48, worst48] = stackedDeviation(fine, 48, "chained");
  // The issue's bound: the floor within 10 % of the tracer, every ring; measured 2.5 % mean and 7.5 %
  // worst at 32³, 1.2 % and 2.9 % at 48³ (the centre ring, where the lower sphere's caustic peaks).
  EXPECT_LT(worst48, 0.10);
  EXPECT_LT(mean48, 0.05);
  EXPECT_LT(mean48, mean32 + 0.005);  // it converges (or holds)
  // The lower sphere stands wholly in the upper one's shadow: the sun's cells through the upper
  // box are left out of its bake, and the upper sphere's light comes in instead.
  EXPECT_GT(fine.lower.left_out, 0u);
  EXPECT_GT(fine.lower.taken_in, 0u);
  // Each sphere's ledger closes with what it took in.
  for (const SimulationStats& s : fine.stats) EXPECT_LT(s.ledgerResidual(), 1e-9);
  // Baked each on its own in the sun (no light from one to the other) the floor is far off: the
  // test fails without the chain.
  const StackedBake alone = bakeStackedSpheres(48, false);
  const auto [mean_alone, worst_alone] = stackedDeviation(alone, 48, "each alone");
  EXPECT_GT(mean_alone, 5.0 * mean48);
  EXPECT_GT(worst_alone, 0.5);
}

// The GPU path (OSMesa/llvmpipe here) hands the light on as the twin does: the patches that leave
// the upper box are read back a step at a time (SimulationOptions::on_leave), and the lower sphere's
// initial patches go up with those taken in. Its floor within the twin's bounds against the exact
// tracer at 32³, and within 1 % relative L2 of the twin's (float against double on the same
// patches; the single sphere's GL map is measured within 1 % of the twin's too).
TEST(ExactOpticsSceneChain, TheGpuPathHandsTheLightOnAsTheTwinDoes) {
  const StackedBake gl = bakeStackedSpheres(32, true, 1.5, Backend::Gl);
  const StackedBake cpu = bakeStackedSpheres(32, true);
  const auto [mean, worst] = stackedDeviation(gl, 32, "chained, GL");
  EXPECT_LT(mean, 0.03);
  EXPECT_LT(worst, 0.08);
  EXPECT_GT(gl.lower.taken_in, 0u);
  EXPECT_EQ(gl.lower.left_out, cpu.lower.left_out);
  const double l2 = relativeL2(gl.floor.rgbValues(), cpu.floor.rgbValues());
  std::printf("GL against the twin: relative L2 %.3g; taken in %zu against %zu\n", l2, gl.lower.taken_in,
              cpu.lower.taken_in);
  EXPECT_LT(l2, 0.01);
}

// An object of air (n = 1) above the sphere hands the sun on as it came: the chained floor is the
// floor of the sphere baked alone (the patches taken in are the upper box's plane wave, flown to
// the lower box; what they would put on the floor going straight is taken away from it and what the
// left-out cells would have put there added back). Here the two boxes' cells coincide (one grid,
// the vertical sun, boxes 3 apart), so the patches taken in are the lower box's own cells and the
// floors agree to rounding (measured 0); 1 % would hold patches of another lattice, and a patch
// taken in where it left a free flight instead of at the box (the first version) was off by 90 %.
TEST(ExactOpticsSceneChain, AnObjectOfAirHandsTheSunOnUnchanged) {
  const StackedBake chained = bakeStackedSpheres(32, true, 1.0);
  const StackedBake alone = bakeStackedSpheres(32, false, 1.0);
  EXPECT_GT(chained.lower.taken_in, 0u);
  const double l2 = relativeL2(chained.floor.rgbValues(), alone.floor.rgbValues());
  std::printf("air above: relative L2 %.3g\n", l2);
  EXPECT_LT(l2, 0.01);
}

// Straight steps (lightsim's default for a clear object over a ground): the corners' rays are
// straight between the sphere's surfaces and cross them exactly whatever the step, so steps of 2
// voxels instead of ½ change only where the patches split. The same bounds against exact optics at
// two resolutions, and against the steps of Δt (free flight for both) at 48³, where a step of 2
// voxels is 1/12 of the sphere's radius: 1 % would be a visible change of the caustic. (At 32³ the
// ring 0.6–0.9, lit by the rim's grazing rays, differs by 1.4 %: 9.9 % under exact optics against
// 8.6 %, which the convergence check's bounds hold.)
TEST(ExactOpticsSphere, StraightStepsBakeTheSameCausticInFewerSteps) {
  const SphereBake flown = bakeSphereOnFloor(48, Stepping::Flight), straight = bakeSphereOnFloor(48, Stepping::Straight);
  EXPECT_TRUE(straight.irradiance.data.empty());  // the map only
  EXPECT_LT(straight.stats.total_patches, flown.stats.total_patches / 3 * 2);
  const double map = relativeL2(straight.map.rgbValues(), flown.map.rgbValues());
  std::printf("straight steps against steps of Δt, 48³: map %.2e relative L2; %llu against %llu patch-steps\n", map,
              static_cast<unsigned long long>(straight.stats.total_patches),
              static_cast<unsigned long long>(flown.stats.total_patches));
  EXPECT_LT(map, 0.01);
  // The ring 0.9–1.0 within 3 %: its texels straddling the shadow's edge hold the light of the
  // patches torn there at the depth limit that passes the sphere (a quarter of a patch per corner),
  // and where the steps end moves which patches tear (measured 2.3 %, 0.0014 W/m² of its 0.06).
  for (int k = 0; k < Rings::kCount; ++k)
    EXPECT_NEAR(straight.rings.irradiance[k] / flown.rings.irradiance[k], 1.0, Rings::kEdges[k] == 0.9 ? 0.03 : 0.01)
        << "ring " << k;
  EXPECT_NEAR(straight.stats.flux_received.x, flown.stats.flux_received.x, 1e-3 * flown.stats.flux_received.x);
  expectConvergesToExactOptics(bakeSphereOnFloor(32, Stepping::Straight), straight);
}

// On a fine grid lightsim's patches are as wide against the sphere as on a coarse one
// (volumeDefaults: split past N/44 voxels, N the grid's longest side). At 96³ (N = 100: split past
// 2.27 voxels, initial patches 1.14) the caustic is as close to exact optics as with the patches of
// the coarse grids (1 voxel, split past 1.5), in far fewer patch-steps.
TEST(ExactOpticsSphere, WiderPatchesOnAFineGridBakeTheSameCausticInFewerSteps) {
  const VolumeDefaults defaults = volumeDefaults(true, sharpVolume("procedural:sphere,r=1,center=0:1.5:0,ior=1.5", 96,
                                                                   std::nullopt, 2.0).grid);
  EXPECT_NEAR(defaults.split_voxels, 100.0 / 44.0, 1e-12);
  EXPECT_NEAR(defaults.patch_voxels, 50.0 / 44.0, 1e-12);
  const SphereBake wide = bakeSphereOnFloor(96, Stepping::Straight);
  const SphereBake narrow = bakeSphereOnFloor(96, Stepping::Straight, Backend::Cpu, PatchSize{1.0, 1.5});
  // Measured: 355 089 against 497 716 patch-steps (0.71), mean deviation 1.49 % against 1.38 %,
  // every ring within 0.7 % of the narrow patches' (a split far too long for the grid, 3 voxels at
  // 64³, costs the rings lit by the rim's grazing rays, 0.4–0.9, 3–5 %).
  std::printf("96³: wide patches %llu patch-steps, mean deviation %.2f %%; narrow %llu, %.2f %%\n",
              static_cast<unsigned long long>(wide.stats.total_patches), 100.0 * wide.mean_deviation,
              static_cast<unsigned long long>(narrow.stats.total_patches), 100.0 * narrow.mean_deviation);
  EXPECT_LT(static_cast<double>(wide.stats.total_patches), 0.75 * static_cast<double>(narrow.stats.total_patches));
  // The issue's bounds at 128³: 5 % mean against exact optics and against it through the texels.
  EXPECT_LT(wide.mean_deviation, 0.05);
  EXPECT_LT(wide.mean_vs_texels, 0.05);
  // As close as the narrow patches: within half a percent of their mean deviation, and each ring
  // within 2 % of theirs.
  EXPECT_LT(wide.mean_deviation, narrow.mean_deviation + 0.005);
  for (int k = 0; k < Rings::kCount; ++k)
    EXPECT_NEAR(wide.rings.irradiance[k] / narrow.rings.irradiance[k], 1.0, 0.02) << "ring " << k;
  EXPECT_NEAR(wide.rings.shadow_radius, 1.0, 0.01);
  EXPECT_LT(wide.stats.flux_killed.x + wide.stats.flux_unfinished.x, 0.01 * std::numbers::pi);
}

// The GPU path flies across quiet space and takes straight steps as the twin does
// (shaders/lightsim/flight.glsl, the twin's code line by line in float): the same caustic within
// the exact-optics bounds at two resolutions, and the twin's map (GL against the CPU twin ≤ 1 %)
// in the twin's number of patch-steps. Without them it took 16× as many (8.9 M against 0.57 M at 64³).
TEST(ExactOpticsSphere, TheGpuPathFliesAndTakesStraightStepsAsTheTwinDoes) {
  const SphereBake cpu = bakeSphereOnFloor(48, Stepping::Straight);
  const SphereBake gpu = bakeSphereOnFloor(48, Stepping::Straight, Backend::Gl);
  EXPECT_EQ(gpu.stats.backend, "gl");
  // Float against double corners: where a patch splits or a flight ends moves by rounding, so the
  // two bakes are not the same patch for patch. Measured at 48³: 1.6e-3 relative L2, 153 947
  // against 154 608 patch-steps; 2 % more patch-steps would be a flight or straight step refused.
  const double map = relativeL2(gpu.map.rgbValues(), cpu.map.rgbValues());
  std::printf("GPU path against the twin, 48³: map %.2e relative L2; %llu against %llu patch-steps\n", map,
              static_cast<unsigned long long>(gpu.stats.total_patches),
              static_cast<unsigned long long>(cpu.stats.total_patches));
  EXPECT_LT(map, 0.01);
  for (int k = 0; k < Rings::kCount; ++k)
    EXPECT_NEAR(gpu.rings.irradiance[k] / cpu.rings.irradiance[k], 1.0, 0.01) << "ring " << k;
  EXPECT_NEAR(static_cast<double>(gpu.stats.total_patches), static_cast<double>(cpu.stats.total_patches),
              0.02 * static_cast<double>(cpu.stats.total_patches));
  // The number of steps only within a factor 2 (without flights and straight steps it was 12×):
  // the last patches alive are faint wavefronts that Fresnel reflected inside the ball and then, on
  // the voxelised surface just past the critical angle, circle in it by total internal reflection
  // until they count as trapped (kMaxTotalReflections); when that happens moves by rounding
  // (measured 128 steps on the twin, 88 on llvmpipe, with 10⁻⁶ of the light).
  EXPECT_LT(gpu.stats.steps, 2 * cpu.stats.steps);
  EXPECT_LT(cpu.stats.steps, 2 * gpu.stats.steps);
  expectConvergesToExactOptics(bakeSphereOnFloor(32, Stepping::Straight, Backend::Gl), gpu);
}

// ---------------------------------------------------------------------------------------------
// Free air: a plane wave through a box of n = 1 deposits its exact irradiance in every voxel (the
// track kernel: flux times path length with each voxel's trilinear hat), whatever the angle and
// the resolution, with no smoothing; and a receiver under it reads E·cos θ in every texel.

double worstFreeAirDeviation(int res, const glm::dvec3& direction, double* map_deviation, bool free_flight) {
  const GridSpec g = cubicGrid(res, 0.5);
  CpuSimulator sim(uniformVolume(g, 1.0));
  LightSpec light;
  light.direction = glm::normalize(direction);
  light.power = glm::dvec3(2.0);
  SimulationOptions options;
  ReceiverSpec floor;
  floor.point = {0.0, -0.6, 0.0};
  floor.half_extent = 0.4;
  options.receiver = floor;
  options.free_flight = free_flight;
  const BakeResult r = sim.run(light, options);
  EXPECT_EQ(r.stats.flights > 0, free_flight);  // all of the box is quiet
  double worst = 0.0;
  for (std::size_t v = 0; v < g.count(); ++v)
    worst = std::max(worst, std::abs(r.irradiance.voxel(v)[0] / 2.0 - 1.0));
  const ReceiverMap& map = r.receivers.at(0);
  const double expected = 2.0 * -light.direction.y;  // planar irradiance: E·cos θ
  *map_deviation = 0.0;
  for (std::size_t t = 0; t < map.texelCount(); ++t)
    *map_deviation = std::max(*map_deviation, std::abs(map.rgb(t).x / expected - 1.0));
  return worst;
}

// The suite checks 32³ and 64³; EIKONAL_FREE_AIR_RES="128 256" runs the larger grids the issue
// names (minutes each on two cores: BENCHMARKS.md has the figures).
std::vector<int> freeAirResolutions() {
  std::vector<int> res;
  if (const char* list = std::getenv("EIKONAL_FREE_AIR_RES")) {
    std::istringstream in(list);
    for (int r; in >> r;) res.push_back(r);
  }
  if (res.empty()) res = {32, 64};
  return res;
}

// Free flight (lightsim's default) at every resolution, steps of Δt at the smallest.
TEST(ExactOpticsFreeAir, EveryVoxelAndTexelGetsTheBeamsIrradiance) {
  const std::vector<int> resolutions = freeAirResolutions();
  for (int res : resolutions)
    for (const bool flight : {true, false})
    for (const glm::dvec3& direction : {glm::dvec3(0, -1, 0), glm::dvec3(std::sin(0.6109), -std::cos(0.6109), 0.0),
                                        glm::dvec3(0.3, -1.0, 0.45)}) {
      if (!flight && res != resolutions.front()) continue;
      double map = 0.0;
      const double worst = worstFreeAirDeviation(res, direction, &map, flight);
      std::printf("free air %d³%s, light (%.2f, %.2f, %.2f): worst voxel %.3f %%, worst texel %.2e %%\n", res,
                  flight ? ", free flight" : "", direction.x, direction.y, direction.z, 100.0 * worst, 100.0 * map);
      // 1 %: the issue's bound. Measured ≤ 0.45 % (the sub-path lattice of ½ voxel across the
      // patch; exactly 0 along the axes).
      EXPECT_LT(worst, 0.01) << res;
      // The footprints tile the plane: each texel gets its exact share (to rounding).
      EXPECT_LT(map, 1e-6) << res;
    }
}

// The map of a light over the floor y = −0.6 (half extent `half_extent`), through the 32³ box
// [−0.5, 0.5]³ of air.
BakeResult bakeThroughAirOntoTheFloor(const LightSpec& light, double half_extent, double patch_voxels = 1.0) {
  CpuSimulator sim(uniformVolume(cubicGrid(32, 0.5), 1.0));
  SimulationOptions options;
  options.patch_voxels = patch_voxels;
  ReceiverSpec floor;
  floor.point = {0.0, -0.6, 0.0};
  floor.half_extent = half_extent;
  options.receiver = floor;
  return sim.run(light, options);
}

// A point light of intensity I over a floor, through a box of air: the floor's planar irradiance
// is I·cos θ / d² = I·h / d³ at every texel (h the light's height over the floor, d its distance),
// the inverse-square law with the cosine of incidence. The light sits off the box's axis, so the
// map holds both the light that crossed the box as patches and what reached the floor beside it in
// closed form (directMapLight). Returns the worst texel of each: {beside the box, through it}.
std::pair<double, double> pointLightOverAFloor(double patch_voxels) {
  const GridSpec g = cubicGrid(32, 0.5);
  LightSpec light;
  light.type = LightSpec::Type::Point;
  light.position = {0.1, 1.5, -0.05};
  light.power = glm::dvec3(3.0);  // W/sr
  const BakeResult r = bakeThroughAirOntoTheFloor(light, 1.5, patch_voxels);
  const ReceiverMap& map = r.receivers.at(0);
  const double h = light.position.y + 0.6;
  double beside = 0.0, through = 0.0, nearest = 1e30, farthest = 0.0;
  std::size_t lit = 0, crossed = 0;
  for (int j = 0; j < map.texels.y; ++j)
    for (int i = 0; i < map.texels.x; ++i) {
      const glm::dvec3 c = map.texelCenter(i, j);
      const double d = glm::length(c - light.position);
      const double want = 3.0 * h / (d * d * d);
      const double got = map.rgb(static_cast<std::size_t>(j) * map.texels.x + i).x;
      // Through the box: the texels the followed patches may reach (their centre rays meet the box
      // grown by lightsim's voxel of margin, and they reach half a patch beyond): the box grown by
      // 2 voxels.
      const bool box = rayHitsBox(light.position, glm::normalize(c - light.position), g.bounds_min - 2.0 / 32.0,
                                  g.bounds_max + 2.0 / 32.0);
      (box ? through : beside) = std::max(box ? through : beside, std::abs(got / want - 1.0));
      crossed += box;
      nearest = std::min(nearest, d);
      farthest = std::max(farthest, d);
      lit += got > 0.0;
    }
  std::printf("point light over a floor, patches of %.2f voxel: %d x %d texels (%zu through the box), distances "
              "%.3f–%.3f, worst texel %.3f %% beside the box, %.3f %% through it; %llu patch-steps\n",
              patch_voxels, map.texels.x, map.texels.y, crossed, nearest, farthest, 100.0 * beside, 100.0 * through,
              static_cast<unsigned long long>(r.stats.total_patches));
  // The map reaches well past the box's shadow, where the irradiance has fallen by more than 2×.
  EXPECT_GT(std::pow(farthest / nearest, 3.0), 2.0);
  EXPECT_EQ(lit, map.texelCount());
  EXPECT_GT(crossed, map.texelCount() / 8);
  EXPECT_GT(map.texelCount() - crossed, map.texelCount() / 4);
  return {beside, through};
}

TEST(ExactOpticsFreeAir, APointLightFallsOffByTheInverseSquareLaw) {
  const auto [beside, through] = pointLightOverAFloor(1.0);
  const auto [beside_fine, through_fine] = pointLightOverAFloor(0.5);
  // Beside the box, in closed form: 1 %, the issue's bound (a texel's mean differs from the law at
  // its centre by the curvature over a texel of h/4, under 10⁻⁴ here); a missing cos θ or a 1/d
  // instead of 1/d² is off by tens of per cent.
  EXPECT_LT(beside, 0.01);
  EXPECT_LT(beside_fine, 0.01);
  // Through the box the light is carried by patches, each spreading its flux evenly over its
  // footprint, where the law changes by |∇ ln E| = 3r/d² across it: a first-order error that
  // halves with the patch (measured 2.8 % and 1.2 % at the box's far corners, where the footprints
  // are largest and the fall steepest). The bound: 3.5 % at a voxel, and the finer patches at most
  // 0.6 of it: it converges.
  EXPECT_LT(through, 0.035);
  EXPECT_LT(through_fine, 0.6 * through);
}

// A spot light (glTF KHR_lights_punctual's cone: full intensity within 30° of its axis, none beyond
// 40°, ((cos θ − cos 40°)/(cos 30° − cos 40°))² between) straight down over a floor 2.6 below, through
// a box of air whose corners lie within 27° of the axis: the floor's irradiance is I·a(θ)·cos θ/d² at
// every texel, and the lit disc ends at r = 2.6·tan 40°.
TEST(ExactOpticsFreeAir, ASpotLightsConeEndsWhereItsOuterAngleMeetsTheFloor) {
  LightSpec light;
  light.type = LightSpec::Type::Spot;
  light.position = {0.0, 2.0, 0.0};
  light.direction = {0.0, -1.0, 0.0};
  light.inner_cone_deg = 30.0;
  light.outer_cone_deg = 40.0;
  light.power = glm::dvec3(3.0);  // W/sr on the axis
  const BakeResult r = bakeThroughAirOntoTheFloor(light, 2.5);
  const ReceiverMap& map = r.receivers.at(0);
  const double h = light.position.y + 0.6;
  const double cos_inner = std::cos(glm::radians(30.0)), cos_outer = std::cos(glm::radians(40.0));
  double worst = 0.0, last_lit = 0.0, first_dark = 1e30;
  int falloff = 0;
  for (int j = 0; j < map.texels.y; ++j)
    for (int i = 0; i < map.texels.x; ++i) {
      const glm::dvec3 c = map.texelCenter(i, j);
      const double d = glm::length(c - light.position), cos_theta = h / d;
      const double t = std::clamp((cos_theta - cos_outer) / (cos_inner - cos_outer), 0.0, 1.0);
      const double want = 3.0 * t * t * h / (d * d * d);
      const double got = map.rgb(static_cast<std::size_t>(j) * map.texels.x + i).x;
      const double radius = std::hypot(c.x, c.z);
      if (want > 0.0) worst = std::max(worst, std::abs(got / want - 1.0));
      else EXPECT_EQ(got, 0.0) << "outside the cone at r = " << radius;
      if (t > 0.0 && t < 1.0) ++falloff;
      if (std::abs(c.z) < map.pitch) {  // the row through the axis
        if (got > 0.0) last_lit = std::max(last_lit, std::abs(c.x));
        else first_dark = std::min(first_dark, std::abs(c.x));
      }
    }
  const double edge = h * std::tan(glm::radians(40.0));
  std::printf("spot light over a floor: %d x %d texels of %.4f, worst texel %.3f %% (%d in the falloff); lit to "
              "%.4f, dark from %.4f, the cone's edge at %.4f\n",
              map.texels.x, map.texels.y, map.pitch, 100.0 * worst, falloff, last_lit, first_dark, edge);
  EXPECT_GT(falloff, 1000);
  // As the point light's (ExactOpticsFreeAir.APointLightFallsOffByTheInverseSquareLaw): the box's
  // corners are inside the inner cone, where its patches' flat footprints are measured at 2.8 % off
  // the law; beside it, the falloff included, every texel is in closed form.
  EXPECT_LT(worst, 0.035);
  // The cone's edge between the last lit texel centre and the first dark one on the row through
  // the axis: within half a texel of the edge, as the issue asks.
  EXPECT_NEAR(0.5 * (last_lit + first_dark), edge, 0.5 * map.pitch);
  EXPECT_LT(first_dark - last_lit, 1.5 * map.pitch);
}

// ---------------------------------------------------------------------------------------------
// A glass slab, n = 1.5, 0.3 thick, horizontal and wider than the grid, in light tilted 35° from
// the vertical: the beam leaves it parallel to itself, shifted sideways by d·sin(θi − θt)/cos θt,
// and carrying (1 − R)² of its flux (R at θi going in equals R at θt going out).

TEST(ExactOpticsSlab, ShiftsTheBeamBySnellsLawAndTransmitsTheFresnelFraction) {
  const double n = 1.5, d = 0.3, theta_i = 35.0 * std::numbers::pi / 180.0;
  const Bounds b = box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  const Volume volume = sharpVolume("procedural:box,size=4:0.3:4,center=0:0:0,ior=1.5", 48, b);
  CpuSimulator sim(volume);
  const VolumeSampler& sampler = sim.sampler();
  const double h = sampler.h();
  const glm::dvec3 L(std::sin(theta_i), -std::cos(theta_i), 0.0);

  // One corner through the slab (the bake's own stepping of a corner).
  glm::dvec3 x(-0.3, 0.45, 0.0), w = L;
  int medium = sampler.materialAt(x);
  glm::dvec4 sample = sampler.materialOptics(medium, x);
  for (int step = 0; step < 400 && x.y > -0.45; ++step)
    advanceCornerSharp(x, w, medium, sample, 0.5 * h, Integrator::Euler, sampler);
  // Snell: inside at θt, entering at y = 0.15 where the straight line from (−0.3, 0.45) meets it.
  const double theta_t = std::asin(std::sin(theta_i) / n);
  const double x_in = -0.3 + (0.45 - 0.15) * std::tan(theta_i);
  const double x_out = x_in + d * std::tan(theta_t);
  // The exact exit line: through (x_out, −0.15) along L. The corner's offset across it:
  const glm::dvec3 off = x - glm::dvec3(x_out, -0.15, 0.0);
  const double across = glm::length(off - glm::dot(off, L) * L);
  const double shift = d * std::sin(theta_i - theta_t) / std::cos(theta_t);
  std::printf("slab: Snell's shift %.5f; the corner is %.2e voxel off the exact shifted ray\n", shift, across / h);
  EXPECT_LT(across, 0.05 * h);  // the issue's bound: 0.05 voxel
  EXPECT_NEAR(glm::dot(glm::normalize(w), L), 1.0, 1e-9);  // parallel to the incident beam again

  // The flux: a receiver under the slab, away from the grid's edges.
  LightSpec light;
  light.direction = L;
  SimulationOptions options;
  options.bounces = 0;  // single pass: the inter-reflection (R² = 0.2 %) is not followed
  ReceiverSpec floor;
  floor.point = {0.0, -0.6, 0.0};
  floor.half_extent = 0.25;
  options.receiver = floor;
  const BakeResult r = sim.run(light, options);
  const ReceiverMap& map = r.receivers.at(0);
  double mean = 0.0;
  for (std::size_t t = 0; t < map.texelCount(); ++t) mean += map.rgb(t).x;
  mean /= static_cast<double>(map.texelCount());
  const double R = reference::fresnelReflectance(1.0, n, std::cos(theta_i));
  const double expected = std::cos(theta_i) * (1.0 - R) * (1.0 - R);
  std::printf("slab: transmitted %.6f, Fresnel (1 − R)² cos θ %.6f (%+.3f %%)\n", mean, expected,
              100.0 * (mean / expected - 1.0));
  EXPECT_NEAR(mean / expected, 1.0, 0.005);  // the issue's bound: 0.5 %
  EXPECT_LT(r.stats.ledgerResidual(), 1e-9);
}

// A reflected wavefront's straight steps (kReflectedStepFactor × 2 voxels) are longer than a thin
// glass wall is thick: a step whose chord starts above a slab 3 voxels thick and ends below it
// ends in air, as it started. Looked at in pieces (findInterfaceOnChord), the chord still meets
// both surfaces, and the corner leaves on the exact shifted ray wherever along a step the slab
// lies (eight starts a step apart by eighths). Asked at its end only, the chord passes through the
// slab for most starts and the corner stays on the unshifted ray, 0.7 voxel across.
TEST(ExactOpticsSlab, LongStraightStepsMeetAWallThinnerThanThemselves) {
  const double n = 1.5, theta_i = 35.0 * std::numbers::pi / 180.0;
  const Bounds b = box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  const double d = 3.0 / 48.0;  // 3 voxels at 48³ in the unit box
  const Volume volume = sharpVolume("procedural:box,size=4:" + std::to_string(d) + ":4,center=0:0:0,ior=1.5", 48, b);
  CpuSimulator sim(volume);
  const VolumeSampler& sampler = sim.sampler();
  const double h = sampler.h();
  ASSERT_LT(d, 4.0 * h);  // thinner than half the step
  const glm::dvec3 L(std::sin(theta_i), -std::cos(theta_i), 0.0);
  const double step = kReflectedStepFactor * 2.0 * h;  // the time of a reflected wavefront's step in air
  ASSERT_EQ(chordPieces(step, h), 4);
  const double theta_t = std::asin(std::sin(theta_i) / n);
  double worst = 0.0;
  for (int s = 0; s < 8; ++s) {
    glm::dvec3 x(-0.3, 0.25 + (s / 8.0) * step * std::cos(theta_i), 0.0), w = L;
    const glm::dvec3 start = x;
    int medium = sampler.materialAt(x);
    glm::dvec4 sample = sampler.materialOptics(medium, x);
    int transmitted = 0;
    for (int k = 0; k < 40 && x.y > -0.3; ++k)
      transmitted += advanceCornerSharp(x, w, medium, sample, step, Integrator::Euler, sampler).transmitted;
    const double x_in = start.x + (start.y - 0.5 * d) * std::tan(theta_i);
    const glm::dvec3 exit(x_in + d * std::tan(theta_t), -0.5 * d, 0.0);
    const glm::dvec3 off = x - exit;
    const double across = glm::length(off - glm::dot(off, L) * L);
    worst = std::max(worst, across / h);
    EXPECT_EQ(transmitted, 2) << "start " << s;
    EXPECT_LT(across, 0.05 * h) << "start " << s;  // as the slab's half-voxel steps above
  }
  std::printf("thin slab, steps of %.0f voxels: the corner at most %.2e voxel off the exact shifted ray\n",
              step / h, worst);
}

// The two slabs of the next tests in the unit box at `res`³: clear glass (n = 1.5) over an
// absorbing liquid (n = 1.33, σa = 2 per material), both 0.2 thick and wider than the grid.
Volume twoSlabs(int res) {
  return sharpVolume(std::vector<std::string>{"procedural:box,size=4:0.2:4,center=0:0.2:0,ior=1.5",
                                              "procedural:box,size=4:0.2:4,center=0:-0.2:0,ior=1.33,sigma_a=2:2:2"},
                     res, box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}));
}

// Light tilted θi from the vertical towards +x, and a single pass (no reflected wavefront followed)
// with free flight, with or without the volume's light.
LightSpec tiltedLight(double theta_i) {
  LightSpec light;
  light.direction = glm::dvec3(std::sin(theta_i), -std::cos(theta_i), 0.0);
  return light;
}
SimulationOptions singlePass(bool volume_deposits) {
  SimulationOptions options;
  options.bounces = 0;
  options.free_flight = true;
  options.volume_deposits = volume_deposits;
  return options;
}

// Straight steps in an absorbing volume: a clear glass slab (n = 1.5) over an absorbing liquid one
// (n = 1.33, σa = 2), both 0.2 thick, light tilted 20°, single pass. What reaches the floor is
// cos θi (1 − R₁)² (1 − R₂)² exp(−σa d / cos θt₂), exactly. Two ways to absorb:
//  - σa per material (VolumeSampler::absorptionPerMaterial, the volume as voxelized): each corner's
//    path is absorbed piece by piece in its material, ending on the interface, so steps are straight
//    (2 voxels) everywhere and the thickness is exact;
//  - the σa field (one voxel of it changed where no measured ray passes, so that the liquid is not
//    one value): step 2 takes σa at the old midpoint, so near and in the liquid the steps are Δt
//    (the absorber map), straight only near the clear slab.
TEST(ExactOpticsSlab, StraightStepsKeepBeerLambertInAnAbsorbingLiquid) {
  const double theta_i = 20.0 * std::numbers::pi / 180.0, sigma = 2.0, d = 0.2;
  const Volume per_material = twoSlabs(48);
  // A liquid voxel at the grid's −x −z corner: its light lands near x ≈ −0.3 on the floor, outside
  // the measured square; the slot's σa then disagrees with the field, which alone describes it.
  Volume field = per_material;
  const std::size_t odd_voxel = field.grid.index(0, field.grid.dims.y / 2 - 10, 0);
  ASSERT_GT(field.fields.at("sigma_a").voxel(odd_voxel)[0], 1.9f);
  field.fields.at("sigma_a").voxel(odd_voxel)[0] = 2.1f;
  ASSERT_TRUE(VolumeSampler(per_material).absorptionPerMaterial());
  ASSERT_FALSE(VolumeSampler(field).absorptionPerMaterial());
  const LightSpec light = tiltedLight(theta_i);
  SimulationOptions options = singlePass(false);
  // The floor's square where every ray came in through the grid's top face (back along the light,
  // x shifts by about −0.4 from the floor to the top), so it crossed both slabs inside the grid
  // (the slabs reach beyond the grid's sides, where the light does not start).
  ReceiverSpec floor;
  floor.point = {0.2, -0.6, 0.0};
  floor.half_extent = 0.15;
  options.receiver = floor;
  SimulationOptions straight = options;
  straight.straight_step_voxels = 2.0;
  const double R1 = reference::fresnelReflectance(1.0, 1.5, std::cos(theta_i));
  const double R2 = reference::fresnelReflectance(1.0, 1.33, std::cos(theta_i));
  const double cos_t2 = std::sqrt(1.0 - std::pow(std::sin(theta_i) / 1.33, 2.0));
  const double expected = std::cos(theta_i) * std::pow((1.0 - R1) * (1.0 - R2), 2.0) * std::exp(-sigma * d / cos_t2);
  // The CPU twin and the GPU path (MATERIAL_ABSORPTION, or its absorber map: shaders/lightsim/).
  std::uint64_t straight_patch_steps[2][2] = {{0, 0}, {0, 0}};  // [field, per material][cpu, gl]
  for (const bool by_material : {false, true}) {
    for (const Backend backend : {Backend::Cpu, Backend::Gl}) {
      SCOPED_TRACE(std::string(backend == Backend::Cpu ? "cpu" : "gl") + (by_material ? ", per material" : ", field"));
      const std::unique_ptr<Simulator> sim = simulatorFor(by_material ? per_material : field, backend);
      std::uint64_t patch_steps[2] = {0, 0};
      double transmitted[2] = {0.0, 0.0};
      int run = 0;
      for (const SimulationOptions& o : {options, straight}) {
        const BakeResult r = sim->run(light, o);
        const ReceiverMap& map = r.receivers.at(0);
        double mean = 0.0;
        for (std::size_t t = 0; t < map.texelCount(); ++t) mean += map.rgb(t).x;
        mean /= static_cast<double>(map.texelCount());
        std::printf("two slabs, %s, σa %s, %s: transmitted %.6f, exact %.6f (%+.3f %%), %llu patch-steps\n",
                    r.stats.backend.c_str(), by_material ? "per material" : "field",
                    run == 0 ? "steps of Δt" : "straight steps", mean, expected, 100.0 * (mean / expected - 1.0),
                    static_cast<unsigned long long>(r.stats.total_patches));
        // Per material: measured exact to the digits printed on both back ends; 0.05 % leaves room
        // for the GPU's float arithmetic. The field: measured −0.05 %, within the slab test's 0.5 %
        // (the field's ramp across the surface holds a thickness quantised to voxel centres).
        EXPECT_NEAR(mean / expected, 1.0, by_material ? 5e-4 : 0.005);
        // The GPU's ledger sums float per-patch entries (gpu_simulator_test's bound).
        EXPECT_LT(r.stats.ledgerResidual(), backend == Backend::Cpu ? 1e-9 : 1e-4);
        transmitted[run] = mean;
        patch_steps[run++] = r.stats.total_patches;
      }
      EXPECT_LT(patch_steps[1], patch_steps[0]);
      straight_patch_steps[by_material ? 1 : 0][backend == Backend::Cpu ? 0 : 1] = patch_steps[1];
      // Per material the absorption is exact at any step; with the field, near the liquid both
      // step by Δt, so the absorption is the same: measured equal to the digit printed.
      EXPECT_NEAR(transmitted[1] / transmitted[0], 1.0, 2e-4);
    }
    // The GPU path flies and steps as the twin does (per material measured 82 900 patch-steps on
    // both, with the field 161 723 on both; before the GPU flew through the liquid, 230 700).
    const std::uint64_t* counts = straight_patch_steps[by_material ? 1 : 0];
    EXPECT_NEAR(static_cast<double>(counts[1]), static_cast<double>(counts[0]), 0.01 * static_cast<double>(counts[0]));
  }
  // Straight steps through the liquid as well: measured 82 900 against 161 723 patch-steps.
  EXPECT_LT(straight_patch_steps[1][0], 0.6 * static_cast<double>(straight_patch_steps[0][0]));
  // A second resolution: per material the absorbing thickness is the interfaces', not the grid's, so
  // a 32³ grid (slabs 6.4 voxels thick) holds the same exact answer on both back ends.
  const Volume coarse = twoSlabs(32);
  ASSERT_TRUE(VolumeSampler(coarse).absorptionPerMaterial());
  for (const Backend backend : {Backend::Cpu, Backend::Gl}) {
    const BakeResult r = simulatorFor(coarse, backend)->run(light, straight);
    const ReceiverMap& map = r.receivers.at(0);
    double mean = 0.0;
    for (std::size_t t = 0; t < map.texelCount(); ++t) mean += map.rgb(t).x;
    mean /= static_cast<double>(map.texelCount());
    std::printf("two slabs at 32³, %s, σa per material, straight steps: transmitted %.6f (%+.3f %%)\n",
                r.stats.backend.c_str(), mean, 100.0 * (mean / expected - 1.0));
    EXPECT_NEAR(mean / expected, 1.0, 5e-4) << r.stats.backend;  // as at 48³
  }
}

// Smoke in a box (n = 1, no surface of its own; σa = 0.5, 2, 4 per unit, 0.37 high, its faces off
// the voxel lattice) beside a small glass cube, lit straight down, single pass: the floor under the
// smoke gets exp(−σa·d) of the sun's irradiance. The air's σa is one box of smoke (core/interfaces.h
// airMediumBox), so σa is per material: each corner's path absorbs the smoke's σa over the share of
// it inside the box, and the steps are straight (2 voxels) or flights through it, on both back ends
// and at two resolutions. With one smoke voxel changed (where no measured ray passes) the smoke is
// not one value, σa comes from the field, and the light steps by Δt through all of it.
TEST(ExactOpticsSlab, SmokeInABoxAbsorbsAsBeerLambertInStraightSteps) {
  const glm::dvec3 sigma(0.5, 2.0, 4.0);
  const double d = 0.37;
  SimulationOptions options = singlePass(false);
  options.straight_step_voxels = 2.0;
  ReceiverSpec floor;
  floor.point = {-0.13, -0.6, -0.11};  // under the smoke's middle
  floor.half_extent = 0.12;
  options.receiver = floor;
  LightSpec light;  // straight down, irradiance 1
  for (const int res : {32, 45}) {
    const Volume boxed = sharpVolume(std::vector<std::string>{"procedural:box,size=0.12:0.12:0.12,center=0.38:0.3:0.38,ior=1.5",
                                                              "procedural:box,size=0.5:0.37:0.5,center=-0.13:0.03:-0.11,ior=1,sigma_a=0.5:2:4"},
                                     res, box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}));
    Volume field = boxed;
    const glm::ivec3 corner = glm::ivec3((glm::dvec3(-0.3, -0.1, -0.3) - field.grid.bounds_min) / field.grid.voxelSize());
    float* odd = field.fields.at("sigma_a").voxel(field.grid.index(corner.x, corner.y, corner.z));
    ASSERT_FLOAT_EQ(odd[0], 0.5f) << "a deep smoke voxel";
    odd[0] = 0.6f;
    ASSERT_TRUE(VolumeSampler(boxed).airBox().has_value());
    ASSERT_TRUE(VolumeSampler(boxed).absorptionPerMaterial());
    ASSERT_FALSE(VolumeSampler(field).absorptionPerMaterial());
    for (const Backend backend : {Backend::Cpu, Backend::Gl}) {
      std::uint64_t patch_steps[2] = {0, 0};  // [field, box]
      for (const bool by_box : {false, true}) {
        const BakeResult r = simulatorFor(by_box ? boxed : field, backend)->run(light, options);
        const ReceiverMap& map = r.receivers.at(0);
        glm::dvec3 mean(0.0);
        for (std::size_t t = 0; t < map.texelCount(); ++t) mean += map.rgb(t);
        mean /= static_cast<double>(map.texelCount());
        for (int c = 0; c < 3; ++c) {
          const double expected = std::exp(-sigma[c] * d);
          std::printf("smoke box %d³, %s, σa %s, channel %d: transmitted %.6f, exact %.6f (%+.3f %%), %llu patch-steps\n",
                      res, r.stats.backend.c_str(), by_box ? "per material" : "field", c, mean[c], expected,
                      100.0 * (mean[c] / expected - 1.0), static_cast<unsigned long long>(r.stats.total_patches));
          // Exact but for stray light from the glass cube's edges: with the smoke clear the map
          // reads 1.00015 of the sun at 32³ (measured); 3·10⁻⁴ of the sun's irradiance.
          EXPECT_NEAR(mean[c], expected, 3e-4) << res << "³ " << r.stats.backend << (by_box ? " box" : " field") << " channel " << c;
        }
        EXPECT_LT(r.stats.ledgerResidual(), backend == Backend::Cpu ? 1e-9 : 1e-4);
        patch_steps[by_box ? 1 : 0] = r.stats.total_patches;
      }
      // Straight steps through the smoke: measured 12 880 against 29 351 patch-steps at 32³, 20 929
      // against 51 942 at 45³ (the GPU path within 1 % of those).
      EXPECT_LT(static_cast<double>(patch_steps[1]), 0.6 * static_cast<double>(patch_steps[0])) << res << "³";
    }
  }
}

// Volume deposits in the same two slabs (σa per material), light tilted 35°, single pass. A track
// deposit measures the fluence rate Φ·ℓ/V, which for a collimated beam is its irradiance across
// the beam, a function of height alone here:
//   above the glass  E₀                      in the glass   E₀ (1 − R₁) cos θi / cos θt₁
//   between them     E₀ (1 − R₁)²            in the liquid  E₀ (1 − R₁)² (1 − R₂) (cos θi / cos θt₂) e^(−σa (y₂ − y)/cos θt₂)
//   below            E₀ (1 − R₁)² (1 − R₂)² e^(−σa d / cos θt₂)
// (y₂ the liquid's top, d its thickness). A voxel holds its trilinear hat's average of that,
// ∫ hat((y − y_v)/h) E(y) dy / h: across x and z the hats integrate to h each. It checks that
//  - the flux decays along a step as it does in the liquid, exp(−σa s), not as the mean of its two
//    ends: a flight crosses the liquid in a few steps (the mean made a staircase, 7–10 % off);
//  - straight steps (2 voxels) keep the answer: one in which a corner meets an interface is retaken
//    as a step of Δt, so every deposited chord is the ray itself or a chord of Δt.
TEST(ExactOpticsSlab, VolumeIrradianceFollowsTheBeamThroughBothSlabs) {
  const double theta_i = 35.0 * std::numbers::pi / 180.0, sigma = 2.0;
  const double interfaces[4] = {0.3, 0.1, -0.1, -0.3};  // glass top, bottom; liquid top, bottom
  const double R1 = reference::fresnelReflectance(1.0, 1.5, std::cos(theta_i));
  const double R2 = reference::fresnelReflectance(1.0, 1.33, std::cos(theta_i));
  const double cos_i = std::cos(theta_i);
  const double cos_t1 = std::sqrt(1.0 - std::pow(std::sin(theta_i) / 1.5, 2.0));
  const double cos_t2 = std::sqrt(1.0 - std::pow(std::sin(theta_i) / 1.33, 2.0));
  auto exact = [&](double y) {
    if (y > interfaces[0]) return 1.0;
    if (y > interfaces[1]) return (1.0 - R1) * cos_i / cos_t1;
    const double gap = (1.0 - R1) * (1.0 - R1);
    if (y > interfaces[2]) return gap;
    if (y > interfaces[3]) return gap * (1.0 - R2) * cos_i / cos_t2 * std::exp(-sigma * (interfaces[2] - y) / cos_t2);
    return gap * (1.0 - R2) * (1.0 - R2) * std::exp(-sigma * (interfaces[2] - interfaces[3]) / cos_t2);
  };
  const LightSpec light = tiltedLight(theta_i);
  const SimulationOptions options = singlePass(true);
  SimulationOptions straight = options;
  straight.straight_step_voxels = 2.0;
  for (const int res : {48, 32}) {
    const Volume volume = twoSlabs(res);
    const GridSpec& g = volume.grid;
    const double h = g.voxelSize().y;
    // The hat's average by the midpoint rule on 4000 pieces of its support: exact to ~10⁻⁶ away
    // from the jumps, to ~10⁻⁴ where one falls in a piece.
    auto voxelExact = [&](double y_v) {
      constexpr int kPieces = 4000;
      double sum = 0.0;
      for (int i = 0; i < kPieces; ++i) {
        const double t = -1.0 + (i + 0.5) * (2.0 / kPieces);
        sum += (1.0 - std::fabs(t)) * exact(y_v + t * h);
      }
      return sum * (2.0 / kPieces);
    };
    // The voxels every ray of whose hats came in through the grid's top face: back along the light
    // a ray shifts by at most tan θi per unit of height (in air), 0.70 from the bottom to the top,
    // so x ≥ −0.5 + 0.70 + 2h; two voxels from every other face.
    const int i0 = static_cast<int>(std::ceil((0.2 + 2.0 * h - g.bounds_min.x) / h - 0.5)), i1 = g.dims.x - 2;
    for (const Backend backend : {Backend::Cpu, Backend::Gl}) {
      if (res != 48 && backend == Backend::Gl) continue;  // the GPU path at one resolution
      SCOPED_TRACE(std::string(backend == Backend::Cpu ? "cpu " : "gl ") + std::to_string(res));
      const std::unique_ptr<Simulator> sim = simulatorFor(volume, backend);
      std::uint64_t patch_steps[2] = {0, 0};
      int run = 0;
      for (const SimulationOptions& o : {options, straight}) {
        const BakeResult r = sim->run(light, o);
        // Each layer's mean over the measured voxels: the lattice's ripple (≤ 0.54 % a voxel,
        // track_deposit.h) averages out across a layer, what depends on height does not. Apart:
        // the layers whose hats reach within half a voxel of an interface, where the chords of the
        // steps of Δt that cross it blur the jump.
        double worst[2] = {0.0, 0.0}, sum = 0.0;  // [away from interfaces, at one]
        int count = 0;
        for (int j = 2; j < g.dims.y - 2; ++j) {
          const double y = g.bounds_min.y + (j + 0.5) * h;
          double mean = 0.0;
          int n = 0;
          for (int k = 2; k < g.dims.z - 2; ++k)
            for (int i = i0; i < i1; ++i, ++n) mean += voxelValue(r.irradiance, g, i, j, k).x;
          const double deviation = std::fabs(mean / n / voxelExact(y) - 1.0);
          bool at_interface = false;
          for (const double yi : interfaces) at_interface |= std::fabs(y - yi) < 1.5 * h;
          worst[at_interface ? 1 : 0] = std::max(worst[at_interface ? 1 : 0], deviation);
          sum += deviation;
          ++count;
        }
        std::printf("two slabs, volume irradiance, %d³, %s, %s: layers off by %.3f %% on average, at most %.3f %% "
                    "away from the interfaces and %.3f %% at one; %llu patch-steps\n",
                    res, r.stats.backend.c_str(), run == 0 ? "steps of Δt" : "straight steps", 100.0 * sum / count,
                    100.0 * worst[0], 100.0 * worst[1], static_cast<unsigned long long>(r.stats.total_patches));
        // Away from the interfaces the layers hold the exact answer to float precision and the
        // ripple that the layer's mean leaves (measured ≤ 0.011 %; the mean of the two ends of a
        // flight, as the bake had it, was up to 10 % off in the liquid).
        EXPECT_LT(worst[0], 0.001);
        // At an interface a step of Δt (½ voxel) that crosses it deposits along its chord, up to
        // sin(θi − θt)·Δt/4 ≈ 0.03 voxel off the kinked ray, which moves a jump of 7–15 % by that
        // much in the hat's average: measured 0.37 % (32³) to 0.94 % (48³).
        EXPECT_LT(worst[1], 0.015);
        patch_steps[run++] = r.stats.total_patches;
      }
      EXPECT_LT(patch_steps[1], patch_steps[0]);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// An absorbing glass sphere (r = 0.5, n = 1.5, σa = 1.5) under the sun straight down: the light
// inside is refracted, converging and absorbed at once, which is what the viewer's scattering
// reads. The bake's fluence rate (its `irradiance` field) against the tracer's, tallied on the
// bake's own voxels with their trilinear hats: both summed over blocks of voxels inside the glass,
// at two resolutions, and the absorbed flux against the tracer's.

struct SphereFluence {
  double worst = 0.0, mean = 0.0;  // relative deviation of the blocks
  int blocks = 0;
  double absorbed = 0.0, absorbed_exact = 0.0;  // W
};

// The tracer's fluence on a grid's voxels and its absorbed flux, traced once per grid.
const reference::ReceiverTally& exactAbsorbingSphere(const GridSpec& grid) {
  static std::vector<std::pair<GridSpec, std::unique_ptr<reference::ReceiverTally>>> traced;
  for (const auto& [g, tally] : traced)
    if (g == grid) return *tally;
  reference::DirectionalBeam beam;
  beam.beam_center = {0.0, 1.0, 0.0};
  beam.beam_radius = 0.6;  // covers the sphere; the rest of the beam passes by
  reference::Receiver floor;
  floor.point = {0.0, -5.0, 0.0};
  reference::TraceOptions trace;
  trace.rays = 800'000;  // a block of 4³ voxels at 48³ is crossed by ~7 000 of them
  trace.fluence.lo = grid.bounds_min;
  trace.fluence.hi = grid.bounds_max;
  trace.fluence.dims = grid.dims;
  trace.fluence.hat = true;  // the window of the bake's voxels
  trace.fluence.solids_only = true;  // the blocks are inside the glass, beyond the hats of the air
  reference::Solid sphere = reference::Solid::sphere({0.0, 0.0, 0.0}, 0.5, 1.5);
  sphere.sigma_a = 1.5;
  traced.emplace_back(grid, std::make_unique<reference::ReceiverTally>(reference::trace({sphere}, beam, floor, trace)));
  return *traced.back().second;
}

SphereFluence absorbingSphereFluence(int res, int block, bool straight) {
  const double radius = 0.5;
  const Volume volume = sharpVolume("procedural:sphere,r=0.5,ior=1.5,sigma_a=1.5:1.5:1.5", res, cube(0.6));
  const GridSpec& grid = volume.grid;
  CpuSimulator sim(volume);
  LightSpec light;
  light.direction = {0.0, -1.0, 0.0};
  light.power = {1.0, 1.0, 1.0};
  SimulationOptions options;
  options.free_flight = true;
  if (straight) options.straight_step_voxels = 2.0;
  const BakeResult bake = sim.run(light, options);

  const reference::ReceiverTally& exact = exactAbsorbingSphere(grid);

  SphereFluence out;
  const glm::dvec3 h = grid.voxelSize();
  double sum = 0.0;
  for (int k0 = 0; k0 + block <= grid.dims.z; k0 += block)
    for (int j0 = 0; j0 + block <= grid.dims.y; j0 += block)
      for (int i0 = 0; i0 + block <= grid.dims.x; i0 += block) {
        double baked = 0.0, traced = 0.0;
        bool inside = true;
        for (int k = k0; k < k0 + block; ++k)
          for (int j = j0; j < j0 + block; ++j)
            for (int i = i0; i < i0 + block; ++i) {
              // Every voxel's hat (a voxel around its centre) inside the glass, half a voxel to spare.
              inside &= glm::length(grid.center(i, j, k)) < radius - 1.5 * h.x;
              const std::size_t v = grid.index(i, j, k);
              baked += bake.irradiance.data[3 * v];
              traced += exact.fluence[v];
            }
        if (!inside) continue;
        const double deviation = std::fabs(baked / traced - 1.0);
        out.worst = std::max(out.worst, deviation);
        sum += deviation;
        ++out.blocks;
      }
  out.mean = out.blocks ? sum / out.blocks : 0.0;
  out.absorbed = bake.stats.flux_absorbed.x;
  out.absorbed_exact = exact.flux_absorbed;
  return out;
}

// Measured (800 k rays): steps of Δt, mean block deviation 1.4 % at 32³ and 1.1 % at 48³, the
// absorbed flux −1.1 % and −0.6 % (converging); straight steps at 48³ 1.3 % and −0.7 %. The worst
// blocks, 5–7 % short with steps of Δt and 12 % with straight steps, are the lower outer glass that
// only rays entering near the silhouette reach: patches there are torn across the surface and
// killed at the depth limit (0.3 % of the flux in, `flux_killed`; a depth of 9 instead of 6 takes
// the worst block from 10 to 6 %). Tolerances sit above these by the tracer's noise in those dim
// blocks (±1.5 % between 0.4 M and 2 M rays). A wrong decay, deposit or refraction is off
// everywhere, by 7–10 % in the mean (the staircase this bake had before its track decay), and the
// reflected wavefront's corners lost behind a thin rim (interface_crossing.cpp reflectedPatch, before
// it searched back in pieces) read 2.1 % in the mean and 19 % in the worst block with straight steps.
TEST(ExactOpticsSphere, VolumeIrradianceInAnAbsorbingSphereMatchesTheTracer) {
  const SphereFluence coarse = absorbingSphereFluence(32, 3, false);
  const SphereFluence fine = absorbingSphereFluence(48, 4, false);
  const SphereFluence straight = absorbingSphereFluence(48, 4, true);
  for (const SphereFluence* f : {&coarse, &fine, &straight})
    std::printf("absorbing sphere: %d blocks, worst %.2f %%, mean %.2f %%; absorbed %.5f W of %.5f W\n", f->blocks,
                100 * f->worst, 100 * f->mean, f->absorbed, f->absorbed_exact);
  EXPECT_GT(coarse.blocks, 100);
  EXPECT_GT(fine.blocks, 200);
  EXPECT_LT(coarse.mean, 0.02);
  EXPECT_LT(fine.mean, coarse.mean);  // converging
  EXPECT_LT(straight.mean, 0.018);
  EXPECT_LT(coarse.worst, 0.09);
  EXPECT_LT(fine.worst, 0.09);
  EXPECT_LT(straight.worst, 0.15);
  const double coarse_absorbed = coarse.absorbed / coarse.absorbed_exact - 1.0;
  const double fine_absorbed = fine.absorbed / fine.absorbed_exact - 1.0;
  EXPECT_LT(std::fabs(coarse_absorbed), 0.02);
  EXPECT_LT(std::fabs(fine_absorbed), std::fabs(coarse_absorbed));  // converging
  EXPECT_LT(std::fabs(straight.absorbed / straight.absorbed_exact - 1.0), 0.01);
}

// ---------------------------------------------------------------------------------------------
// A prism, n = 1.5, apex 60°, lit at minimum deviation: behind it the light travels deviated by
// D = 2·asin(n·sin(A/2)) − A = 37.18°.

TEST(ExactOpticsPrism, BakedLightDirectionShowsTheMinimumDeviation) {
  const double n = 1.5, apex = std::numbers::pi / 3.0;
  const double deviation = 2.0 * std::asin(n * std::sin(apex / 2.0)) - apex;
  // procedural:prism: a corner towards −z, face normals (sin a, 0, cos a) for a = 0°, 120°, 240°
  // (the face at a = 0 facing +z, the base). The symmetric path enters the face of a = 240° and
  // leaves by the face of a = 120°, running along +x inside, A/2 = 30° from the entry face's
  // inward normal (at 30° from +x in the xz plane): the light arrives at 30° − θi and leaves at
  // 30° − θi + D (angles from +x towards +z), θi = (A + D)/2.
  // A black opaque wall over the base keeps the wide beam off it: a third beam, through the base
  // and out of the exit face, would share the exit face's light.
  const Bounds b = box({-0.8, -0.2, -0.8}, {0.8, 0.2, 0.8});
  const Volume volume = sharpVolume(std::vector<std::string>{"procedural:prism,side=0.6,height=2,ior=1.5",
                                     "procedural:box,size=0.64:2:0.04,center=0:0:0.19,albedo=0.05:0.05:0.05,name=wall"},
                                    64, b);
  CpuSimulator sim(volume);
  const double theta_i = (apex + deviation) / 2.0;
  const double in_angle = std::numbers::pi / 6.0 - theta_i, out_angle = in_angle + deviation;
  LightSpec light;
  light.direction = glm::dvec3(std::cos(in_angle), 0.0, std::sin(in_angle));
  const BakeResult r = sim.run(light, SimulationOptions{});
  const glm::dvec3 expected(std::cos(out_angle), 0.0, std::sin(out_angle));
  // In front of the exit face (normal n, midpoint at the inradius; t along n, s along the face
  // towards the base, s = ±0.3 at its ends): the beam through the entry face goes out at +18.6°
  // (s = s₀ + 1.14 t), the direct light passes the base's corner (s > 0.3 + 0.3 t), and the rays
  // that met the apex within a quarter voxel — where the voxelised distance rounds the edge — fan
  // out at 20–46° from s₀ = −0.3 (s ≤ −0.3 + 4 t; measured: 1 % of the beam). Only the main beam
  // reaches t ∈ [0.06, 0.1], s ∈ [0.15, 0.28]: average the baked direction there, weighted by E.
  const GridSpec& g = volume.grid;
  const glm::dvec3 exit_normal(std::sin(glm::radians(120.0)), 0.0, std::cos(glm::radians(120.0)));
  const glm::dvec3 along(-exit_normal.z, 0.0, exit_normal.x);
  const double inradius = 0.6 / (2.0 * std::sqrt(3.0));
  glm::dvec3 sum(0.0);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = g.dims.y / 2 - 2; j <= g.dims.y / 2 + 2; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::dvec3 c = g.center(i, j, k);
        const double t = glm::dot(c, exit_normal) - inradius, s_along = glm::dot(c - inradius * exit_normal, along);
        if (t < 0.06 || t > 0.1 || s_along < 0.15 || s_along > 0.28) continue;
        const float* e = r.irradiance.voxel(g.index(i, j, k));
        const float* dir = r.light_dir.voxel(g.index(i, j, k));
        sum += static_cast<double>(e[0]) * glm::dvec3(dir[0], dir[1], dir[2]);
      }
  const glm::dvec3 mean = glm::normalize(sum);
  const double error_deg = glm::degrees(std::acos(std::min(1.0, glm::dot(mean, expected))));
  std::printf("prism: baked light direction behind it (%.4f, %.4f, %.4f), minimum deviation %.3f°: %.3f° off\n",
              mean.x, mean.y, mean.z, glm::degrees(deviation), error_deg);
  EXPECT_LT(error_deg, 0.1);  // the issue's bound
}

// The same prism lit straight onto its base (light along −z, normal to the face of a = 0): inside,
// each half of the beam meets a side face at 60°, past the critical angle (41.8°), and is totally
// reflected onto the other side face, which it leaves along that face's normal. Behind the exit
// face's lower half the light must travel along the face normal with E = (1 − R₀)²·E₀, R₀ =
// ((n − 1)/(n + 1))² (normal incidence twice; total reflection loses nothing, and keeps the beam's
// width). A wavefront meets the reflecting face corner by corner over several steps: the corners
// already reflected must not make it look torn (it was, and 16 % of the light entering the prism
// died at the split depth).
struct TirPrismProbe {
  double e_error = 0.0, direction_error_deg = 0.0, killed = 0.0;
  std::uint64_t patch_steps = 0;
};
TirPrismProbe bakeTirPrism(int res, Backend backend) {
  const double n = 1.5, r0 = (n - 1.0) * (n - 1.0) / ((n + 1.0) * (n + 1.0));
  const double expected_e = (1.0 - r0) * (1.0 - r0);
  const double side = 0.7;
  // Exit face a = 240° (normal (−sin 60°, 0, −½)): from its midpoint (u = ½, where the ray that met
  // the reflecting face at the base's corner leaves) to the apex (u = 1).
  const glm::dvec3 exit_normal(std::sin(glm::radians(240.0)), 0.0, std::cos(glm::radians(240.0)));
  const double circumradius = side / std::sqrt(3.0);
  const glm::dvec3 base_corner(-side / 2.0, 0.0, circumradius / 2.0), apex(0.0, 0.0, -circumradius);
  // The prism taller than the box: no caps inside it.
  const Volume volume = sharpVolume("procedural:prism,side=0.7,height=2,ior=1.5", res,
                                    box({-0.5, -0.2, -0.6}, {0.5, 0.2, 0.4}));
  const std::unique_ptr<Simulator> sim = simulatorFor(volume, backend);
  LightSpec light;
  light.direction = glm::dvec3(0.0, 0.0, -1.0);
  const BakeResult r = sim->run(light, SimulationOptions{});
  // Probe points in the shadow of the base, in the exit beam only: u ∈ [0.7, 0.85] along the exit
  // face, 1.5–4 voxels out along its normal. The beam's edges are left out: at u = ½ and 1 its rays
  // met the prism's edges, which the voxelised distances round within a voxel or so, and fan out
  // from there (at 48³ they add 25 % at u = 0.6 and 15 % at u = 0.65).
  const GridSpec& g = volume.grid;
  const double h = voxelEdge(g);
  glm::dvec3 dir_sum(0.0);
  double e_sum = 0.0;
  int count = 0;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = g.dims.y / 2 - 2; j <= g.dims.y / 2 + 2; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::dvec3 c = g.center(i, j, k);
        const double t = glm::dot(c - apex, exit_normal);
        const glm::dvec3 on_face = c - t * exit_normal;
        const double u = glm::dot(on_face - base_corner, apex - base_corner) / (side * side);
        if (t < 1.5 * h || t > 4.0 * h || u < 0.7 || u > 0.85) continue;
        const float* e = r.irradiance.voxel(g.index(i, j, k));
        const float* d = r.light_dir.voxel(g.index(i, j, k));
        e_sum += e[0];
        dir_sum += static_cast<double>(e[0]) * glm::dvec3(d[0], d[1], d[2]);
        ++count;
      }
  EXPECT_GT(count, 10) << res;
  TirPrismProbe probe;
  const double mean_e = count > 0 ? e_sum / count : 0.0;
  probe.e_error = mean_e / expected_e - 1.0;
  probe.direction_error_deg = glm::degrees(std::acos(std::min(1.0, glm::dot(glm::normalize(dir_sum), exit_normal))));
  // The light that met the prism: its base's width times the box's height, E₀ = 1.
  const double into_prism = side * 0.4;
  probe.killed = r.stats.flux_killed.x / into_prism;
  probe.patch_steps = r.stats.total_patches;
  std::printf("%d³, %s: prism with total internal reflection: E behind the exit face %.4f (exact %.4f, %+.2f %%), "
              "direction %.3f° off its normal; killed %.2f %% of the light into the prism; %llu patch-steps\n",
              res, r.stats.backend.c_str(), mean_e, expected_e, 100.0 * probe.e_error, probe.direction_error_deg,
              100.0 * probe.killed, static_cast<unsigned long long>(r.stats.total_patches));
  EXPECT_LT(r.stats.ledgerResidual(), backend == Backend::Cpu ? 1e-9 : 1e-5);
  // What dies: the patches torn at the base's two edges, where the beam grazes the prism (a
  // sixteenth of a voxel each side at the depth limit), and at the apex. Measured 0.2 % (32³)
  // and 0.06 % (48³); before the corners already reflected counted as met, 12 % and 16 %.
  EXPECT_LT(probe.killed, 0.01) << res;
  return probe;
}

TEST(ExactOpticsPrism, TotalInternalReflectionKeepsTheWavefrontWhole) {
  const TirPrismProbe coarse = bakeTirPrism(32, Backend::Cpu), fine = bakeTirPrism(48, Backend::Cpu);
  // The exit beam: at 48³ within 4 % of (1 − R₀)² and 1° of the face normal (measured +2.7 %,
  // 0.57°: light the rounded edges fan out still reaches into the probe), closer than at 32³
  // (+14.9 %, 2.3°): the discretisation converges. A beam that lost its torn patches, or that the
  // reflection widened or narrowed, would be off by far more (it was −47 % and 12° off, in 55 M
  // patch-steps instead of 1.7 M); one that left by the wrong face, or unrefracted, by tens of
  // degrees.
  EXPECT_LT(std::abs(fine.e_error), 0.04);
  EXPECT_LT(std::abs(fine.e_error), std::abs(coarse.e_error));
  EXPECT_LT(fine.direction_error_deg, 1.0);
  EXPECT_LT(fine.direction_error_deg, coarse.direction_error_deg);
}

// The GPU path keeps the reflected corners the same way (update.frag, the patch's META): the same
// exit beam as the twin's within 1 % (GL against the CPU twin) at 24³.
TEST(ExactOpticsPrism, TheGpuPathKeepsTotallyReflectedWavefrontsWhole) {
  const TirPrismProbe cpu = bakeTirPrism(24, Backend::Cpu), gpu = bakeTirPrism(24, Backend::Gl);
  EXPECT_NEAR((1.0 + gpu.e_error) / (1.0 + cpu.e_error), 1.0, 0.01);
  EXPECT_NEAR(gpu.direction_error_deg, cpu.direction_error_deg, 0.2);
  EXPECT_NEAR(static_cast<double>(gpu.patch_steps), static_cast<double>(cpu.patch_steps),
              0.01 * test_scenes::gpuArithmeticSlack() * static_cast<double>(cpu.patch_steps));
}

// ---------------------------------------------------------------------------------------------
// The Luneburg lens, n(r) = sqrt(2 − (r/R)²), graded with no jump at its surface: with sharp
// interfaces it is one graded material, and a plane wave still focuses on the far surface.

TEST(ExactOpticsLuneburg, GradedLensFocusesOnTheFarSurfaceWithinHalfAVoxel) {
  const double h = 1.0 / 30.0, R = 0.5;
  const Bounds b = box({-18.5 * h, -0.6 - 18.5 * h, -18.5 * h}, {18.5 * h, 0.6 - 0.5 * h, 18.5 * h});
  const Volume v = sharpVolume("procedural:luneburg,r=0.5", 54, b);
  ASSERT_EQ(v.grid.dims, glm::ivec3(37, 54, 37));
  CpuSimulator sim(v);
  const BakeResult r = sim.run(LightSpec{}, SimulationOptions{});
  const GridSpec& g = v.grid;
  int best = -1;
  double best_e = -1.0;
  for (int j = 0; j < g.dims.y && g.center(0, j, 0).y < 0.0; ++j) {
    const double e = r.irradiance.voxel(g.index(g.dims.x / 2, j, g.dims.z / 2))[0];
    if (e > best_e) best_e = e, best = j;
  }
  const double y_max = g.center(0, best, 0).y;
  std::printf("Luneburg (sharp): on-axis maximum at %.4f, focus at %.4f: %.2f voxels off\n", y_max, -R, (y_max + R) / h);
  EXPECT_LT(std::abs(y_max + R), 0.5 * h);  // the grid puts a voxel centre on the focus
}

// A thin glass wall (1.9 voxels at 24³) over a thick slab that reaches below the grid, light tilted
// 35° from the vertical, one bounce followed. Looked at in pieces (findInterfaceOnChord), long
// chords meet the wall: willTear's look ahead of 4 patch sizes for the corners that have not met
// it yet, and with straight steps a reflected wavefront's steps of 8 voxels and their merges.
// With the look ahead asked at its end only, every patch that reached the wall tore, split to the
// depth limit and died (1 % of the light killed; with steps of Δt 100 times the patch-steps).
//  - Steps of Δt: what is not followed, hence in the ledger's `reflected`, is what the wall's top
//    face sends back down of the wall's internal reflection (Φ·T·R·R) and what its two faces send
//    back of the thick slab's reflection on its way up (Φ·T²·R·(1 − T²)), T = 1 − R at 35° (the
//    same R at θt inside).
//  - Straight steps (the command's default), with and without flights and merged steps: the GPU
//    path (sharp.glsl, flight.glsl, update.frag) as the twin, within 1 %; a GPU path whose 8-voxel
//    steps step over the wall keeps 15–35 % less of it in `reflected`.
TEST(ExactOpticsSlab, AThinWallIsMetByLongChordsOnBothBackEnds) {
  const double theta_i = 35.0 * std::numbers::pi / 180.0;
  const double R = reference::fresnelReflectance(1.0, 1.5, std::cos(theta_i)), T = 1.0 - R;
  // At two resolutions, the wall 1.92 voxels thick at each: no light killed (1 % of it when every
  // patch that reached the wall tore), the ledger balanced and GL equal to the twin at both.
  double deviation[2] = {0.0, 0.0};
  for (const int res : {24, 36}) {
    SCOPED_TRACE(res);
    char wall[96];
    std::snprintf(wall, sizeof wall, "procedural:box,size=4:%.6f:4,center=0:0.14:0,ior=1.5", 1.92 / res);
    const Volume volume = sharpVolume(std::vector<std::string>{wall, "procedural:box,size=4:0.8:4,center=0:-0.6:0,ior=1.5"},
                                      res, box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}));
    struct Config {
      const char* name;
      double straight_step;
      bool flights;
    };
    for (const Config& config : {Config{"steps of Δt", 0.0, true}, Config{"straight steps", 2.0, true},
                                 Config{"straight steps, no flights", 2.0, false}}) {
      SCOPED_TRACE(config.name);
      SimulationOptions options;
      options.bounces = 1;
      options.free_flight = config.flights;
      options.volume_deposits = false;
      options.straight_step_voxels = config.straight_step;
      double reflected[2] = {0.0, 0.0}, out[2] = {0.0, 0.0};
      for (const Backend backend : {Backend::Cpu, Backend::Gl}) {
        const std::unique_ptr<Simulator> sim = simulatorFor(volume, backend);
        const BakeResult r = sim->run(tiltedLight(theta_i), options);
        const int b = backend == Backend::Cpu ? 0 : 1;
        const double in = luminance(r.stats.flux_in);
        reflected[b] = luminance(r.stats.flux_reflected);
        out[b] = luminance(r.stats.flux_out);
        const double expected = in * R * (T * R + T * T * (1.0 - T * T));
        std::printf("thin wall over a slab, %s, %s: reflected (not followed) %.6f (Δt steps: expected %.6f, %+.1f %%); "
                    "killed %.2e of %.4f in; %llu patch-steps\n",
                    r.stats.backend.c_str(), config.name, reflected[b], expected, 100.0 * (reflected[b] / expected - 1.0),
                    luminance(r.stats.flux_killed), in, static_cast<unsigned long long>(r.stats.total_patches));
        // The ledger's unfollowed reflections against Fresnel's share are printed, not asserted:
        // +3.8 % at 24³ but −12.8 % at 36³ with steps of Δt, so the ledger's share does not converge
        // to Fresnel's. It also holds reflections left unfollowed for other reasons (a reflected
        // wavefront's own, those traced back to no interface near the grid's sides), which the two
        // lattices meet differently; a test that tells them apart is left to do (BENCHMARKS.md).
        if (config.straight_step == 0.0 && b == 0) deviation[res == 24 ? 0 : 1] = reflected[b] / expected - 1.0;
        EXPECT_LT(luminance(r.stats.flux_killed), 1e-4 * in);  // 1 % with the tears
        EXPECT_LT(r.stats.ledgerResidual(), 1e-6);
      }
      // The GPU path's float arithmetic against the twin's double: 1 % (the issue's bound for GL
      // against the twin).
      EXPECT_NEAR(reflected[1] / reflected[0], 1.0, 0.01);
      EXPECT_NEAR(out[1] / out[0], 1.0, 0.01);
    }
  }
  std::printf("thin wall: reflected with steps of Δt against Fresnel's %+.2f %% (24³), %+.2f %% (36³)\n",
              100.0 * deviation[0], 100.0 * deviation[1]);
}

}  // namespace
}  // namespace eik
