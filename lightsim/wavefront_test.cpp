// Unit tests of the wavefront pieces (lightsim/wavefront.h) and the bake glue (lightsim/bake.h):
// sampling, initial patches, splits, Fresnel, light parsing, the bake's fields and manifest entries.
#include "lightsim/wavefront.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/error.h"
#include "core/interfaces.h"
#include "lightsim/bake.h"
#include "lightsim/test_scenes.h"

namespace eik {
namespace {

using test_scenes::cubicGrid;
using test_scenes::uniformVolume;

constexpr double kPi = std::numbers::pi;

GridSpec smallGrid() {
  GridSpec g;
  g.dims = {4, 3, 2};
  g.bounds_min = {-1.0, 0.0, 2.0};
  g.bounds_max = {1.0, 3.0, 3.0};  // voxel size (0.5, 1, 0.5)
  return g;
}

// A volume whose n, ∇n and σa hold arbitrary (random) values per voxel.
Volume randomVolume(const GridSpec& g, unsigned seed) {
  Volume v;
  v.grid = g;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const char* name : {"ior", "ior_grad", "sigma_a"}) {
    Field& f = v.addField(name, std::string(name) == "ior" ? 1 : 3);
    for (float& x : f.data) x = std::string(name) == "ior" ? 1.0f + u(rng) : u(rng) - 0.5f;
  }
  return v;
}

// Trilinear interpolation written out by hand from ALGORITHM.md "Units and inputs".
double handTrilinear(const Field& f, const GridSpec& g, const glm::dvec3& p, int component) {
  double c[3];
  int i0[3], i1[3];
  for (int a = 0; a < 3; ++a) {
    const double uvw = (p[a] - g.bounds_min[a]) / (g.bounds_max[a] - g.bounds_min[a]);
    c[a] = std::clamp(uvw * g.dims[a] - 0.5, 0.0, double(g.dims[a] - 1));
    i0[a] = int(std::floor(c[a]));
    i1[a] = std::min(i0[a] + 1, g.dims[a] - 1);
    c[a] -= i0[a];
  }
  double sum = 0.0;
  for (int k = 0; k < 8; ++k) {
    const int ix = (k & 1) ? i1[0] : i0[0], iy = (k & 2) ? i1[1] : i0[1], iz = (k & 4) ? i1[2] : i0[2];
    const double w = ((k & 1) ? c[0] : 1 - c[0]) * ((k & 2) ? c[1] : 1 - c[1]) * ((k & 4) ? c[2] : 1 - c[2]);
    sum += w * f.voxel(g.index(ix, iy, iz))[component];
  }
  return sum;
}

// ---------------------------------------------------------------------------------------------
// Sampling

TEST(VolumeSampler, VoxelCentresReturnTheVoxelValue) {
  const GridSpec g = smallGrid();
  const Volume v = randomVolume(g, 1);
  const VolumeSampler s(v);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const std::size_t idx = g.index(i, j, k);
        EXPECT_NEAR(s.ior(g.center(i, j, k)), v.fields.at("ior").data[idx], 1e-6);
        EXPECT_NEAR(s.sigmaA(g.center(i, j, k)).y, v.fields.at("sigma_a").voxel(idx)[1], 1e-6);
      }
}

TEST(VolumeSampler, MatchesHandComputationInsideAndClampsAtTheBorders) {
  const GridSpec g = smallGrid();
  const Volume v = randomVolume(g, 2);
  const VolumeSampler s(v);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.3, 1.3);  // also outside the box: clamp-to-edge
  for (int t = 0; t < 500; ++t) {
    const glm::dvec3 p = g.bounds_min + glm::dvec3(u(rng), u(rng), u(rng)) * g.extent();
    const glm::dvec4 ng = s.iorAndGradient(p);
    EXPECT_NEAR(ng.x, handTrilinear(v.fields.at("ior"), g, p, 0), 1e-6);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(ng[c + 1], handTrilinear(v.fields.at("ior_grad"), g, p, c), 1e-6);
      EXPECT_NEAR(s.sigmaA(p)[c], handTrilinear(v.fields.at("sigma_a"), g, p, c), 1e-6);
      EXPECT_NEAR(sampleTrilinear(v.fields.at("ior_grad"), g, p)[c], handTrilinear(v.fields.at("ior_grad"), g, p, c), 1e-12);
    }
  }
}

TEST(VolumeSampler, HandValuesOnALinearField) {
  // n = 1 + i + 10j + 100k at voxel (i, j, k): trilinear reproduces it exactly between the
  // outermost centres and holds the edge value beyond them (GL_CLAMP_TO_EDGE).
  const GridSpec g = smallGrid();
  Volume v = uniformVolume(g, 1.0);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) v.fields.at("ior").data[g.index(i, j, k)] = float(1 + i + 10 * j + 100 * k);
  const VolumeSampler s(v);
  // Continuous voxel coordinate (1.25, 0.5, 0.75) → world min + (c + 0.5)·h.
  const glm::dvec3 h = g.voxelSize();
  auto world = [&](double ci, double cj, double ck) { return g.bounds_min + (glm::dvec3(ci, cj, ck) + 0.5) * h; };
  EXPECT_NEAR(s.ior(world(1.25, 0.5, 0.75)), 1 + 1.25 + 5 + 75, 1e-9);
  EXPECT_NEAR(s.ior(world(-3.0, 0.5, 0.0)), 1 + 0 + 5 + 0, 1e-9);     // clamped in x
  EXPECT_NEAR(s.ior(world(3.4, 7.0, 1.0)), 1 + 3 + 20 + 100, 1e-9);   // clamped in x, y
  EXPECT_NEAR(s.ior(g.bounds_min), 1.0, 1e-9);                        // the corner holds voxel 0
  EXPECT_FALSE(s.hasAbsorption());
  EXPECT_EQ(s.sigmaA(world(1, 1, 1)), glm::dvec3(0.0));
}

