// The voxelize pipeline end to end (procedural shape → composite → smoothed n → ∇n) against
// analytic answers. All tests assume the default pre-smoothing σ = 0.75 voxel unless they say
// otherwise (docs/physics.md: tests state the σ they assume).
#include "voxelize/pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/testing.h"
#include "core/volume.h"
#include "voxelize/grid_builder.h"
#include "voxelize/procedural.h"

namespace eik {
namespace {

constexpr double kSigma = 0.75;

// Trilinear interpolation of a 3-component field at a world point (voxel centres are samples).
glm::dvec3 sampleVector(const Field& f, const GridSpec& g, const glm::dvec3& p) {
  const glm::dvec3 v = g.toVoxel(p) - 0.5;
  const glm::ivec3 i0 = glm::ivec3(glm::floor(v));
  const glm::dvec3 t = v - glm::dvec3(i0);
  glm::dvec3 out(0.0);
  for (int c = 0; c < 8; ++c) {
    const glm::ivec3 o(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    const glm::ivec3 i = glm::clamp(i0 + o, glm::ivec3(0), g.dims - 1);
    const double w = (o.x ? t.x : 1 - t.x) * (o.y ? t.y : 1 - t.y) * (o.z ? t.z : 1 - t.z);
    const float* q = f.voxel(g.index(i.x, i.y, i.z));
    out += w * glm::dvec3(q[0], q[1], q[2]);
  }
  return out;
}

// Directions spread evenly over the sphere (Fibonacci lattice).
std::vector<glm::dvec3> directions(int n) {
  std::vector<glm::dvec3> out;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / n;
    const double r = std::sqrt(1.0 - y * y);
    out.emplace_back(r * std::cos(golden * i), y, r * std::sin(golden * i));
  }
  return out;
}

struct SphereCase {
  double R = 0.5;
  GridSpec grid;
  Volume volume;
};

// The thesis' smoothed mode, which most of these tests are about (sharp interfaces:
// sharp_interfaces_test.cpp).
PipelineOptions smoothed() {
  PipelineOptions options;
  options.interfaces = InterfaceMode::Smooth;
  return options;
}

// A glass sphere (n = 1.5) of radius 0.5 on a 128³ grid: 122 voxels across plus 3 of air per side.
SphereCase sphere(GradientOperator op = GradientOperator::Isotropic) {
  SphereCase s;
  const ProceduralSpec spec = parseProceduralSpec("procedural:sphere,r=0.5,ior=1.5");
  s.grid = makeGrid(proceduralBounds(spec), 122, 3.0);
  PipelineOptions options = smoothed();
  options.smooth_sigma_voxels = kSigma;
  options.gradient = op;
  s.volume = buildVolume(voxelizeProcedural(spec, s.grid), s.grid, options);
  return s;
}

double maxMagnitude(const Field& f) {
  double m = 0.0;
  for (std::size_t v = 0; v < f.data.size() / 3; ++v) {
    const float* q = f.voxel(v);
    m = std::max(m, std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2]));
  }
  return m;
}

// Largest angle (degrees) between ∇n and the inward radial direction over the voxels within half a
// voxel of the surface whose |∇n| is at least 90 % of the peak; `count` gets how many there are and
// `band` how many voxels the half-voxel shell holds.
double worstAngle(const SphereCase& s, int& count, int& band) {
  const Field& grad = s.volume.fields.at("ior_grad");
  const double peak = maxMagnitude(grad);
  const double h = s.grid.voxelSize().x;
  double worst = 0.0;
  count = band = 0;
  for (int k = 0; k < s.grid.dims.z; ++k)
    for (int j = 0; j < s.grid.dims.y; ++j)
      for (int i = 0; i < s.grid.dims.x; ++i) {
        const glm::dvec3 c = s.grid.center(i, j, k);
        const double r = glm::length(c);
        if (std::abs(r - s.R) > 0.5 * h) continue;
        ++band;
        const float* q = grad.voxel(s.grid.index(i, j, k));
        const glm::dvec3 g(q[0], q[1], q[2]);
        if (glm::length(g) < 0.9 * peak) continue;
        ++count;
        const double cosine = glm::dot(glm::normalize(g), -c / r);  // n falls outwards: ∇n points in
        worst = std::max(worst, std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi);
      }
  return worst;
}

