// A procedural shape's parameters against its schema: defaults, ranges and their messages, choices,
// triples, material keys.
#include "voxelize/shape_params.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/error.h"
#include "core/testing.h"

namespace eik {
namespace {

using test_support::inputErrorOf;

const std::vector<ParamDef>& schema() {
  static const std::vector<ParamDef> defs = {
      positiveParam("r", "0.5", "radius"),
      numberParam("fill", "0.45", 0.0, 1.0, false, "fraction"),
      iorParam("n1", "1.45", "index"),
      tripleParam("size", "1:1:1", 0.0, true, "sides"),
      choiceParam("axis", "y", {"x", "y", "z"}, "axis"),
      tripleParam("tint", "", 0.0, false, "optional"),
      centerParam(),
  };
  return defs;
}
const std::vector<std::string> kMaterialKeys = {"sigma_a", "abbe", "name"};

ShapeParams params(std::map<std::string, std::string> given) {
  return ShapeParams("test_shape", schema(), kMaterialKeys, ProceduralSpec{"test_shape", std::move(given)});
}

std::string errorOf(std::map<std::string, std::string> given) {
  return inputErrorOf([&] { params(std::move(given)); });
}

TEST(ShapeParams, SpecText) {
  EXPECT_EQ((ProceduralSpec{"sphere", {{"r", "0.25"}, {"ior", "1.6"}}}.text()), "procedural:sphere,ior=1.6,r=0.25");
  EXPECT_EQ((ProceduralSpec{"box", {}}.text()), "procedural:box");
}

TEST(ShapeParams, DefaultsAndGivenValues) {
  const ShapeParams p = params({{"r", "2"}, {"axis", "z"}, {"sigma_a", "1:2:3"}});
  EXPECT_EQ(p.number("r"), 2.0);
  EXPECT_EQ(p.number("fill"), 0.45);
  EXPECT_EQ(p.vec("size"), glm::dvec3(1.0));
  EXPECT_EQ(p.vec("center"), glm::dvec3(0.0));
  EXPECT_EQ(p.text("axis"), "z");
  EXPECT_TRUE(p.given("r"));
  EXPECT_TRUE(p.given("sigma_a")) << "material keys count as given";
  EXPECT_FALSE(p.given("fill"));
  EXPECT_FALSE(p.given("tint"));
  EXPECT_EQ(p.material(Material{}).sigma_a, glm::vec3(1.0f, 2.0f, 3.0f));
  EXPECT_EQ(p.dispersionFor(1.6, 0.25f), 0.25f) << "no abbe: the fallback";
  EXPECT_FLOAT_EQ(params({{"abbe", "40"}}).dispersionFor(1.6, 0.25f), cauchyBFromAbbe(1.6f, 40.0f));
}

TEST(ShapeParams, RangeMessages) {
  EXPECT_EQ(errorOf({{"r", "0"}}), "procedural:test_shape: r: 0 is out of range: must be > 0");
  EXPECT_EQ(errorOf({{"fill", "1.5"}}), "procedural:test_shape: fill: 1.5 is out of range: must lie in [0, 1]");
  EXPECT_EQ(errorOf({{"n1", "0.9"}}), "procedural:test_shape: n1: 0.9 is out of range: must be >= 1");
  EXPECT_EQ(errorOf({{"size", "1:0:1"}}), "procedural:test_shape: size: 0 is out of range: must be > 0");
  EXPECT_EQ(errorOf({{"axis", "w"}}), "procedural:test_shape: axis: 'w' is not one of x, y, z");
  EXPECT_EQ(errorOf({{"r", "big"}}), "procedural:test_shape: r: 'big' is not a number");
  EXPECT_CONTAINS(errorOf({{"size", "1:2"}}), "procedural:test_shape: size: '1:2' must be R:G:B");
}

TEST(ShapeParams, UnknownAndRefusedKeysListTheValidOnes) {
  const std::string valid = "(valid keys: r, fill, n1, size, axis, tint, center, sigma_a, abbe, name)";
  EXPECT_EQ(errorOf({{"radius", "1"}}), "procedural:test_shape: radius: unknown key for shape 'test_shape' " + valid);
  EXPECT_EQ(errorOf({{"ior", "1.5"}}),
            "procedural:test_shape: ior: material key not accepted by shape 'test_shape' " + valid);
  EXPECT_CONTAINS(errorOf({{"abbe", "-1"}}), "procedural:test_shape: abbe: -1 must be positive")
      << "material keys are validated when the parameters are";
  EXPECT_EQ(inputErrorOf([] { params({}).fail("r", "too big"); }), "procedural:test_shape: r: too big");
}

}  // namespace
}  // namespace eik