// Sharp volumes of one (sphere), two (wine glass) and three (layered cube) material slots.
const std::vector<std::vector<std::string>> kSharpScenes = {
    {"procedural:sphere,r=0.3,ior=1.5"},
    {"procedural:wine_glass,height=0.8"},
    {"procedural:layered_cube,size=0.8,radius=0.1"}};

// The slot distances read from the used slots alone (one to three floats a voxel) are the
// trilinear interpolant of the interfaces field with all four channels: of a field of one distance
// per slot (as voxelize writes it) the unused slots read +band; of a field of four (volumes written
// before) the four as they are, and one whose unused channels vary is read whole.
TEST(VolumeSampler, SlotDistancesAreTheInterfacesFieldsInterpolant) {
  std::mt19937 rng(11);
  for (const auto& specs : kSharpScenes) {
    Volume v = test_scenes::sharpVolume(specs, 24);
    const InterfaceTable table = interfaceTable(v);
    const int slots = static_cast<int>(table.slots.size());
    ASSERT_EQ(v.fields.at("interfaces").components, slots);
    const Field lean = v.fields.at("interfaces");
    Field four = fourSlotDistances(lean, table.band);
    for (int form = 0; form < 3; ++form) {
      if (form > 0) v.fields.at("interfaces") = four;
      if (form == 2 && slots < 4) {
        four.voxel(7)[3] += 0.5f;  // an unused channel that varies
        v.fields.at("interfaces") = four;
      }
      const VolumeSampler sampler(v);
      ASSERT_EQ(sampler.slotCount(), slots);
      const GridSpec& g = v.grid;
      std::uniform_real_distribution<double> u(0.0, 1.0);
      for (int n = 0; n < 200; ++n) {
        // Inside the grid and a little beyond it (clamp to edge).
        const glm::dvec3 p = g.bounds_min + (glm::dvec3(u(rng), u(rng), u(rng)) * 1.1 - 0.05) * g.extent();
        const glm::dvec4 got = sampler.distances(p);
        const glm::dvec4 want = sampleTrilinear(four, g, p);
        for (int k = 0; k < 4; ++k)
          EXPECT_NEAR(got[k], want[k], 1e-9 * (1.0 + std::abs(want[k]))) << slots << " slots, form " << form << ", k " << k;
      }
    }
  }
}

// materialAt reads a cell's material from one byte where the cell's eight taps agree on it: at
// random points, and at points on the surfaces (where the cells are mixed), it must be the
// material of the interpolated distances, in scenes of one to three slots.
TEST(VolumeSampler, TheMaterialAtAPointIsThatOfItsInterpolatedDistances) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const auto& specs : kSharpScenes) {
    const Volume v = test_scenes::sharpVolume(specs, 24);
    const VolumeSampler sampler(v);
    const GridSpec& g = v.grid;
    int per_material[5] = {0, 0, 0, 0, 0}, near_surface = 0;
    for (int n = 0; n < 20000; ++n) {
      const glm::dvec3 p = g.bounds_min + (glm::dvec3(u(rng), u(rng), u(rng)) * 1.1 - 0.05) * g.extent();
      const glm::dvec4 d = sampler.distances(p);
      const int want = materialSlot(d, sampler.slotCount());
      ASSERT_EQ(sampler.materialAt(p), want) << specs[0] << " at point " << n;
      ++per_material[want + 1];
      double nearest = 1e30;
      for (int k = 0; k < sampler.slotCount(); ++k) nearest = std::min(nearest, std::abs(d[k]));
      if (nearest < sampler.h()) ++near_surface;
    }
    // Every material is met, and points within a voxel of a surface (mixed cells) too.
    for (int m = -1; m < sampler.slotCount(); ++m) EXPECT_GT(per_material[m + 1], 50) << specs[0] << " material " << m;
    EXPECT_GT(near_surface, 500) << specs[0];
  }
}