TEST(Pipeline, SphereGridIs128Cubed) {
  const SphereCase s = sphere();
  EXPECT_EQ(s.grid.dims, glm::ivec3(128));
  EXPECT_TRUE(s.volume.has("ior"));
  EXPECT_TRUE(s.volume.has("ior_grad"));
  EXPECT_EQ(s.volume.fields.at("ior_grad").components, 3);
  EXPECT_FALSE(s.volume.has("sigma_a")) << "clear glass needs no σa field";
  EXPECT_EQ(s.volume.metadata.at("ior_smoothing_sigma_voxels").get<double>(), kSigma);
  EXPECT_EQ(s.volume.metadata.at("ior_gradient").get<std::string>(), "isotropic");
}

TEST(Pipeline, SphereOccupiedVolume) {
  const SphereCase s = sphere();
  const double exact = 4.0 / 3.0 * std::numbers::pi * s.R * s.R * s.R;
  // Smoothing preserves Σ(n − 1) (the sphere is far from the borders), so the occupied volume
  // Σ coverage·V_voxel can be read off the smoothed n: coverage = (n − 1)/(1.5 − 1).
  double sum = 0.0;
  for (float n : s.volume.fields.at("ior").data) sum += (n - 1.0) / 0.5;
  EXPECT_NEAR(sum * s.grid.voxelVolume(), exact, 0.005 * exact);
  EXPECT_NEAR(sum * s.grid.voxelVolume(), exact, 0.0005 * exact) << "in fact 10x closer";
  const double composited = s.volume.metadata.at("materials")[0].at("volume").get<double>();
  EXPECT_NEAR(composited, exact, 0.0005 * exact);
}

TEST(Pipeline, SphereIndexInsideAndOutside) {
  const SphereCase s = sphere();
  const Field& n = s.volume.fields.at("ior");
  const double h = s.grid.voxelSize().x;
  const double margin = (3.0 * kSigma + 1.0) * h;
  int inside = 0, outside = 0;
  for (int k = 0; k < s.grid.dims.z; ++k)
    for (int j = 0; j < s.grid.dims.y; ++j)
      for (int i = 0; i < s.grid.dims.x; ++i) {
        const double r = glm::length(s.grid.center(i, j, k));
        const float value = n.data[s.grid.index(i, j, k)];
        if (r < s.R - margin) {
          ASSERT_NEAR(value, 1.5f, 1e-3f) << i << "," << j << "," << k;
          ++inside;
        } else if (r > s.R + margin) {
          ASSERT_NEAR(value, 1.0f, 1e-3f) << i << "," << j << "," << k;
          ++outside;
        }
        ASSERT_GE(value, 1.0f - 1e-6f);
        ASSERT_LE(value, 1.5f + 1e-6f);
      }
  EXPECT_GT(inside, 800000);
  EXPECT_GT(outside, 800000);
}

TEST(Pipeline, SphereGradientPeaksAtTheSurface) {
  const SphereCase s = sphere();
  const Field& grad = s.volume.fields.at("ior_grad");
  const double h = s.grid.voxelSize().x;
  for (const glm::dvec3& d : directions(300)) {
    double best = -1.0, best_r = 0.0;
    for (double r = s.R - 5.0 * h; r <= s.R + 5.0 * h; r += 0.02 * h) {
      const double m = glm::length(sampleVector(grad, s.grid, r * d));
      if (m > best) {
        best = m;
        best_r = r;
      }
    }
    ASSERT_LE(std::abs(best_r - s.R), h) << "direction " << d.x << "," << d.y << "," << d.z;
    // Magnitude sanity: a step of 0.5 smoothed by σ peaks near 0.5/(σ_eff·√(2π)) per voxel.
    ASSERT_GT(best * h, 0.12);
    ASSERT_LT(best * h, 0.3);
  }
}

TEST(Pipeline, SphereGradientIsRadial) {
  const SphereCase s = sphere();
  int count = 0, band = 0;
  const double worst = worstAngle(s, count, band);
  EXPECT_LT(worst, 2.0);
  EXPECT_GT(count, 0.8 * band) << "most of the surface shell is near the peak";
}

// Why the pipeline does not use Eq. 3.1 as printed: on the same sphere its directions are off by
// more than twice as much (measured ~5.5° against ~1.6°).
TEST(Pipeline, PlainCentralDifferencesAreLessIsotropic) {
  int count = 0, band = 0;
  const double iso = worstAngle(sphere(GradientOperator::Isotropic), count, band);
  const double plain = worstAngle(sphere(GradientOperator::CentralDifference), count, band);
  EXPECT_GT(plain, 2.0 * iso);
  EXPECT_LT(plain, 8.0);
}

