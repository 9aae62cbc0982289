#include "voxelize/composite.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "voxelize/procedural.h"

namespace eik {
namespace {

GridSpec oneVoxel() {
  GridSpec g;
  g.dims = glm::ivec3(1);
  g.bounds_min = glm::dvec3(0);
  g.bounds_max = glm::dvec3(0.5);  // V_voxel = 1/8
  return g;
}

Region region(const std::string& name, float coverage, double enclosed, Material m = {}) {
  Region r;
  r.name = name;
  r.material = std::move(m);
  r.coverage = {coverage};
  r.enclosed_volume = enclosed;
  return r;
}

TEST(Composite, InnermostWinsAndAirTakesTheRest) {
  Material inner;
  inner.ior = 1.8f;
  inner.sigma_a = glm::vec3(4, 0, 0);
  inner.emission = glm::vec3(0, 2, 0);
  inner.dispersion_b = 0.01f;
  Material outer;
  outer.ior = 1.4f;
  outer.sigma_a = glm::vec3(0, 0, 2);
  // Input order: outer first. The inner one (smaller enclosed volume) takes 0.6, the outer what is
  // left of its 0.7 (0.4), air nothing.
  const Volume v = compositeRegions({region("outer", 0.7f, 10.0, outer), region("inner", 0.6f, 1.0, inner)}, oneVoxel());
  EXPECT_NEAR(v.fields.at("ior").data[0], 1.0 + 0.6 * 0.8 + 0.4 * 0.4, 1e-6);
  const float* sa = v.fields.at("sigma_a").voxel(0);
  EXPECT_NEAR(sa[0], 0.6 * 4, 1e-6);
  EXPECT_NEAR(sa[2], 0.4 * 2, 1e-6);
  EXPECT_NEAR(v.fields.at("emission").voxel(0)[1], 0.6 * 2, 1e-6);
  EXPECT_NEAR(v.fields.at("dispersion").data[0], 0.6 * 0.01, 1e-7);
  EXPECT_FALSE(v.has("scatter"));
  EXPECT_FALSE(v.has("opaque"));

  const auto& m = v.metadata.at("materials");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].at("name"), "outer");  // input order
  EXPECT_NEAR(m[0].at("volume").get<double>(), 0.4 / 8.0, 1e-7);
  EXPECT_NEAR(m[1].at("volume").get<double>(), 0.6 / 8.0, 1e-7);
  EXPECT_NEAR(m[1].at("ior").get<double>(), 1.8, 1e-6);
}

TEST(Composite, LeavesIorOutWhenTheCallerMakesIt) {
  // Sharp interfaces take n from the distances (sharp_interfaces.cpp): the composite then makes no
  // `ior`, and everything else as with it: the blended fields and each region's volume.
  Material inner;
  inner.ior = 1.8f;
  inner.sigma_a = glm::vec3(4, 0, 0);
  Material outer;
  outer.ior = 1.4f;
  const std::vector<Region> regions = {region("outer", 0.7f, 10.0, outer), region("inner", 0.6f, 1.0, inner)};
  CompositeOptions without;
  without.ior = false;
  const Volume with_ior = compositeRegions(regions, oneVoxel());
  const Volume v = compositeRegions(regions, oneVoxel(), without);
  EXPECT_FALSE(v.has("ior"));
  ASSERT_TRUE(v.has("sigma_a"));
  EXPECT_EQ(v.fields.at("sigma_a").data, with_ior.fields.at("sigma_a").data);
  EXPECT_EQ(v.metadata.at("materials"), with_ior.metadata.at("materials"));
  EXPECT_NEAR(v.metadata.at("materials")[0].at("volume").get<double>(), 0.4 / 8.0, 1e-7);
}

TEST(Composite, PartialCoverageMixesWithAir) {
  Material glass;
  glass.ior = 1.5f;
  const Volume v = compositeRegions({region("glass", 0.25f, 1.0, glass)}, oneVoxel());
  EXPECT_NEAR(v.fields.at("ior").data[0], 1.125, 1e-6);
  EXPECT_EQ(v.fields.size(), 1u) << "only n when nothing else is non-zero";
}

TEST(Composite, TiesGoToTheLaterInput) {
  Material a, b;
  a.ior = 1.3f;
  b.ior = 1.7f;
  const Volume v = compositeRegions({region("a", 1.0f, 5.0, a), region("b", 1.0f, 5.0, b)}, oneVoxel());
  EXPECT_NEAR(v.fields.at("ior").data[0], 1.7, 1e-6);
  EXPECT_EQ(compositeOrder({region("a", 1.0f, 5.0), region("b", 1.0f, 5.0), region("c", 1.0f, 1.0)}),
            (std::vector<std::size_t>{2, 1, 0}));
}