// σa per material (VolumeSampler::absorptionPerMaterial): each material's σa from the slot table or
// its deep voxels, refused (the field then decides) wherever the σa field says otherwise.
TEST(VolumeSampler, AbsorptionIsPerMaterialWhereTheFieldIsOneValueInsideEach) {
  // Wine in a sphere, a glass plate too thin for any voxel to lie a voxel diagonal inside it.
  const std::vector<std::string> specs = {"procedural:sphere,r=0.3,ior=1.33,sigma_a=1:2:3,name=wine",
                                          "procedural:box,size=0.8:0.05:0.8,center=0:-0.4:0,ior=1.5,name=glass"};
  const Volume v = test_scenes::sharpVolume(specs, 24, test_scenes::cube(0.5));
  const VolumeSampler sampler(v);
  ASSERT_TRUE(sampler.absorptionPerMaterial());
  auto slotNamed = [](const VolumeSampler& s, const std::string& name) {
    for (int k = 0; k < s.slotCount(); ++k)
      if (s.interfaces().slots[static_cast<std::size_t>(k)].name == name) return k;
    ADD_FAILURE() << "no slot " << name;
    return -1;
  };
  const int wine = slotNamed(sampler, "wine"), glass = slotNamed(sampler, "glass");
  EXPECT_EQ(sampler.materialSigmaA(wine), glm::dvec3(1.0, 2.0, 3.0));
  EXPECT_EQ(sampler.materialSigmaA(glass), glm::dvec3(0.0));
  EXPECT_EQ(sampler.materialSigmaA(-1), glm::dvec3(0.0));

  auto withoutRecordedSigma = [](Volume volume) {
    for (nlohmann::json& slot : volume.metadata["interfaces"]["slots"]) slot.erase("sigma_a");
    return volume;
  };
  // An older volume (no σa in the table): the thin plate has no deep voxel to read σa from.
  EXPECT_FALSE(VolumeSampler(withoutRecordedSigma(v)).absorptionPerMaterial());
  // With a thick plate every material has deep voxels, and their σa is each material's.
  const Volume thick = withoutRecordedSigma(test_scenes::sharpVolume(
      {specs[0], "procedural:box,size=0.8:0.2:0.8,center=0:-0.4:0,ior=1.5,name=glass"}, 24, test_scenes::cube(0.5)));
  const VolumeSampler inferred(thick);
  ASSERT_TRUE(inferred.absorptionPerMaterial());
  EXPECT_EQ(inferred.materialSigmaA(slotNamed(inferred, "wine")), glm::dvec3(1.0, 2.0, 3.0));
  EXPECT_EQ(inferred.materialSigmaA(slotNamed(inferred, "glass")), glm::dvec3(0.0));

  // The field disagrees: deep inside the wine, in the air, or with the table.
  const std::size_t centre = v.grid.index(12, 12, 12), corner = v.grid.index(1, 22, 1);
  ASSERT_EQ(sampler.materialAt(v.grid.center(12, 12, 12)), wine);
  ASSERT_EQ(sampler.materialAt(v.grid.center(1, 22, 1)), -1);
  for (const std::size_t voxel : {centre, corner}) {
    Volume changed = v;
    changed.fields.at("sigma_a").voxel(voxel)[1] = 2.5f;
    EXPECT_FALSE(VolumeSampler(changed).absorptionPerMaterial()) << voxel;
  }
  Volume recorded_differently = v;
  recorded_differently.metadata["interfaces"]["slots"][wine]["sigma_a"] = {1.0, 2.0, 3.5};
  EXPECT_FALSE(VolumeSampler(recorded_differently).absorptionPerMaterial());
  // Smooth interfaces: σa is the field's.
  EXPECT_FALSE(VolumeSampler(test_scenes::proceduralVolume(specs[0], 24)).absorptionPerMaterial());
}

TEST(VolumeSampler, RequiresIorAndGradient) {
  Volume v;
  v.grid = smallGrid();
  v.addField("ior", 1);
  EXPECT_THROW(VolumeSampler{v}, InputError);
}

// ---------------------------------------------------------------------------------------------
// Geometry

TEST(Geometry, RayBox) {
  const glm::dvec3 lo(-1.0), hi(1.0);
  EXPECT_TRUE(rayHitsBox({0, 5, 0}, {0, -1, 0}, lo, hi));
  EXPECT_FALSE(rayHitsBox({0, 5, 0}, {0, 1, 0}, lo, hi));     // pointing away
  EXPECT_TRUE(rayHitsBox({0, 0, 0}, {0, 1, 0}, lo, hi));      // starts inside
  EXPECT_FALSE(rayHitsBox({2, 5, 0}, {0, -1, 0}, lo, hi));    // parallel, outside the slab
  EXPECT_TRUE(rayHitsBox({1, 5, 0}, {0, -1, 0}, lo, hi));     // grazes the face (closed box)
  EXPECT_TRUE(rayHitsBox({3, 3, 0}, {-1, -1, 0}, lo, hi));
  EXPECT_FALSE(rayHitsBox({3, 0, 0}, {0, 1, 1}, lo, hi));
  EXPECT_TRUE(insideBox({1, 1, 1}, lo, hi));
  EXPECT_FALSE(insideBox({1, 1, 1.0001}, lo, hi));
}