TEST(Pipeline, LuneburgIndexAndGradientFollowTheFormula) {
  const ProceduralSpec spec = parseProceduralSpec("procedural:luneburg,r=0.5");
  const GridSpec grid = makeGrid(proceduralBounds(spec), 90, 3.0);
  const Volume v = buildVolume(voxelizeProcedural(spec, grid), grid, smoothed());
  const Field& n = v.fields.at("ior");
  const Field& grad = v.fields.at("ior_grad");
  const double R = 0.5, h = grid.voxelSize().x;
  const double margin = (3.0 * kSigma + 1.0) * h;
  int checked = 0;
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const glm::dvec3 p = grid.center(i, j, k);
        const double r = glm::length(p);
        if (r > R - margin) continue;
        const double expected = std::sqrt(2.0 - (r / R) * (r / R));
        const std::size_t at = grid.index(i, j, k);
        ASSERT_NEAR(n.data[at], expected, 1e-3) << "r = " << r;
        // ∇n = −p / (R² n)
        const glm::dvec3 g_expected = -p / (R * R * expected);
        const float* g = grad.voxel(at);
        ASSERT_LT(glm::length(glm::dvec3(g[0], g[1], g[2]) - g_expected), 0.01) << "r = " << r;
        ++checked;
      }
  EXPECT_GT(checked, 200000);
  // The centre and sample radii along the axes (interpolated).
  for (double f : {0.0, 0.25, 0.5, 0.75}) {
    for (const glm::dvec3& d : {glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1)}) {
      const glm::dvec3 p = f * R * d;
      const glm::dvec3 vox = grid.toVoxel(p) - 0.5;
      const glm::ivec3 i0 = glm::ivec3(glm::floor(vox));
      const glm::dvec3 t = vox - glm::dvec3(i0);
      double value = 0.0;
      for (int c = 0; c < 8; ++c) {
        const glm::ivec3 o(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        const double w = (o.x ? t.x : 1 - t.x) * (o.y ? t.y : 1 - t.y) * (o.z ? t.z : 1 - t.z);
        value += w * n.data[grid.index(i0.x + o.x, i0.y + o.y, i0.z + o.z)];
      }
      EXPECT_NEAR(value, std::sqrt(2.0 - f * f), 1e-3) << "r/R = " << f;
    }
  }
}

TEST(Pipeline, GradientSlabIsLinearWithConstantGradient) {
  const ProceduralSpec spec = parseProceduralSpec("procedural:gradient_slab,size=1:0.5:0.5,n0=1.2,n1=1.8,axis=x");
  const GridSpec grid = makeGrid(proceduralBounds(spec), 80, 3.0);
  const Volume v = buildVolume(voxelizeProcedural(spec, grid), grid, smoothed());
  const Field& n = v.fields.at("ior");
  const Field& grad = v.fields.at("ior_grad");
  const double h = grid.voxelSize().x;
  const double margin = (3.0 * kSigma + 1.0) * h;
  int checked = 0;
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const glm::dvec3 p = grid.center(i, j, k);
        if (std::abs(p.x) > 0.5 - margin || std::abs(p.y) > 0.25 - margin || std::abs(p.z) > 0.25 - margin) continue;
        const std::size_t at = grid.index(i, j, k);
        ASSERT_NEAR(n.data[at], 1.2 + 0.6 * (p.x + 0.5), 1e-4);
        // ∇n reads n one voxel further out.
        if (std::abs(p.x) > 0.5 - margin - h || std::abs(p.y) > 0.25 - margin - h || std::abs(p.z) > 0.25 - margin - h)
          continue;
        const float* g = grad.voxel(at);
        ASSERT_NEAR(g[0], 0.6, 1e-3);
        ASSERT_NEAR(g[1], 0.0, 1e-3);
        ASSERT_NEAR(g[2], 0.0, 1e-3);
        ++checked;
      }
  EXPECT_GT(checked, 50000);
}

TEST(Pipeline, NoSmoothingKeepsTheRawComposite) {
  const ProceduralSpec spec = parseProceduralSpec("procedural:sphere,r=0.4,sigma_a=1:2:3");
  const GridSpec grid = makeGrid(proceduralBounds(spec), 24, 2.0);
  const auto regions = voxelizeProcedural(spec, grid);
  PipelineOptions options = smoothed();
  options.smooth_sigma_voxels = 0.0;
  const Volume v = buildVolume(regions, grid, options);
  for (std::size_t i = 0; i < grid.count(); ++i)
    ASSERT_FLOAT_EQ(v.fields.at("ior").data[i], 1.0f + 0.5f * regions[0].coverage[i]);
  // σa is never smoothed (only n is, as in the thesis).
  PipelineOptions smooth = smoothed();
  const Volume s = buildVolume(regions, grid, smooth);
  EXPECT_EQ(s.fields.at("sigma_a").data, v.fields.at("sigma_a").data);
  EXPECT_NE(s.fields.at("ior").data, v.fields.at("ior").data);
}

