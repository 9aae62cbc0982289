#include "voxelize/procedural.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>

#include "core/error.h"
#include "voxelize/composite.h"

namespace eik {
namespace {

std::string inputErrorOf(const std::string& spec) {
  try {
    parseProceduralSpec(spec);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

double coverageSum(const Region& r) {
  double s = 0.0;
  for (float c : r.coverage) s += c;
  return s;
}

GridSpec cubeGrid(int n, double half) {
  GridSpec g;
  g.dims = glm::ivec3(n);
  g.bounds_min = glm::dvec3(-half);
  g.bounds_max = glm::dvec3(half);
  return g;
}

TEST(ProceduralSpec, Parses) {
  const ProceduralSpec s = parseProceduralSpec("procedural:sphere,r=0.25,sigma_a=1:2:3");
  EXPECT_EQ(s.name, "sphere");
  EXPECT_EQ(s.params.at("r"), "0.25");
  EXPECT_EQ(s.params.at("sigma_a"), "1:2:3");
  EXPECT_EQ(parseProceduralSpec("wine_glass").name, "wine_glass");  // the prefix is optional
  EXPECT_TRUE(isProceduralSpec("procedural:box"));
  EXPECT_FALSE(isProceduralSpec("box.obj"));
  EXPECT_EQ(s.text(), "procedural:sphere,r=0.25,sigma_a=1:2:3");
}

TEST(ProceduralSpec, Errors) {
  std::string e = inputErrorOf("procedural:teapot");
  EXPECT_NE(e.find("procedural:teapot: unknown shape 'teapot'"), std::string::npos) << e;
  EXPECT_NE(e.find("wine_glass"), std::string::npos) << "lists the shapes: " << e;

  e = inputErrorOf("procedural:sphere,radius=1");
  EXPECT_NE(e.find("procedural:sphere: radius: unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("valid keys: r, center, ior"), std::string::npos) << e;

  e = inputErrorOf("procedural:sphere,r=big");
  EXPECT_NE(e.find("r: 'big' is not a number"), std::string::npos) << e;
  e = inputErrorOf("procedural:sphere,r=-1");
  EXPECT_NE(e.find("r: -1 is out of range: must be > 0"), std::string::npos) << e;
  e = inputErrorOf("procedural:wine_glass,fill=1.5");
  EXPECT_NE(e.find("fill: 1.5 is out of range: must lie in [0, 1]"), std::string::npos) << e;
  e = inputErrorOf("procedural:gradient_slab,axis=w");
  EXPECT_NE(e.find("axis: 'w' is not one of x, y, z"), std::string::npos) << e;
  e = inputErrorOf("procedural:luneburg,n=1.5");
  EXPECT_NE(e.find("procedural:luneburg: n: material key not accepted"), std::string::npos) << e;
  e = inputErrorOf("procedural:sphere,g=2");
  EXPECT_NE(e.find("g: 2 is outside (-1, 1)"), std::string::npos) << "material keys are validated too: " << e;
  e = inputErrorOf("procedural:rounded_cube,size=1,radius=0.7");
  EXPECT_NE(e.find("radius: 0.7 exceeds half the size"), std::string::npos) << e;
  e = inputErrorOf("procedural:box,size=1:2");
  EXPECT_NE(e.find("size:"), std::string::npos) << e;
  e = inputErrorOf("procedural:sphere,r");
  EXPECT_NE(e.find("KEY=VALUE"), std::string::npos) << e;
  e = inputErrorOf("procedural:");
  EXPECT_NE(e.find("missing shape name"), std::string::npos) << e;
  EXPECT_THROW(proceduralBounds(ProceduralSpec{"sphere", {{"r", "0"}}}), InputError);
}

TEST(ProceduralSpec, EveryShapeIsDocumented) {
  ASSERT_GE(proceduralShapes().size(), 9u);
  for (const auto& shape : proceduralShapes()) {
    EXPECT_FALSE(shape.description.empty()) << shape.name;
    EXPECT_FALSE(shape.regions.empty()) << shape.name;
    for (const auto& p : shape.params) EXPECT_FALSE(p.meaning.empty()) << shape.name << " " << p.key;
  }
}

TEST(ProceduralSpec, BoundsFollowParameters) {
  const Bounds b = proceduralBounds(parseProceduralSpec("procedural:sphere,r=0.3,center=1:2:3"));
  EXPECT_NEAR(b.min.x, 0.7, 1e-12);
  EXPECT_NEAR(b.max.z, 3.3, 1e-12);
  const Bounds w = proceduralBounds(parseProceduralSpec("procedural:wine_glass,height=2"));
  EXPECT_NEAR(w.min.y, -1.0, 1e-12);
  EXPECT_NEAR(w.max.y, 1.0, 1e-12);
}

// Every shape voxelises on its own bounds: the documented regions, coverage in [0, 1], nothing
// outside the bounds, enclosed_volume = Σ coverage·V (0 for the open floor).
TEST(Procedural, EveryShapeVoxelises) {
  for (const auto& shape : proceduralShapes()) {
    const ProceduralSpec spec = parseProceduralSpec(kProceduralPrefix + shape.name);
    const Bounds bounds = proceduralBounds(spec);
    const GridSpec grid = makeGrid(bounds, 40, 3.0);
    const auto regions = voxelizeProcedural(spec, grid);
    ASSERT_EQ(regions.size(), shape.regions.size()) << shape.name;
    const glm::dvec3 h = grid.voxelSize();
    for (std::size_t r = 0; r < regions.size(); ++r) {
      const Region& region = regions[r];
      EXPECT_EQ(region.name, shape.regions[r]) << shape.name;
      ASSERT_EQ(region.coverage.size(), grid.count());
      EXPECT_GT(coverageSum(region), 1.0) << shape.name << " " << region.name;
      if (shape.name == "floor")
        EXPECT_EQ(region.enclosed_volume, 0.0);
      else
        EXPECT_NEAR(region.enclosed_volume, coverageSum(region) * grid.voxelVolume(), 1e-9);
      for (int k = 0; k < grid.dims.z; ++k)
        for (int j = 0; j < grid.dims.y; ++j)
          for (int i = 0; i < grid.dims.x; ++i) {
            const float c = region.coverage[grid.index(i, j, k)];
            ASSERT_GE(c, 0.0f);
            ASSERT_LE(c, 1.0f);
            if (c > 0.0f) {
              const glm::dvec3 p = grid.center(i, j, k);
              Bounds voxel;
              voxel.extend(p - 0.5 * h);
              voxel.extend(p + 0.5 * h);
              Bounds grown = bounds;
              // (the floor's default thickness is one voxel below its bounds' top face)
              grown.extend(bounds.min - 2.0 * h);
              grown.extend(bounds.max + 2.0 * h);
              ASSERT_TRUE(grown.contains(voxel)) << shape.name << " voxel " << i << "," << j << "," << k;
            }
          }
    }
  }
}

TEST(Procedural, SphereVolumeAt128) {
  const double R = 0.5;
  const GridSpec grid = cubeGrid(128, 0.53);
  const double exact = 4.0 / 3.0 * std::numbers::pi * R * R * R;
  for (bool antialias : {true, false}) {
    ProceduralOptions options;
    options.antialias = antialias;
    const auto regions = voxelizeProcedural(parseProceduralSpec("procedural:sphere"), grid, options);
    const double volume = coverageSum(regions[0]) * grid.voxelVolume();
    EXPECT_NEAR(volume, exact, 5e-4 * exact) << "antialias " << antialias;  // 10x tighter than required
    EXPECT_DOUBLE_EQ(regions[0].enclosed_volume, volume);
  }
}

TEST(Procedural, BoxVolumeIsExactForOffGridFaces) {
  const GridSpec grid = cubeGrid(50, 0.5);
  const auto regions =
      voxelizeProcedural(parseProceduralSpec("procedural:box,size=0.71:0.453:0.333,center=0.013:-0.02:0.031"), grid);
  const double exact = 0.71 * 0.453 * 0.333;
  EXPECT_NEAR(regions[0].enclosed_volume, exact, 1e-3 * exact);
  // Away from edges a face voxel holds exactly the fraction the face leaves it.
  const glm::dvec3 h = grid.voxelSize();
  const int i = static_cast<int>(std::floor((0.013 + 0.355 + 0.5) / h.x));  // voxel holding the +x face
  const double x0 = grid.center(i, 25, 25).x - 0.5 * h.x;
  const double expected = (0.013 + 0.355 - x0) / h.x;
  EXPECT_NEAR(regions[0].coverage[grid.index(i, 25, 25)], expected, 1e-5);
}

TEST(Procedural, SupersamplingConvergesToTheExactVolume) {
  const GridSpec grid = cubeGrid(32, 0.55);
  const double exact = 4.0 / 3.0 * std::numbers::pi * 0.125;
  double previous_error = 1.0;
  for (int s : {1, 4, 12}) {
    ProceduralOptions options;
    options.supersample = s;
    options.antialias = false;
    const double v = voxelizeProcedural(parseProceduralSpec("procedural:sphere"), grid, options)[0].enclosed_volume;
    const double error = std::abs(v - exact) / exact;
    EXPECT_LT(error, std::max(previous_error, 2e-3)) << "S = " << s;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 1e-3);
  ProceduralOptions bad;
  bad.supersample = 0;
  EXPECT_THROW(voxelizeProcedural(parseProceduralSpec("procedural:sphere"), grid, bad), std::invalid_argument);
}

TEST(Procedural, DeterministicWhateverTheThreadCount) {
  const GridSpec grid = cubeGrid(40, 0.6);
  const ProceduralSpec spec = parseProceduralSpec("procedural:wine_glass");
  ::setenv("EIKONAL_THREADS", "1", 1);
  const auto one = voxelizeProcedural(spec, grid);
  ::setenv("EIKONAL_THREADS", "3", 1);
  const auto three = voxelizeProcedural(spec, grid);
  ::unsetenv("EIKONAL_THREADS");
  ASSERT_EQ(one.size(), three.size());
  for (std::size_t r = 0; r < one.size(); ++r) {
    EXPECT_EQ(one[r].coverage, three[r].coverage);
    EXPECT_EQ(one[r].enclosed_volume, three[r].enclosed_volume);
  }
}

TEST(Procedural, LuneburgCarriesNPerVoxel) {
  const double R = 0.5;
  const GridSpec grid = cubeGrid(48, 0.55);
  const auto regions = voxelizeProcedural(parseProceduralSpec("procedural:luneburg,sigma_a=0.1"), grid);
  ASSERT_EQ(regions.size(), 1u);
  const Region& lens = regions[0];
  ASSERT_EQ(lens.ior.size(), grid.count());
  EXPECT_FLOAT_EQ(lens.material.sigma_a.x, 0.1f);
  const double h = grid.voxelSize().x;
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const std::size_t at = grid.index(i, j, k);
        const double r = glm::length(grid.center(i, j, k));
        if (r < R - h) {  // wholly inside: n at the centre, Eq. n(r) = sqrt(2 − (r/R)²)
          ASSERT_EQ(lens.coverage[at], 1.0f);
          ASSERT_NEAR(lens.ior[at], std::sqrt(2.0 - (r / R) * (r / R)), 1e-6);
        } else if (lens.coverage[at] > 0.0f) {  // boundary: the mean over the covered part, n ≈ 1
          ASSERT_GE(lens.ior[at], 1.0f);
          ASSERT_LE(lens.ior[at], std::sqrt(2.0 - std::pow((R - h) / R, 2)) + 1e-6);
        }
      }
}

TEST(Procedural, GradientSlabIsLinear) {
  const GridSpec grid = cubeGrid(40, 0.6);
  const auto regions = voxelizeProcedural(parseProceduralSpec("procedural:gradient_slab,n0=1.2,n1=1.8,axis=x"), grid);
  const Region& slab = regions[0];
  ASSERT_EQ(slab.ior.size(), grid.count());
  int checked = 0;
  for (int i = 0; i < grid.dims.x; ++i) {
    const std::size_t at = grid.index(i, 20, 20);  // z = 0.015, inside the 0.25 thick slab
    const double x = grid.center(i, 20, 20).x;
    if (slab.coverage[at] == 1.0f) {
      EXPECT_NEAR(slab.ior[at], 1.2 + 0.6 * (x + 0.5), 1e-6);
      ++checked;
    }
  }
  EXPECT_GE(checked, 30);
}

TEST(Procedural, WineGlassHoldsWineInsideTheBowl) {
  const ProceduralSpec spec = parseProceduralSpec("procedural:wine_glass");
  const GridSpec grid = makeGrid(proceduralBounds(spec), 96, 3.0);
  const auto regions = voxelizeProcedural(spec, grid);
  ASSERT_EQ(regions.size(), 2u);
  const Region& glass = regions[0];
  const Region& wine = regions[1];
  EXPECT_EQ(glass.name, "glass");
  EXPECT_EQ(wine.name, "wine");
  EXPECT_NEAR(glass.material.ior, 1.5f, 1e-6f);
  EXPECT_NEAR(wine.material.ior, 1.34f, 1e-6f);
  EXPECT_GT(wine.material.sigma_a.y, 4.0f * wine.material.sigma_a.x) << "red wine passes red";
  EXPECT_LT(wine.enclosed_volume, glass.enclosed_volume * 10.0);
  EXPECT_GT(wine.enclosed_volume, 0.0);

  // Default profile (height 1): bowl sphere of outer radius 0.26 centred at y = 0.5 − 0.55·0.26,
  // wall 0.025, wine up to 45 % of the inner depth.
  const double rb = 0.26, wall = 0.025, yc = 0.5 - 0.55 * rb, a = rb - wall;
  const double bottom = yc - a, level = bottom + 0.45 * (0.5 - bottom);
  const glm::dvec3 h = grid.voxelSize();
  const double half_diag = 0.5 * glm::length(h);
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const std::size_t at = grid.index(i, j, k);
        const glm::dvec3 p = grid.center(i, j, k);
        // No voxel is more than full: wine and glass never overlap.
        ASSERT_LE(glass.coverage[at] + wine.coverage[at], 1.0f + 1e-6f);
        if (wine.coverage[at] > 0.0f) {  // strictly inside the bowl's cavity and below the level
          ASSERT_LT(glm::length(p - glm::dvec3(0, yc, 0)), a + half_diag);
          ASSERT_LT(p.y, level + half_diag);
        }
      }
  // The wine is a spherical segment of height level − bottom.
  const double depth = level - bottom;
  const double segment = std::numbers::pi * depth * depth * (3.0 * a - depth) / 3.0;
  EXPECT_NEAR(wine.enclosed_volume, segment, 0.01 * segment);

  // Compositing takes nothing from either: both keep their whole volume.
  const Volume v = compositeRegions(regions, grid);
  const auto& m = v.metadata.at("materials");
  EXPECT_NEAR(m[0].at("volume").get<double>(), glass.enclosed_volume, 1e-6 * glass.enclosed_volume);
  EXPECT_NEAR(m[1].at("volume").get<double>(), wine.enclosed_volume, 1e-6 * wine.enclosed_volume);
}

TEST(Procedural, WineGlassScalesWithHeight) {
  const auto a = proceduralSolids(parseProceduralSpec("procedural:wine_glass"), cubeGrid(8, 1));
  const auto b = proceduralSolids(parseProceduralSpec("procedural:wine_glass,height=2"), cubeGrid(8, 1));
  EXPECT_NEAR(a[0].sdf(glm::dvec3(0.1, 0.2, 0.05)) * 2.0, b[0].sdf(glm::dvec3(0.2, 0.4, 0.1)), 1e-12);
  EXPECT_NEAR(a[1].material.sigma_a.y, 2.0f * b[1].material.sigma_a.y, 1e-5f) << "σa scales with 1/size";
  const auto c = proceduralSolids(parseProceduralSpec("procedural:wine_glass,height=2,wine_sigma_a=1:2:3"), cubeGrid(8, 1));
  EXPECT_FLOAT_EQ(c[1].material.sigma_a.y, 2.0f) << "an explicit σa is per world unit";
}

TEST(Procedural, LogoBlockEmbedsTheLogo) {
  const GridSpec grid = cubeGrid(64, 0.55);
  const auto regions = voxelizeProcedural(parseProceduralSpec("procedural:logo_block"), grid);
  ASSERT_EQ(regions.size(), 2u);
  const Region& block = regions[0];
  const Region& logo = regions[1];
  EXPECT_FALSE(logo.material.opaque);
  EXPECT_GT(logo.material.sigma_a.x, 1.0f);
  EXPECT_GT(logo.enclosed_volume, 0.0);
  for (std::size_t v = 0; v < grid.count(); ++v) ASSERT_LE(block.coverage[v] + logo.coverage[v], 1.0f + 1e-6f);
  // The logo (the ring) passes through (0, 0.36, 0); glass around it, air outside.
  const glm::dvec3 h = grid.voxelSize();
  auto at = [&](glm::dvec3 p) {
    const glm::ivec3 v = glm::ivec3(glm::floor((p - grid.bounds_min) / h));
    return grid.index(v.x, v.y, v.z);
  };
  EXPECT_GT(logo.coverage[at({0.0, 0.36, 0.0})], 0.5f);
  EXPECT_EQ(block.coverage[at({0.0, 0.0, 0.2})], 1.0f);
  EXPECT_EQ(block.coverage[at({0.0, 0.0, 0.3})] + logo.coverage[at({0.0, 0.0, 0.3})], 0.0f);

  const auto opaque = proceduralSolids(parseProceduralSpec("procedural:logo_block,logo_albedo=0.1:0.1:0.1,n=1.6"), grid);
  EXPECT_TRUE(opaque[1].material.opaque);
  EXPECT_FLOAT_EQ(opaque[1].material.ior, 1.6f) << "an opaque logo takes the block's n";
  EXPECT_NE(inputErrorOf("procedural:logo_block,logo_albedo=2"), "");
}

TEST(Procedural, LayeredCubePartitionsTheRoundedCube) {
  const GridSpec grid = cubeGrid(48, 0.55);
  const double cube =
      voxelizeProcedural(parseProceduralSpec("procedural:rounded_cube,radius=0.15"), grid)[0].enclosed_volume;
  for (const char* axis : {"y", "radial"}) {
    const auto layers = voxelizeProcedural(parseProceduralSpec(std::string("procedural:layered_cube,axis=") + axis), grid);
    ASSERT_EQ(layers.size(), 3u);
    double total = 0.0;
    for (const auto& l : layers) {
      EXPECT_GT(l.enclosed_volume, 0.0);
      total += l.enclosed_volume;
    }
    EXPECT_NEAR(total, cube, 2e-3 * cube) << axis;
    for (std::size_t v = 0; v < grid.count(); ++v)
      ASSERT_LE(layers[0].coverage[v] + layers[1].coverage[v] + layers[2].coverage[v], 1.0f + 1e-5f);
    EXPECT_NE(layers[0].material.ior, layers[2].material.ior);
    EXPECT_NE(layers[0].material.sigma_a, layers[2].material.sigma_a);
  }
  // Horizontal layers: the bottom one is layer1.
  const auto layers = voxelizeProcedural(parseProceduralSpec("procedural:layered_cube"), grid);
  const std::size_t low = grid.index(24, 6, 24), high = grid.index(24, 42, 24);
  EXPECT_EQ(layers[0].coverage[low], 1.0f);
  EXPECT_EQ(layers[2].coverage[high], 1.0f);
}

TEST(Procedural, FloorIsAnOpaqueLayerOneVoxelThick) {
  const GridSpec grid = cubeGrid(32, 1.2);  // h = 0.075
  const auto regions = voxelizeProcedural(parseProceduralSpec("procedural:floor,y=-0.53,albedo=0.5"), grid);
  ASSERT_EQ(regions.size(), 1u);
  const Region& floor = regions[0];
  EXPECT_TRUE(floor.material.opaque);
  EXPECT_FLOAT_EQ(floor.material.albedo.x, 0.5f);
  EXPECT_FLOAT_EQ(floor.material.ior, 1.0f);
  EXPECT_EQ(floor.enclosed_volume, 0.0) << "open surfaces always win";
  for (int i = 4; i < 28; ++i) {  // columns inside the 2 × 2 square
    double column = 0.0;
    for (int j = 0; j < grid.dims.y; ++j) column += floor.coverage[grid.index(i, j, 16)];
    EXPECT_NEAR(column, 1.0, 1e-5) << i;
  }
}

}  // namespace
}  // namespace eik