TEST(Geometry, PatchQuantities) {
  Patch p;
  p.x = {glm::dvec3(0, 0, 0), {2, 0, 0}, {2, 1, 0}, {0, 1, 0}};  // 2×1, counter-clockwise about +z
  for (auto& w : p.w) w = {0, 0, 1.5};
  p.flux = {4, 2, 1};
  EXPECT_EQ(p.midpoint(), glm::dvec3(1, 0.5, 0));
  EXPECT_EQ(p.direction(), glm::dvec3(0, 0, 1));
  EXPECT_NEAR(glm::distance(p.areaVector(), glm::dvec3(0, 0, 2)), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(p.area(), 2.0);
  EXPECT_DOUBLE_EQ(p.longestEdge(), 2.0);
  EXPECT_EQ(p.irradiance(), glm::dvec3(2, 1, 0.5));  // Eq. 4.16
  EXPECT_DOUBLE_EQ(luminance(p.flux), 7.0 / 3.0);
}

TEST(Split, ConservesFluxAndTilesTheParent) {
  const Volume v = uniformVolume(cubicGrid(8, 1.0), 1.3);
  const VolumeSampler s(v);
  Patch p;  // a skewed, non-planar quadrilateral
  p.x = {glm::dvec3(0, 0, 0), {0.2, 0.01, 0.02}, {0.25, 0.18, -0.03}, {-0.02, 0.15, 0.01}};
  p.w = {glm::dvec3(0.1, 0.0, 1.0), {0.0, 0.2, 1.0}, {-0.1, 0.1, 1.2}, {0.0, 0.0, 0.9}};
  p.flux = {3.0, 1.0, 0.5};
  p.depth = 2;
  p.n_in = 1.5;
  p.cos_in = 0.7;
  const auto children = splitPatch(p, s);
  glm::dvec3 total(0.0);
  double area_sum = 0.0;
  for (int j = 0; j < 4; ++j) {
    const Patch& c = children[j];
    total += c.flux;
    area_sum += c.area();
    EXPECT_EQ(c.depth, 3);
    EXPECT_EQ(c.n_in, 1.5);
    EXPECT_EQ(c.cos_in, 0.7);
    EXPECT_DOUBLE_EQ(c.area0, c.area());
    // Corners are the bilinear patch at the child's parameter square (ALGORITHM.md step 6).
    const double u0 = kSplitChildOrigin[j][0], v0 = kSplitChildOrigin[j][1];
    const double us[4] = {u0, u0 + 0.5, u0 + 0.5, u0}, vs[4] = {v0, v0, v0 + 0.5, v0 + 0.5};
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(glm::distance(c.x[k], bilinear(p.x, us[k], vs[k])), 0.0, 1e-15);
      EXPECT_NEAR(glm::length(c.w[k]), s.ior(c.x[k]), 1e-12);  // renormalised to n
      EXPECT_NEAR(glm::length(glm::normalize(c.w[k]) - glm::normalize(bilinear(p.w, us[k], vs[k]))), 0.0, 1e-12);
    }
  }
  EXPECT_NEAR(glm::distance(total, p.flux), 0.0, 1e-14);
  // Φ_child ∝ A_child.
  for (const Patch& c : children) EXPECT_NEAR(c.flux.x / 3.0, c.area() / area_sum, 1e-14);
  // The children tile the parent: shared corners are identical and the corners reproduce the parent's.
  EXPECT_EQ(children[0].x[0], p.x[0]);
  EXPECT_EQ(children[1].x[1], p.x[1]);
  EXPECT_EQ(children[3].x[2], p.x[2]);
  EXPECT_EQ(children[2].x[3], p.x[3]);
  EXPECT_EQ(children[0].x[1], children[1].x[0]);
  EXPECT_EQ(children[0].x[2], children[3].x[0]);
  EXPECT_EQ(children[0].x[3], children[2].x[0]);
  EXPECT_EQ(children[1].x[2], children[3].x[1]);
  EXPECT_EQ(children[2].x[2], children[3].x[3]);
  // For a planar parallelogram the children's areas add up to the parent's.
  Patch q;
  q.x = {glm::dvec3(0, 0, 0), {1, 0, 0}, {1.5, 2, 0}, {0.5, 2, 0}};
  for (auto& w : q.w) w = {0, 0, 1};
  q.flux = glm::dvec3(1.0);
  double a = 0.0;
  for (const Patch& c : splitPatch(q, s)) a += c.area();
  EXPECT_NEAR(a, q.area(), 1e-14);
}

TEST(Split, AxisRuleHalvesOnlyTheLongDirection) {
  const Volume v = uniformVolume(cubicGrid(8, 1.0), 1.3);
  const VolumeSampler s(v);
  // A sliver: u edges (x0x1, x3x2) 0.3 long, v edges (x1x2, x0x3) 0.05.
  Patch p;
  p.x = {glm::dvec3(0, 0, 0), {0.3, 0.0, 0.01}, {0.31, 0.05, 0.0}, {0.0, 0.05, 0.0}};
  for (auto& w : p.w) w = {0.0, 0.0, 1.3};
  p.flux = {2.0, 1.0, 0.5};
  p.depth = 1.5;
  const double threshold = 0.2;
  const SplitAxes axis = splitAxes(p, threshold, SplitRule::Axis);
  EXPECT_TRUE(axis.u);
  EXPECT_FALSE(axis.v);
  EXPECT_EQ(axis.count(), 2);
  const SplitAxes quad = splitAxes(p, threshold, SplitRule::Quad);
  EXPECT_TRUE(quad.u && quad.v);
  EXPECT_EQ(quad.count(), 4);
  EXPECT_FALSE(splitAxes(p, 0.4, SplitRule::Axis).any());
  EXPECT_FALSE(splitAxes(p, 0.4, SplitRule::Quad).any());
  // The same sliver turned by 90° in parameter space splits along v.
  Patch q = p;
  q.x = {p.x[1], p.x[2], p.x[3], p.x[0]};
  const SplitAxes turned = splitAxes(q, threshold, SplitRule::Axis);
  EXPECT_FALSE(turned.u);
  EXPECT_TRUE(turned.v);

  for (const auto& [patch, axes] : {std::pair{p, axis}, std::pair{q, turned}}) {
    std::array<Patch, 4> children;
    ASSERT_EQ(splitPatch(patch, s, axes, children), 2);
    const Patch &a = children[0], &b = children[1];
    EXPECT_EQ(a.depth, 2.0);  // + ½ for a 1×2 split
    EXPECT_EQ(b.depth, 2.0);
    EXPECT_NEAR(glm::distance(a.flux + b.flux, patch.flux), 0.0, 1e-14);
    EXPECT_NEAR(a.flux.x / b.flux.x, a.area() / b.area(), 1e-12);
    // The children tile the parent: its corners, and the shared edge at the long edges' midpoints.
    EXPECT_EQ(a.x[0], patch.x[0]);
    if (axes.u) {
      EXPECT_EQ(b.x[1], patch.x[1]);
      EXPECT_EQ(b.x[2], patch.x[2]);
      EXPECT_EQ(a.x[3], patch.x[3]);
      EXPECT_EQ(a.x[1], b.x[0]);
      EXPECT_EQ(a.x[2], b.x[3]);
      EXPECT_NEAR(glm::distance(a.x[1], 0.5 * (patch.x[0] + patch.x[1])), 0.0, 1e-15);
    } else {
      EXPECT_EQ(a.x[1], patch.x[1]);
      EXPECT_EQ(b.x[2], patch.x[2]);
      EXPECT_EQ(b.x[3], patch.x[3]);
      EXPECT_EQ(a.x[3], b.x[0]);
      EXPECT_EQ(a.x[2], b.x[1]);
      EXPECT_NEAR(glm::distance(a.x[3], 0.5 * (patch.x[0] + patch.x[3])), 0.0, 1e-15);
    }
    // Both children are now within the threshold along the axis that was split.
    for (const Patch& c : {a, b}) EXPECT_FALSE(splitAxes(c, threshold, SplitRule::Axis).any());
  }
}