// The Cauchy B is smoothed with n, so in one material B/(n − 1) is the material's ratio in every
// voxel of the boundary layer, as the viewer's ∇n(λ) = ∇n·(1 + c·B/(n − 1)) assumes. Left sharp,
// the outer half of the layer would have B = 0 and the inner half too much.
TEST(Pipeline, DispersionIsSmoothedWithTheIndex) {
  const ProceduralSpec spec = parseProceduralSpec("procedural:sphere,r=0.4,ior=1.75,abbe=20");
  const GridSpec grid = makeGrid(proceduralBounds(spec), 32, 3.0);
  const Volume v = buildVolume(voxelizeProcedural(spec, grid), grid, smoothed());
  const Field& n = v.fields.at("ior");
  const Field& b = v.fields.at("dispersion");
  const double ratio = 0.523655 / 20.0;  // B = 0.523655·(n_d − 1)/V_d
  int layer = 0;
  for (std::size_t i = 0; i < grid.count(); ++i) {
    if (n.data[i] - 1.0f < 1e-3f) {
      EXPECT_LE(b.data[i], 1.01e-3 * ratio);
      continue;
    }
    if (n.data[i] < 1.74f) ++layer;
    ASSERT_NEAR(b.data[i] / (n.data[i] - 1.0f), ratio, 1e-3 * ratio) << "voxel " << i;
  }
  EXPECT_GT(layer, 1000);  // the boundary layer was checked, not only the core
}

TEST(Pipeline, ReportsProgressUpToOne) {
  const ProceduralSpec spec = parseProceduralSpec("procedural:sphere");
  const GridSpec grid = makeGrid(proceduralBounds(spec), 16, 2.0);
  std::vector<double> seen;
  std::mutex m;
  PipelineOptions options = smoothed();
  options.progress = [&](double f) {
    std::lock_guard<std::mutex> lock(m);
    seen.push_back(f);
  };
  buildVolume(voxelizeProcedural(spec, grid), grid, options);
  ASSERT_FALSE(seen.empty());
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  for (double f : seen) {
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
  }
}

// The whole run as `voxelize` makes it: the same volume as the library steps, stats, and the
// option checks that come before any work (tests/voxelize_cli_test.cpp checks the program itself).
TEST(VoxelizeFiles, WritesTheVolumeTheStepsBuild) {
  test_support::TempDir dir;
  VoxelizeOptions options;
  options.inputs = {"procedural:sphere,r=0.5,ior=1.5"};
  options.output = (dir / "sphere.vol.json").string();
  options.stats = (dir / "stats.json").string();
  options.res = 12;
  options.quiet = true;
  voxelizeFiles(options);

  const ProceduralSpec spec = parseProceduralSpec(options.inputs[0]);
  const GridSpec grid = makeGrid(proceduralBounds(spec), 12);
  ProceduralOptions sharp;  // voxelize's default: sharp interfaces
  sharp.distance_band = interfaceBand(grid);
  const Volume expected = buildVolume(voxelizeProcedural(spec, grid, sharp), grid);
  const Volume written = readVolume(dir / "sphere.vol.json");
  EXPECT_EQ(written.grid.dims, grid.dims);
  ASSERT_EQ(written.fields.size(), expected.fields.size());
  for (const auto& [name, field] : expected.fields) EXPECT_EQ(written.fields.at(name).data, field.data) << name;
  EXPECT_EQ(written.metadata.at("source").at("program"), "voxelize");

  const nlohmann::json stats = nlohmann::json::parse(test_support::readFile(dir / "stats.json"));
  EXPECT_EQ(stats.at("voxels").get<std::size_t>(), grid.count());
  EXPECT_EQ(stats.at("objects").size(), 1u);
  EXPECT_EQ(stats.at("objects")[0].at("region"), "sphere");
  for (const char* key : {"time_occupancy_s", "time_fields_s", "time_write_s", "time_total_s", "peak_memory_mib"})
    EXPECT_TRUE(stats.contains(key)) << key;
}