TEST(Composite, ScatterAndOpaqueAreWeighted) {
  Material smoke;
  smoke.ior = 1.0f;
  smoke.scatter = 0.5f;
  smoke.g = 0.8f;
  Material milk;
  milk.scatter = 1.0f;
  milk.g = -0.2f;
  Material floor_m;
  floor_m.ior = 1.0f;
  floor_m.opaque = true;
  floor_m.albedo = glm::vec3(0.2f, 0.4f, 0.6f);
  // floor (open, enclosed 0) first: 0.25; milk 0.25; smoke the remaining 0.5.
  const Volume v = compositeRegions(
      {region("smoke", 1.0f, 100.0, smoke), region("milk", 0.25f, 2.0, milk), region("floor", 0.25f, 0.0, floor_m)},
      oneVoxel());
  const float* s = v.fields.at("scatter").voxel(0);
  const double w = 0.5 * 0.5 + 0.25 * 1.0;
  EXPECT_NEAR(s[0], w, 1e-6);
  EXPECT_NEAR(s[1], (0.5 * 0.5 * 0.8 + 0.25 * 1.0 * -0.2) / w, 1e-6) << "g of the scattering part";
  const float* o = v.fields.at("opaque").voxel(0);
  EXPECT_NEAR(o[0], 0.2, 1e-6) << "albedo is not darkened by partial coverage";
  EXPECT_NEAR(o[2], 0.6, 1e-6);
  EXPECT_NEAR(o[3], 0.25, 1e-6) << "indicator = covered fraction";
  EXPECT_NEAR(v.fields.at("ior").data[0], 1.0 + 0.25 * 0.5, 1e-6);
}

TEST(Composite, PerVoxelIorIsUsed) {
  Region r = region("lens", 0.5f, 1.0);
  r.ior = {1.9f};
  const Volume v = compositeRegions({r}, oneVoxel());
  EXPECT_NEAR(v.fields.at("ior").data[0], 1.0 + 0.5 * 0.9, 1e-6);
}

TEST(Composite, AllFieldsOnRequest) {
  CompositeOptions options;
  options.all_fields = true;
  const Volume v = compositeRegions({region("glass", 1.0f, 1.0)}, oneVoxel(), options);
  for (const char* name : {"ior", "sigma_a", "emission", "scatter", "opaque", "dispersion"})
    EXPECT_TRUE(v.has(name)) << name;
  EXPECT_EQ(v.fields.at("opaque").components, 4);
  EXPECT_EQ(v.fields.at("scatter").components, 2);
}

TEST(Composite, RejectsArraysThatDoNotMatchTheGrid) {
  Region r = region("bad", 1.0f, 1.0);
  r.coverage.push_back(0.0f);
  EXPECT_THROW(compositeRegions({r}, oneVoxel()), std::invalid_argument);
  Region s = region("bad_ior", 1.0f, 1.0);
  s.ior = {1.5f, 1.5f};
  EXPECT_THROW(compositeRegions({s}, oneVoxel()), std::invalid_argument);
}

// A small sphere inside a big one gets the inner material, whatever the input order.
TEST(Composite, NestedSpheres) {
  GridSpec g;
  g.dims = glm::ivec3(48);
  g.bounds_min = glm::dvec3(-0.6);
  g.bounds_max = glm::dvec3(0.6);
  auto big = voxelizeProcedural(parseProceduralSpec("procedural:sphere,r=0.5,ior=1.5,name=big"), g);
  auto small = voxelizeProcedural(parseProceduralSpec("procedural:sphere,r=0.2,ior=1.8,sigma_a=3,name=small"), g);
  ASSERT_EQ(big.size(), 1u);
  ASSERT_EQ(small.size(), 1u);
  EXPECT_EQ(small[0].name, "small");
  for (bool small_first : {false, true}) {
    std::vector<Region> regions = small_first ? std::vector<Region>{small[0], big[0]} : std::vector<Region>{big[0], small[0]};
    const Volume v = compositeRegions(regions, g);
    const Field& n = v.fields.at("ior");
    const Field& sa = v.fields.at("sigma_a");
    for (int k = 0; k < g.dims.z; ++k)
      for (int j = 0; j < g.dims.y; ++j)
        for (int i = 0; i < g.dims.x; ++i) {
          const double r = glm::length(g.center(i, j, k));
          const std::size_t at = g.index(i, j, k);
          const double h = g.voxelSize().x;
          if (r < 0.2 - h) {
            ASSERT_NEAR(n.data[at], 1.8f, 1e-6f);
            ASSERT_NEAR(sa.voxel(at)[0], 3.0f, 1e-6f);
          } else if (r > 0.2 + h && r < 0.5 - h) {
            ASSERT_NEAR(n.data[at], 1.5f, 1e-6f);
            ASSERT_EQ(sa.voxel(at)[0], 0.0f);
          } else if (r > 0.5 + h) {
            ASSERT_EQ(n.data[at], 1.0f);
          }
          ASSERT_LE(n.data[at], 1.8f + 1e-6f);
        }
    // The big sphere holds its volume less the small one's.
    const auto& m = v.metadata.at("materials");
    const std::size_t ib = small_first ? 1 : 0, is = 1 - ib;
    EXPECT_NEAR(m[is].at("volume").get<double>(), small[0].enclosed_volume, 1e-9);
    EXPECT_NEAR(m[ib].at("volume").get<double>(), big[0].enclosed_volume - small[0].enclosed_volume, 1e-6);
  }
}

}  // namespace
}  // namespace eik