// ---------------------------------------------------------------------------------------------
// Fresnel (the corrected thesis Eq. 3.6; docs/physics.md)

TEST(Fresnel, NormalIncidence) {
  EXPECT_NEAR(fresnelReflectance(1.0, 1.5, 1.0), 0.04, 1e-15);
  EXPECT_NEAR(fresnelReflectance(1.5, 1.0, 1.0), 0.04, 1e-15);
  EXPECT_NEAR(fresnelReflectance(1.0, 1.333, 1.0), std::pow(0.333 / 2.333, 2), 1e-15);
  EXPECT_NEAR(fresnelReflectance(1.4, 1.4, 0.3), 0.0, 1e-30);
}

TEST(Fresnel, BrewsterAngleAndObliqueValues) {
  // At Brewster's angle tan θB = n2/n1, Rp = 0, so R = Rs/2 with Rs = cos²(θi + θt)... written out:
  const double n1 = 1.0, n2 = 1.5;
  const double tb = std::atan(n2 / n1);
  const double tt = std::asin(n1 * std::sin(tb) / n2);
  const double rs = std::pow(std::sin(tb - tt) / std::sin(tb + tt), 2);  // Fresnel's sine law
  EXPECT_NEAR(tb + tt, kPi / 2, 1e-12);
  EXPECT_NEAR(fresnelReflectance(n1, n2, std::cos(tb)), 0.5 * rs, 1e-12);
  EXPECT_NEAR(fresnelReflectance(n1, n2, std::cos(tb)), 0.0739, 1e-4);  // tabulated for n = 1.5
  // 45° against the sine/tangent laws.
  const double ti = kPi / 4, t2 = std::asin(std::sin(ti) / 1.5);
  const double Rs = std::pow(std::sin(ti - t2) / std::sin(ti + t2), 2);
  const double Rp = std::pow(std::tan(ti - t2) / std::tan(ti + t2), 2);
  EXPECT_NEAR(fresnelReflectance(1.0, 1.5, std::cos(ti)), 0.5 * (Rs + Rp), 1e-12);
  // Reciprocity: the same R from either side for Snell-paired angles.
  EXPECT_NEAR(fresnelReflectance(1.5, 1.0, std::cos(t2)), fresnelReflectance(1.0, 1.5, std::cos(ti)), 1e-12);
  // Grazing incidence reflects everything.
  EXPECT_NEAR(fresnelReflectance(1.0, 1.5, 0.0), 1.0, 1e-12);
}

TEST(Fresnel, TotalInternalReflection) {
  const double critical = std::asin(1.0 / 1.5);
  EXPECT_EQ(fresnelReflectance(1.5, 1.0, std::cos(critical + 0.01)), 1.0);
  EXPECT_EQ(fresnelReflectance(1.5, 1.0, 0.0), 1.0);
  EXPECT_LT(fresnelReflectance(1.5, 1.0, std::cos(critical - 0.01)), 1.0);
  EXPECT_GT(fresnelReflectance(1.5, 1.0, std::cos(critical - 0.001)), 0.7);
}

TEST(Fresnel, BoundaryReflectanceRules) {
  // Same index on both sides (skimmed the layer or turned back by the ray equation): nothing.
  EXPECT_EQ(boundaryReflectance(1.003, 0.05, 1.001, 0.05, 0.01), 0.0);
  EXPECT_EQ(boundaryReflectance(1.5, 0.2, 1.495, 0.9, 0.01), 0.0);
  // Into the denser side: the entry angle.
  EXPECT_EQ(boundaryReflectance(1.0, 0.6, 1.5, 0.2, 0.01), fresnelReflectance(1.0, 1.5, 0.6));
  // Out of it: the angle on the lower-index side, never TIR for a patch that did get out.
  EXPECT_EQ(boundaryReflectance(1.5, 0.6, 1.0, 0.3, 0.01), fresnelReflectance(1.0, 1.5, 0.3));
  EXPECT_EQ(boundaryReflectance(1.5, 0.6, 1.0, -1.0, 0.01), fresnelReflectance(1.5, 1.0, 0.6));
}

// ---------------------------------------------------------------------------------------------
// Initialisation

TEST(Initialisation, BasisIsRightHanded) {
  for (const glm::dvec3 L : {glm::dvec3(0, -1, 0), glm::normalize(glm::dvec3(1, -2, 0.5)), glm::dvec3(0, 0, 1),
                             glm::normalize(glm::dvec3(-3, 0.1, 0.2))}) {
    glm::dvec3 u, v;
    orthonormalBasis(L, u, v);
    EXPECT_NEAR(glm::dot(u, L), 0.0, 1e-15);
    EXPECT_NEAR(glm::dot(v, L), 0.0, 1e-15);
    EXPECT_NEAR(glm::length(u), 1.0, 1e-15);
    EXPECT_NEAR(glm::distance(glm::cross(u, v), L), 0.0, 1e-15);
  }
}