// With sharp interfaces and clear glass, nothing but the reported volume reads a procedural shape's
// coverage (n comes from the distances): it is taken at the voxel centres, one sample a voxel, and
// the fields are those of the S³ sub-samples to the bit. An absorbing material blends σa by
// coverage, so it keeps the sub-samples. The distances (skipped along x where the Lipschitz bound
// clamps them) are the sphere's own at every voxel.
TEST(VoxelizeFiles, ASharpClearShapeTakesItsOccupancyAtTheVoxelCentres) {
  test_support::TempDir dir;
  auto run = [&](const std::string& input, const std::string& name) {
    VoxelizeOptions options;
    options.inputs = {input};
    options.output = (dir / (name + ".vol.json")).string();
    options.stats = (dir / (name + ".json")).string();
    options.res = 24;
    options.quiet = true;
    voxelizeFiles(options);
    return std::make_pair(readVolume(dir / (name + ".vol.json")),
                          nlohmann::json::parse(test_support::readFile(dir / (name + ".json"))));
  };
  auto build = [](const std::string& input, int supersample) {
    const ProceduralSpec spec = parseProceduralSpec(input);
    const GridSpec grid = makeGrid(proceduralBounds(spec), 24);
    ProceduralOptions options;
    options.supersample = supersample;
    options.distance_band = interfaceBand(grid);
    return buildVolume(voxelizeProcedural(spec, grid, options), grid);
  };

  const std::string clear = "procedural:sphere,r=0.5,ior=1.5";
  const auto [glass, glass_stats] = run(clear, "clear");
  EXPECT_EQ(glass_stats.at("procedural_supersample").get<int>(), 1);
  const Volume sub_sampled = build(clear, 4);
  ASSERT_EQ(glass.fields.size(), sub_sampled.fields.size());
  for (const auto& [name, field] : sub_sampled.fields) EXPECT_EQ(glass.fields.at(name).data, field.data) << name;
  // The volume from the centres' distances, clamp(1/2 − d/h, 0, 1) a voxel: +2.8e-3 of the exact
  // sphere's at 24 voxels across (the ramp overestimates a convex surface's, by O(h²); the S³
  // sub-samples' is +1.4e-4). Boundary voxels counted empty or full would be off by about 10 %.
  const double exact = 4.0 / 3.0 * std::numbers::pi * 0.125;
  EXPECT_NEAR(glass_stats.at("objects")[0].at("enclosed_volume").get<double>(), exact, 4e-3 * exact);
  const Field& distances = glass.fields.at("interfaces");
  const double band = interfaceBand(glass.grid);
  const glm::dvec3 centre = 0.5 * (glass.grid.bounds_min + glass.grid.bounds_max);
  std::size_t inside = 0;
  for (int k = 0; k < glass.grid.dims.z; ++k)
    for (int j = 0; j < glass.grid.dims.y; ++j)
      for (int i = 0; i < glass.grid.dims.x; ++i) {
        const double d = std::clamp(glm::length(glass.grid.center(i, j, k) - centre) - 0.5, -band, band);
        ASSERT_NEAR(distances.data[glass.grid.index(i, j, k)], d, 1e-6) << i << " " << j << " " << k;
        inside += d < 0.0;
      }
  EXPECT_GT(inside, 1000u);

  const std::string absorbing = "procedural:sphere,r=0.5,ior=1.5,sigma_a=2";
  const auto [amber, amber_stats] = run(absorbing, "absorbing");
  EXPECT_EQ(amber_stats.at("procedural_supersample").get<int>(), 4);
  EXPECT_EQ(amber.fields.at("sigma_a").data, build(absorbing, 4).fields.at("sigma_a").data);
  EXPECT_NE(amber.fields.at("sigma_a").data, build(absorbing, 1).fields.at("sigma_a").data);
}

TEST(VoxelizeFiles, ChecksTheOptionsBeforeAnyWork) {
  test_support::TempDir dir;
  auto errorOf = [](VoxelizeOptions options) {
    options.quiet = true;
    return test_support::inputErrorOf([&] { voxelizeFiles(options); });
  };
  VoxelizeOptions o;
  EXPECT_EQ(errorOf(o), "command line: INPUT: no input given (see voxelize --help)");
  o.inputs = {"procedural:sphere"};
  EXPECT_EQ(errorOf(o), "command line: -o: no output given (-o OUT.vol.json)");
  o.output = (dir / "sphere.nrrd").string();
  EXPECT_CONTAINS(errorOf(o), "the output manifest must end in .vol.json");
  o.output = (dir / "sphere.vol.json").string();
  o.smooth = 9;
  EXPECT_EQ(errorOf(o), "--smooth: must be in [0, 8] voxels");
  o.smooth = 0.75;
  o.stats = (dir / "missing" / "stats.json").string();
  EXPECT_CONTAINS(errorOf(o), "does not exist");
  o.stats.clear();
  o.materials = {"ior=1.5", "ior=1.6"};
  EXPECT_EQ(errorOf(o), "--material: given 2 times for 1 OBJ/procedural inputs (give it once, or once per such input)");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{}) << "nothing written";
}

}  // namespace
}  // namespace eik
