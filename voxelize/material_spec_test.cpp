#include "voxelize/material_spec.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "core/testing.h"

namespace eik {
namespace {

using test_support::inputErrorOf;

TEST(MaterialSpec, ParsesEveryKey) {
  const Material m = parseMaterialSpec(
      "ior=1.7, sigma_a=0.5:8:6,emission=0:1:2,scatter=0.3,g=-0.4,abbe=40,name=flint", Material{});
  EXPECT_FLOAT_EQ(m.ior, 1.7f);
  EXPECT_FLOAT_EQ(m.sigma_a.x, 0.5f);
  EXPECT_FLOAT_EQ(m.sigma_a.y, 8.0f);
  EXPECT_FLOAT_EQ(m.sigma_a.z, 6.0f);
  EXPECT_FLOAT_EQ(m.emission.z, 2.0f);
  EXPECT_FLOAT_EQ(m.scatter, 0.3f);
  EXPECT_FLOAT_EQ(m.g, -0.4f);
  EXPECT_EQ(m.name, "flint");
  EXPECT_FALSE(m.opaque);
  // B = 0.523655·(n − 1)/V_d (docs/volume-format.md).
  EXPECT_NEAR(m.dispersion_b, 0.523655 * 0.7 / 40.0, 1e-6);
}

// 1e39 is a finite double but +Inf as the float every field stores: refused where it is read
// (it failed when writing the NRRD, after the whole voxelization).
TEST(MaterialSpec, ValuesBeyondFloatAreRefused) {
  for (const char* bad : {"ior=1e39", "sigma_a=1:1e39:1", "emission=-1e40"}) {
    const std::string e = inputErrorOf([&] { parseMaterialSpec(bad, Material{}); });
    EXPECT_NE(e.find("32-bit float"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_EQ(parseMaterialSpec("sigma_a=3e38", Material{}).sigma_a.x, 3e38f);
}

TEST(MaterialSpec, KeepsTheBaseForKeysNotGiven) {
  Material base;
  base.ior = 1.33f;
  base.sigma_a = glm::vec3(1.0f, 2.0f, 3.0f);
  const Material m = parseMaterialSpec("g=0.5", base);
  EXPECT_FLOAT_EQ(m.ior, 1.33f);
  EXPECT_FLOAT_EQ(m.sigma_a.y, 2.0f);
  EXPECT_FLOAT_EQ(m.g, 0.5f);
}

TEST(MaterialSpec, OneValueIsGrey) {
  const Material m = parseMaterialSpec("sigma_a=2", Material{});
  EXPECT_EQ(m.sigma_a, glm::vec3(2.0f));
}

TEST(MaterialSpec, AlbedoMakesOpaque) {
  const Material m = parseMaterialSpec("albedo=0.1:0.2:0.3", Material{});
  EXPECT_TRUE(m.opaque);
  EXPECT_FLOAT_EQ(m.albedo.y, 0.2f);
}

TEST(MaterialSpec, AbbeUsesTheFinalIorWhateverTheOrder) {
  const Material a = parseMaterialSpec("abbe=30,ior=1.8", Material{});
  const Material b = parseMaterialSpec("ior=1.8,abbe=30", Material{});
  EXPECT_FLOAT_EQ(a.dispersion_b, b.dispersion_b);
  EXPECT_NEAR(a.dispersion_b, 0.523655 * 0.8 / 30.0, 1e-6);
}

TEST(MaterialSpec, NIsASynonymForIor) {
  EXPECT_FLOAT_EQ(parseMaterialSpec("n=1.25", Material{}).ior, 1.25f);
  EXPECT_NE(inputErrorOf([] { parseMaterialSpec("n=1.25,ior=1.3", Material{}); }), "");
}

TEST(MaterialSpec, ErrorsNameTheFlagAndTheKey) {
  auto err = [](const std::string& spec) { return inputErrorOf([&] { parseMaterialSpec(spec, Material{}); }); };
  const std::string unknown = err("ior=1.5,colour=1");
  EXPECT_NE(unknown.find("--material: colour: unknown material key"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("sigma_a"), std::string::npos) << "lists the valid keys: " << unknown;
  EXPECT_NE(err("ior=glass").find("--material: ior: 'glass' is not a number"), std::string::npos);
  EXPECT_NE(err("ior=1.5x").find("not a number"), std::string::npos);
  EXPECT_NE(err("ior=0.9").find("--material: ior:"), std::string::npos);
  EXPECT_NE(err("sigma_a=1:-2:3").find("--material: sigma_a:"), std::string::npos);
  EXPECT_NE(err("sigma_a=1:2").find("R:G:B"), std::string::npos);
  EXPECT_NE(err("emission=-1").find("--material: emission:"), std::string::npos);
  EXPECT_NE(err("albedo=1.5").find("--material: albedo:"), std::string::npos);
  EXPECT_NE(err("scatter=2").find("--material: scatter:"), std::string::npos);
  EXPECT_NE(err("g=1").find("--material: g: 1 is outside (-1, 1)"), std::string::npos);
  EXPECT_NE(err("g=-1").find("--material: g:"), std::string::npos);
  EXPECT_NE(err("abbe=0").find("--material: abbe:"), std::string::npos);
  EXPECT_NE(err("name=").find("--material: name:"), std::string::npos);
  EXPECT_NE(err("ior").find("KEY=VALUE"), std::string::npos);
  EXPECT_NE(err("ior=1.5,ior=1.6").find("given more than once"), std::string::npos);
  EXPECT_NE(err("ior=nan").find("not a number"), std::string::npos);
  EXPECT_NE(err("").find("empty"), std::string::npos);
  EXPECT_NO_THROW(parseMaterialSpec("ior=+1.5", Material{}));
}

TEST(MaterialSpec, SourceIsUsedInMessages) {
  const std::string e = inputErrorOf([] { parseMaterialSpec("g=3", Material{}, "scene.json: material"); });
  EXPECT_EQ(e.rfind("scene.json: material: g:", 0), 0u) << e;
}

TEST(MaterialSpec, SplitKeyValuesTrimsAndKeepsOrder) {
  const auto pairs = splitKeyValues(" a = 1 ,b=2:3 ", "src");
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0], KeyValue("a", "1"));
  EXPECT_EQ(pairs[1], KeyValue("b", "2:3"));
  EXPECT_TRUE(splitKeyValues("", "src").empty());
}

}  // namespace
}  // namespace eik