TEST(Initialisation, DirectionalStraightDownCoversTheBoxExactly) {
  const GridSpec g = cubicGrid(16, 0.5);
  const Volume v = uniformVolume(g, 1.0);
  const VolumeSampler s(v);
  LightSpec light;
  light.direction = {0, -1, 0};
  light.power = {2.0, 1.0, 0.5};
  double ref = 0.0;
  const auto patches = initialPatches(light, g, s, test_scenes::pointDepositOptions(), &ref);
  ASSERT_EQ(patches.size(), 16u * 16u);
  glm::dvec3 total(0.0);
  for (const Patch& p : patches) {
    total += p.flux;
    EXPECT_LE(p.longestEdge(), s.h() * (1 + 1e-12));
    EXPECT_GT(glm::dot(p.areaVector(), light.direction), 0.0);  // N along L
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(p.x[c].y, 0.5 + 0.5 * s.h(), 1e-12);  // the plane ½h before the box
      EXPECT_EQ(p.w[c], light.direction);
    }
    EXPECT_EQ(p.depth, 0);
    EXPECT_EQ(p.n_in, 0.0);
    EXPECT_DOUBLE_EQ(p.area0, p.area());
  }
  EXPECT_NEAR(total.x, 2.0 * 1.0, 1e-12);  // E_L × projected area of the box
  EXPECT_NEAR(total.z, 0.5 * 1.0, 1e-12);
  EXPECT_NEAR(ref, 2.0 / 256.0, 1e-15);
}

TEST(Initialisation, DirectionalObliqueFluxIsIrradianceTimesProjectedArea) {
  GridSpec g;
  g.dims = {20, 10, 16};
  g.bounds_min = {-1.0, -0.5, -0.8};
  g.bounds_max = {1.0, 0.5, 0.8};
  const Volume v = uniformVolume(g, 1.2);
  const VolumeSampler s(v);
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(1.0, -2.0, 0.5));
  light.power = glm::dvec3(3.0);
  SimulationOptions options = test_scenes::pointDepositOptions();
  const auto patches = initialPatches(light, g, s, options, nullptr);
  const glm::dvec3 L = light.direction, e = g.extent();
  const double projected = std::fabs(L.x) * e.y * e.z + std::fabs(L.y) * e.x * e.z + std::fabs(L.z) * e.x * e.y;
  glm::dvec3 u, w;
  orthonormalBasis(L, u, w);
  double flux = 0.0, edge = 0.0, umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
  for (const Patch& p : patches) {
    flux += p.flux.x;
    edge = std::max(edge, p.longestEdge());
    EXPECT_TRUE(rayHitsBox(p.midpoint(), L, g.bounds_min, g.bounds_max));
    EXPECT_NEAR(glm::length(p.w[0]), s.ior(p.x[0]), 1e-12);  // w = n·L
    for (const auto& x : p.x) {
      umin = std::min(umin, glm::dot(x, u));
      umax = std::max(umax, glm::dot(x, u));
      vmin = std::min(vmin, glm::dot(x, w));
      vmax = std::max(vmax, glm::dot(x, w));
    }
  }
  EXPECT_LE(edge, s.h() * (1 + 1e-12));
  // Quantisation: only patches cut by the silhouette can be wrongly in or out; the silhouette is a
  // convex hexagon inside the covering rectangle, so its perimeter is at most the rectangle's.
  const double perimeter = 2.0 * ((umax - umin) + (vmax - vmin));
  EXPECT_NEAR(flux, 3.0 * projected, 3.0 * 0.5 * perimeter * s.h());
  EXPECT_NEAR(flux, 3.0 * projected, 0.03 * 3.0 * projected);
}

// Solid angle of a rectangle a×b seen from distance d on its axis.
double rectangleSolidAngle(double a, double b, double d) {
  return 4.0 * std::atan(a * b / (2.0 * d * std::sqrt(4.0 * d * d + a * a + b * b)));
}

TEST(Initialisation, CubeCellSolidAnglesAddUpToTheSphere) {
  EXPECT_NEAR(cubeCellSolidAngle(-1, -1, 1, 1), 4.0 * kPi / 6.0, 1e-14);
  double sum = 0.0;
  const int m = 7;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i)
      sum += cubeCellSolidAngle(-1 + 2.0 * i / m, -1 + 2.0 * j / m, -1 + 2.0 * (i + 1) / m, -1 + 2.0 * (j + 1) / m);
  EXPECT_NEAR(sum, 4.0 * kPi / 6.0, 1e-13);
  for (const CubeFace& f : cubeFaces()) EXPECT_EQ(glm::cross(f.s, f.t), f.normal);
}

TEST(Initialisation, PointLightFarAwaySeesTheBoxSolidAngle) {
  const GridSpec g = cubicGrid(16, 0.5);
  const Volume v = uniformVolume(g, 1.0);
  const VolumeSampler s(v);
  LightSpec light;
  light.type = LightSpec::Type::Point;
  light.position = {0.0, 8.0, 0.0};
  light.power = glm::dvec3(5.0);
  const auto patches = initialPatches(light, g, s, test_scenes::pointDepositOptions(), nullptr);
  const double r0 = pointLightStartRadius(light.position, g);
  EXPECT_NEAR(r0, 7.5 - s.h(), 1e-12);
  double omega = 0.0, edge = 0.0;
  for (const Patch& p : patches) {
    omega += p.flux.x / 5.0;  // Φ = I·Ω
    edge = std::max(edge, p.longestEdge());
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(glm::distance(p.x[c], light.position), r0, 1e-12);
    EXPECT_GT(glm::dot(p.areaVector(), p.midpoint() - light.position), 0.0);  // N points outwards
  }
  EXPECT_LE(edge, s.h() * (1 + 1e-12));
  // Only the top face is visible from the axis. Cells are kept by their centre ray, so the kept
  // set lies between the face shrunk and grown by one cell; a cell subtends at most the patch edge
  // at r₀, i.e. at most h·d/r₀ on the face at distance d.
  const double d = 7.5, cell = s.h() * d / r0;
  EXPECT_GT(omega, rectangleSolidAngle(1.0 - 2 * cell, 1.0 - 2 * cell, d));
  EXPECT_LT(omega, rectangleSolidAngle(1.0 + 2 * cell, 1.0 + 2 * cell, d));
  EXPECT_NEAR(omega, 1.0 / (d * d), 0.05 / (d * d));  // ≈ A/d²
}

