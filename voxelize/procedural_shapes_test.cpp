// The procedural shapes (the table in procedural_shapes.cpp): each one voxelises to its documented
// regions with the geometry and materials the thesis scenes need.
#include "voxelize/procedural_shapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "core/error.h"
#include "core/testing.h"
#include "voxelize/composite.h"
#include "voxelize/procedural.h"
#include "voxelize/test_meshes.h"

namespace eik {
namespace {

// The InputError message of parsing `spec` ("" and a test failure if it parses).
std::string specErrorOf(const std::string& spec) {
  return test_support::inputErrorOf([&] { parseProceduralSpec(spec); });
}

double coverageSum(const Region& r) {
  double s = 0.0;
  for (float c : r.coverage) s += c;
  return s;
}

// n³ voxels on [−half, half]³.
GridSpec centredGrid(int n, double half) { return cubeGrid(glm::dvec3(0.0), 2.0 * half, n); }

TEST(ProceduralShapes, TableNamesTenShapesWithTheirRegions) {
  ASSERT_EQ(shapeDefs().size(), 10u);
  EXPECT_EQ(shapeNames(),
            "sphere, box, prism, rounded_cube, layered_cube, wine_glass, logo_block, luneburg, gradient_slab, floor");
  for (const ShapeDef& shape : shapeDefs()) {
    EXPECT_EQ(&findShape(shape.name, "test"), &shape);
    ASSERT_TRUE(shape.build) << shape.name;
    // With the defaults, the builder makes one solid per documented region, in that order.
    const auto solids = buildShapeSolids(ProceduralSpec{shape.name, {}}, 0.01);
    ASSERT_EQ(solids.size(), shape.regions.size()) << shape.name;
    for (std::size_t i = 0; i < solids.size(); ++i) {
      EXPECT_EQ(solids[i].name, shape.regions[i]) << shape.name;
      EXPECT_FALSE(solids[i].bounds.empty()) << shape.name;
      EXPECT_TRUE(solids[i].sdf) << shape.name;
    }
  }
}

TEST(ProceduralShapes, UnknownShapeListsTheShapes) {
  const std::string e = test_support::inputErrorOf([] { findShape("teapot", "procedural:teapot"); });
  EXPECT_EQ(e, "procedural:teapot: unknown shape 'teapot' (valid shapes: " + shapeNames() + ")");
}

TEST(ProceduralShapes, SolidsAreNegativeInsideAndPositiveOutside) {
  for (const ShapeDef& shape : shapeDefs()) {
    if (shape.name == "floor") continue;  // an open receiver, not centred at the origin
    const auto solids = buildShapeSolids(ProceduralSpec{shape.name, {}}, 0.01);
    EXPECT_GT(solids[0].sdf(glm::dvec3(5.0, 5.0, 5.0)), 4.0) << shape.name;  // far outside: about the distance
  }
  const auto sphere = buildShapeSolids(ProceduralSpec{"sphere", {{"r", "0.25"}, {"center", "1:0:0"}}}, 0.01);
  EXPECT_NEAR(sphere[0].sdf(glm::dvec3(1.0, 0.0, 0.0)), -0.25, 1e-15);
  EXPECT_NEAR(sphere[0].sdf(glm::dvec3(1.0, 0.5, 0.0)), 0.25, 1e-15);
  // The floor's default thickness is one voxel of the grid being voxelised.
  const auto floor = buildShapeSolids(ProceduralSpec{"floor", {}}, 0.125);
  EXPECT_DOUBLE_EQ(floor[0].bounds.min.y, -0.625);
  EXPECT_TRUE(floor[0].open_surface);
}

// scale and euler_deg place a shape as a scene places a volume: about its centre, lengths × s, the
// turn X then Y then Z. A box 1 × 0.5 × 0.25 at (1, 0, 0), scaled 1.5 and turned 30° about y: its
// long axis then points along (cos 30°, 0, −sin 30°) (a turn about +y carries +x towards −z), its
// faces 0.75, 0.375 and 0.1875 from the centre, and its bounds those of the turned corners.
TEST(ProceduralShapes, ScaleAndEulerAnglesPlaceTheShapeAboutItsCentre) {
  const ProceduralSpec spec{"box", {{"size", "1:0.5:0.25"}, {"center", "1:0:0"}, {"scale", "1.5"}, {"euler_deg", "0:30:0"}}};
  const auto solids = buildShapeSolids(spec, 0.01);
  ASSERT_EQ(solids.size(), 1u);
  const double a = glm::radians(30.0);
  const glm::dvec3 c(1.0, 0.0, 0.0), along(std::cos(a), 0.0, -std::sin(a)), across(std::sin(a), 0.0, std::cos(a));
  EXPECT_NEAR(solids[0].sdf(c), -0.1875, 1e-12);                  // the thinnest half-extent, 0.125 × 1.5
  EXPECT_NEAR(solids[0].sdf(c + 0.8 * along), 0.05, 1e-12);       // past the end face at 0.75
  EXPECT_NEAR(solids[0].sdf(c + 0.7 * along), -0.05, 1e-12);
  EXPECT_NEAR(solids[0].sdf(c + 0.2 * across), 0.2 - 0.1875, 1e-12);
  EXPECT_GT(solids[0].sdf(c + glm::dvec3(0.7, 0.0, 0.0)), 0.0);   // unturned, this would be inside
  EXPECT_NEAR(solids[0].bounds.max.x, 1.0 + 0.75 * std::cos(a) + 0.1875 * std::sin(a), 1e-12);
  EXPECT_NEAR(solids[0].bounds.min.z, -(0.75 * std::sin(a) + 0.1875 * std::cos(a)), 1e-12);
  EXPECT_NEAR(solids[0].bounds.max.y, 0.375, 1e-12);
  // Voxelised: the enclosed volume is the box's × s³ (1.5³ · 0.125), within the occupancy's
  // supersampling error on 64³ (measured well under 1 %; a missing s³ would be 70 % off).
  const GridSpec grid = makeGrid(proceduralBounds(spec), 64, 3.0);
  const auto regions = voxelizeProcedural(spec, grid);
  EXPECT_NEAR(regions.at(0).enclosed_volume / (1.5 * 1.5 * 1.5 * 0.125), 1.0, 0.01);
  EXPECT_NE(specErrorOf("procedural:box,scale=0").find("scale"), std::string::npos);
  EXPECT_NE(specErrorOf("procedural:box,euler_deg=1:x:2").find("euler_deg"), std::string::npos);
  EXPECT_NE(specErrorOf("procedural:floor,scale=2").find("unknown key"), std::string::npos);  // a floor is a plane
  EXPECT_NE(specErrorOf("procedural:box,scale=1:0:1").find("scale"), std::string::npos);
}

// scale=X:Y:Z scales along the shape's own axes before the turn: the unit sphere (r 0.5) scaled
// 1.5 : 0.75 : 1.2 and turned 90° about y is the ellipsoid with semi-axes 0.75 along world z (its
// x), 0.375 along y and 0.6 along world x (its z). The distance is the sphere's × 0.75 (the
// shortest factor): exact along the shortest axis, a lower bound elsewhere, zero on the surface.
TEST(ProceduralShapes, AScaleAlongTheAxesMakesTheSphereAnEllipsoid) {
  const ProceduralSpec spec{"sphere", {{"scale", "1.5:0.75:1.2"}, {"euler_deg", "0:90:0"}}};
  const auto solids = buildShapeSolids(spec, 0.01);
  ASSERT_EQ(solids.size(), 1u);
  const auto& sdf = solids[0].sdf;
  EXPECT_NEAR(sdf(glm::dvec3(0.0, 0.0, 0.75)), 0.0, 1e-12);
  EXPECT_NEAR(sdf(glm::dvec3(0.0, 0.0, -0.75)), 0.0, 1e-12);
  EXPECT_NEAR(sdf(glm::dvec3(0.6, 0.0, 0.0)), 0.0, 1e-12);
  EXPECT_NEAR(sdf(glm::dvec3(0.0, 0.375, 0.0)), 0.0, 1e-12);
  EXPECT_NEAR(sdf(glm::dvec3(0.0, 0.475, 0.0)), 0.1, 1e-12);  // along the shortest axis: exact
  EXPECT_LT(sdf(glm::dvec3(0.0, 0.0, 0.85)), 0.1);            // along the longest: a lower bound
  EXPECT_GT(sdf(glm::dvec3(0.0, 0.0, 0.85)), 0.0);
  EXPECT_LT(sdf(glm::dvec3(0.59, 0.0, 0.0)), 0.0);
  EXPECT_NEAR(solids[0].bounds.max.z, 0.75, 1e-12);
  EXPECT_NEAR(solids[0].bounds.max.x, 0.6, 1e-12);
  EXPECT_NEAR(solids[0].bounds.max.y, 0.375, 1e-12);
  // Voxelised: the enclosed volume is the ellipsoid's, 4/3·π·0.75·0.375·0.6 (within the
  // occupancy's supersampling error on 64³, as above).
  const GridSpec grid = makeGrid(proceduralBounds(spec), 64, 3.0);
  const auto regions = voxelizeProcedural(spec, grid);
  EXPECT_NEAR(regions.at(0).enclosed_volume / (4.0 / 3.0 * 3.14159265358979 * 0.75 * 0.375 * 0.6), 1.0, 0.01);
}

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

TEST(Procedural, LuneburgCarriesNPerVoxel) {
  const double R = 0.5;
  const GridSpec grid = centredGrid(48, 0.55);
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
  const GridSpec grid = centredGrid(40, 0.6);
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
  const auto a = proceduralSolids(parseProceduralSpec("procedural:wine_glass"), centredGrid(8, 1));
  const auto b = proceduralSolids(parseProceduralSpec("procedural:wine_glass,height=2"), centredGrid(8, 1));
  EXPECT_NEAR(a[0].sdf(glm::dvec3(0.1, 0.2, 0.05)) * 2.0, b[0].sdf(glm::dvec3(0.2, 0.4, 0.1)), 1e-12);
  EXPECT_NEAR(a[1].material.sigma_a.y, 2.0f * b[1].material.sigma_a.y, 1e-5f) << "σa scales with 1/size";
  const auto c = proceduralSolids(parseProceduralSpec("procedural:wine_glass,height=2,wine_sigma_a=1:2:3"), centredGrid(8, 1));
  EXPECT_FLOAT_EQ(c[1].material.sigma_a.y, 2.0f) << "an explicit σa is per world unit";
}

TEST(Procedural, LogoBlockEmbedsTheLogo) {
  const GridSpec grid = centredGrid(64, 0.55);
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
  EXPECT_NE(specErrorOf("procedural:logo_block,logo_albedo=2"), "");
}

TEST(Procedural, LayeredCubePartitionsTheRoundedCube) {
  const GridSpec grid = centredGrid(48, 0.55);
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
  const GridSpec grid = centredGrid(32, 1.2);  // h = 0.075
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

// The prism: the faces are planes at the inradius side/(2√3) from its axis, with a corner towards
// −z, and the caps at ±height/2.
TEST(ProceduralShapes, PrismFacesLieAtTheInradius) {
  const auto solids = buildShapeSolids(parseProceduralSpec("procedural:prism,side=0.6,height=1,center=0.1:0:0"), 0.01);
  ASSERT_EQ(solids.size(), 1u);
  const auto& sdf = solids[0].sdf;
  const double inradius = 0.6 / (2.0 * std::sqrt(3.0));
  EXPECT_NEAR(sdf({0.1, 0.0, inradius}), 0.0, 1e-12);                        // the face facing +z
  EXPECT_NEAR(sdf({0.1, 0.0, -2.0 * inradius}), 0.0, 1e-12);                 // the corner towards −z
  EXPECT_NEAR(sdf({0.1, 0.0, 0.0}), -inradius, 1e-12);                       // the axis
  EXPECT_NEAR(sdf({0.1, 0.5, 0.0}), 0.0, 1e-12);                             // the top cap
  EXPECT_NEAR(sdf({0.1 + inradius * std::sin(2.0944) + 0.05, 0.0, inradius * std::cos(2.0944) + 0.05 * 0.0}),
              0.05 * std::sin(2.0944), 1e-4);  // beside the face facing (sin 120°, cos 120°)
}

}  // namespace
}  // namespace eik