TEST(Initialisation, PointLightInsideTheBoxEmitsFourPiI) {
  const GridSpec g = cubicGrid(16, 0.5);
  const Volume v = uniformVolume(g, 1.0);
  const VolumeSampler s(v);
  LightSpec light;
  light.type = LightSpec::Type::Point;
  light.position = {0.1, -0.2, 0.05};
  light.power = {2.0, 1.0, 0.25};
  SimulationOptions options = test_scenes::pointDepositOptions();
  options.patch_voxels = 0.2;  // a finer start than the default, to exercise M > 1
  double ref = 0.0;
  const auto patches = initialPatches(light, g, s, options, &ref);
  const double r0 = pointLightStartRadius(light.position, g);
  EXPECT_DOUBLE_EQ(r0, 0.5 * s.h());
  const int m = pointLightCubeResolution(r0, g, options);
  EXPECT_EQ(m, 5);
  EXPECT_EQ(patches.size(), std::size_t(6 * m * m));
  glm::dvec3 total(0.0);
  for (const Patch& p : patches) total += p.flux;
  EXPECT_NEAR(total.x, 4.0 * kPi * 2.0, 1e-12);
  EXPECT_NEAR(total.z, 4.0 * kPi * 0.25, 1e-12);
  EXPECT_GT(ref, 0.0);
}

TEST(Initialisation, CubeResolutionIsCapped) {
  const GridSpec g = cubicGrid(16, 0.5);
  SimulationOptions options;
  EXPECT_EQ(pointLightCubeResolution(1e6, g, options), kMaxCubeResolution);
  EXPECT_EQ(pointLightCubeResolution(1e-9, g, options), 1);
}

TEST(Initialisation, RejectsBadLightsAndOptions) {
  const GridSpec g = cubicGrid(8, 0.5);
  const Volume v = uniformVolume(g, 1.0);
  const VolumeSampler s(v);
  LightSpec light;
  light.power = {1.0, -1.0, 1.0};
  EXPECT_THROW(initialPatches(light, g, s, {}, nullptr), InputError);
  light.power = glm::dvec3(1.0);
  light.direction = glm::dvec3(0.0);
  EXPECT_THROW(initialPatches(light, g, s, {}, nullptr), InputError);
  light.direction = {0, -1, 0};
  SimulationOptions o;
  o.step_voxels = 0.0;
  EXPECT_THROW(initialPatches(light, g, s, o, nullptr), InputError);
  o = {};
  o.boundary_off = 0.5;
  EXPECT_THROW(validateOptions(o), InputError);
  o = {};
  o.max_depth = -1;
  EXPECT_THROW(validateOptions(o), InputError);
  // Zero power is not an error here (parseLight rejects it): patches that carry nothing.
  light.power = glm::dvec3(0.0);
  double ref = 1.0;
  EXPECT_EQ(initialPatches(light, g, s, test_scenes::pointDepositOptions(), &ref).size(), 64u);
  EXPECT_EQ(ref, 0.0);
}

TEST(Initialisation, APointLightFarAwayCanMissASmallVolume) {
  // The box falls between the centre rays of the finest cube map (2048² cells a face).
  GridSpec g = cubicGrid(6, 3e-4);
  const Volume v = uniformVolume(g, 1.5);
  const VolumeSampler s(v);
  LightSpec light;
  light.type = LightSpec::Type::Point;
  light.position = {100.0, 37.0, -55.0};
  double ref = 1.0;
  EXPECT_TRUE(initialPatches(light, g, s, {}, &ref).empty());
  EXPECT_EQ(ref, 0.0);
}

TEST(RunConstants, TimeStepAndMaxSteps) {
  const GridSpec g = cubicGrid(20, 0.5);  // h = 0.05, diagonal √3
  SimulationOptions o;
  EXPECT_DOUBLE_EQ(timeStep(g, o), 0.025);
  EXPECT_EQ(maxSteps(g, o), int(std::ceil(4.0 * std::sqrt(3.0) / 0.025)));
  o.max_steps = 17;
  EXPECT_EQ(maxSteps(g, o), 17);
  EXPECT_DOUBLE_EQ(fluxKillThreshold(2.0, o, 2), 1e-4 * 2.0 / 16.0);
}

// ---------------------------------------------------------------------------------------------
// Lights and the bake (bake.h)

TEST(ParseLight, DirectionalAndPoint) {
  LightSpec d = parseLight("directional:0,-2,0", "1,0.5,0.25");
  EXPECT_EQ(d.type, LightSpec::Type::Directional);
  EXPECT_EQ(d.direction, glm::dvec3(0, -1, 0));  // normalised
  EXPECT_EQ(d.power, glm::dvec3(1, 0.5, 0.25));
  LightSpec p = parseLight("point:1.5,2,-3", "4");
  EXPECT_EQ(p.type, LightSpec::Type::Point);
  EXPECT_EQ(p.position, glm::dvec3(1.5, 2, -3));
  EXPECT_EQ(p.power, glm::dvec3(4.0));
  EXPECT_EQ(parseLight("point:0,0,0", "0,1,0").power, glm::dvec3(0, 1, 0));  // one dark channel is fine
}

TEST(ParseLight, Errors) {
  for (const char* bad : {"directional:0,0,0", "spot:1,2,3", "directional", "directional:1,2", "directional:1,2,3,4",
                          "point:a,b,c", "point:1,,2", "point:1,2,nan", "point:1,2,inf", "directional:1e999,0,0", ""}) {
    EXPECT_THROW(parseLight(bad, "1,1,1"), InputError) << bad;
  }
  // 1e300 and 1e31: finite as doubles, but a bake of them overflows its 32-bit float fields (it
  // failed when writing, after the whole bake); the limit is kMaxLightPower = 1e30.
  for (const char* bad : {"0,0,0", "0", "-1,1,1", "1,2", "x", "1,1,1,1", "", "1e300", "1,1e31,1"}) {
    EXPECT_THROW(parseLight("directional:0,-1,0", bad), InputError) << bad;
  }
  EXPECT_EQ(parseLight("directional:0,-1,0", "1e30").power, glm::dvec3(1e30));
  LightSpec strong;
  strong.power = glm::dvec3(1e31);
  EXPECT_THROW(validateLight(strong), InputError);
  try {
    parseLight("directional:0,0,0", "1");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--light"), std::string::npos);
  }
  try {
    parseLight("directional:0,1,0", "-1");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--power"), std::string::npos);
  }
}

TEST(Bake, LightJsonIsASceneLight) {
  LightSpec d = parseLight("directional:0,-1,0", "1,2,3");
  EXPECT_EQ(d.toJson(), nlohmann::json::parse(R"({"type":"directional","direction":[0,-1,0],"irradiance":[1,2,3]})"));
  LightSpec p = parseLight("point:1,2,3", "4,5,6");
  EXPECT_EQ(p.toJson(), nlohmann::json::parse(R"({"type":"point","position":[1,2,3],"intensity":[4,5,6]})"));
}

TEST(Bake, AddsFieldsAndManifestEntries) {
  Volume v = uniformVolume(cubicGrid(4, 0.5), 1.0);
  BakeResult r;
  r.irradiance.components = r.light_dir.components = 3;
  r.irradiance.data.assign(64 * 3, 2.0f);
  r.light_dir.data.assign(64 * 3, 0.0f);
  r.stats.initial_patches = 10;
  r.stats.flux_in = glm::dvec3(1.0);
  r.stats.flux_out = glm::dvec3(0.5);
  r.stats.flux_reflected = glm::dvec3(0.5);
  r.stats.backend = "cpu";
  r.stats.phase_seconds["update"] = 0.25;
  const LightSpec light = parseLight("directional:0,-1,0", "1");
  applyBake(v, r, light);
  EXPECT_EQ(v.fields.at("irradiance").data[5], 2.0f);
  EXPECT_TRUE(v.has("light_dir"));
  EXPECT_EQ(v.metadata.at("light"), light.toJson());
  const auto& stats = v.metadata.at("bake_stats");
  EXPECT_EQ(stats.at("initial_patches"), 10);
  EXPECT_EQ(stats.at("backend"), "cpu");
  EXPECT_EQ(stats.at("phase_seconds").at("update"), 0.25);
  EXPECT_EQ(stats.at("flux").at("ledger_relative_residual"), 0.0);
  EXPECT_TRUE(stats.at("warnings").empty());
  // A result of the wrong size is a programming error, not bad input.
  r.light_dir.data.resize(3);
  EXPECT_THROW(applyBake(v, r, light), std::invalid_argument);
}

// A bake without volume deposits (empty fields) leaves no field of an earlier bake behind.
TEST(Bake, ABakeWithoutVolumeDepositsRemovesAnEarlierBakesFields) {
  Volume v = uniformVolume(cubicGrid(4, 0.5), 1.0);
  v.addField("irradiance", 3);
  v.addField("light_dir", 3);
  BakeResult r;
  r.irradiance.components = r.light_dir.components = 3;
  applyBake(v, r, parseLight("directional:0,-1,0", "1"));
  EXPECT_FALSE(v.has("irradiance"));
  EXPECT_FALSE(v.has("light_dir"));
  EXPECT_TRUE(v.has("ior"));
  EXPECT_TRUE(v.metadata.contains("bake_stats"));
}

// The viewer reads a volume's baked light for in-scattering, opaque parts and, without a receiver
// map, the ground: the deciding voxel is one of 64, so a check that skipped voxels would fail.
TEST(Bake, TheViewerReadsTheVolumesLightWhereSomethingScattersOrIsOpaqueOrNoMapIsBaked) {
  Volume glass = uniformVolume(cubicGrid(4, 0.5), 1.5);
  EXPECT_FALSE(viewerReadsVolumeLight(glass, true));
  EXPECT_TRUE(viewerReadsVolumeLight(glass, false));
  Volume smoke = glass;
  smoke.addField("scatter", 2).data[2 * 37 + 1] = 0.8f;  // g alone scatters nothing
  EXPECT_FALSE(viewerReadsVolumeLight(smoke, true));
  smoke.fields.at("scatter").data[2 * 37] = 0.5f;
  EXPECT_TRUE(viewerReadsVolumeLight(smoke, true));
  Volume embedded = glass;
  embedded.addField("opaque", 4).data[4 * 63 + 0] = 0.7f;  // an albedo without the indicator
  EXPECT_FALSE(viewerReadsVolumeLight(embedded, true));
  embedded.fields.at("opaque").data[4 * 63 + 3] = 1.0f;
  EXPECT_TRUE(viewerReadsVolumeLight(embedded, true));
}

TEST(Bake, StatsWarnWhenTheLightBroughtNothing) {
  SimulationStats s;
  EXPECT_TRUE(lightMissedVolume(s));
  EXPECT_EQ(s.toJson().at("warnings").size(), 1u);
}

}  // namespace
}  // namespace eik
