// glTF materials → Material: transmissive ones become dielectrics with n, σa and the Cauchy B of
// the KHR_materials_* extensions, the others opaque with their base colour; emission everywhere.
#include "voxelize/gltf_materials.h"

#include <tiny_gltf.h>

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/testing.h"

namespace eik {
namespace {

using test_support::inputErrorOf;

tinygltf::Value object(tinygltf::Value::Object members) { return tinygltf::Value(std::move(members)); }
tinygltf::Value number(double v) { return tinygltf::Value(v); }
tinygltf::Value rgb(double r, double g, double b) {
  return tinygltf::Value(tinygltf::Value::Array{number(r), number(g), number(b)});
}

tinygltf::Model modelWith(const tinygltf::Material& material) {
  tinygltf::Model model;
  model.materials.push_back(material);
  return model;
}

TEST(GltfMaterials, TransmissionMakesADielectric) {
  tinygltf::Material m;
  m.name = "flint";
  m.extensions["KHR_materials_transmission"] = object({{"transmissionFactor", number(1.0)}});
  m.extensions["KHR_materials_ior"] = object({{"ior", number(1.7)}});
  m.extensions["KHR_materials_volume"] =
      object({{"attenuationColor", rgb(1.0, 0.5, 0.25)}, {"attenuationDistance", number(2.0)}});
  m.extensions["KHR_materials_dispersion"] = object({{"dispersion", number(20.0 / 30.0)}});
  std::vector<std::string> warnings;
  const Material out = gltfMaterial(modelWith(m), 0, {"g.gltf", &warnings});
  EXPECT_EQ(out.name, "flint");
  EXPECT_FALSE(out.opaque);
  EXPECT_FLOAT_EQ(out.ior, 1.7f);
  EXPECT_FLOAT_EQ(out.sigma_a.x, 0.0f);
  EXPECT_FLOAT_EQ(out.sigma_a.y, static_cast<float>(std::log(2.0) / 2.0));  // −ln(colour) / distance
  EXPECT_FLOAT_EQ(out.sigma_a.z, static_cast<float>(std::log(4.0) / 2.0));
  EXPECT_NEAR(out.dispersion_b, cauchyBFromAbbe(1.7f, 30.0f), 1e-6);
  EXPECT_TRUE(warnings.empty());
}

TEST(GltfMaterials, WithoutTransmissionOpaqueWithItsBaseColour) {
  tinygltf::Material m;
  m.pbrMetallicRoughness.baseColorFactor = {0.2, 1.5, -0.1, 1.0};
  m.emissiveFactor = {1.0, 0.5, 0.0};
  m.extensions["KHR_materials_emissive_strength"] = object({{"emissiveStrength", number(4.0)}});
  std::vector<std::string> warnings;
  const Material out = gltfMaterial(modelWith(m), 0, {"g.gltf", &warnings});
  EXPECT_EQ(out.name, "materials[0]") << "unnamed: the field";
  EXPECT_TRUE(out.opaque);
  EXPECT_EQ(out.albedo, glm::vec3(0.2f, 1.0f, 0.0f)) << "clamped to [0, 1]";
  EXPECT_EQ(out.emission, glm::vec3(4.0f, 2.0f, 0.0f));
}

TEST(GltfMaterials, OddValuesWarnAndBadOnesFail) {
  tinygltf::Material m;
  m.extensions["KHR_materials_transmission"] = object({{"transmissionFactor", number(1.0)}});
  m.extensions["KHR_materials_ior"] = object({{"ior", number(0.5)}});
  m.extensions["KHR_materials_volume"] = object({{"attenuationDistance", number(-1.0)}});
  std::vector<std::string> warnings;
  const Material out = gltfMaterial(modelWith(m), 0, {"g.gltf", &warnings});
  EXPECT_FLOAT_EQ(out.ior, 1.0f);
  EXPECT_EQ(out.sigma_a, glm::vec3(0.0f));
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0], "g.gltf: materials[0].extensions.KHR_materials_ior.ior: 0.500000 < 1, using 1");
  EXPECT_EQ(warnings[1],
            "g.gltf: materials[0].extensions.KHR_materials_volume.attenuationDistance: -1.000000 is not positive; no "
            "absorption");

  m.extensions["KHR_materials_ior"] = object({{"ior", tinygltf::Value(std::string("glass"))}});
  EXPECT_EQ(inputErrorOf([&] { gltfMaterial(modelWith(m), 0, {"g.gltf", &warnings}); }),
            "g.gltf: materials[0].extensions.KHR_materials_ior.ior: is not a number");
  m.extensions["KHR_materials_ior"] = object({});
  m.extensions["KHR_materials_volume"] = object({{"attenuationColor", rgb(1, 1, 1)}, {"attenuationDistance", number(1)}});
  m.extensions["KHR_materials_volume"].Get<tinygltf::Value::Object>()["attenuationColor"] =
      tinygltf::Value(tinygltf::Value::Array{number(1)});
  EXPECT_EQ(inputErrorOf([&] { gltfMaterial(modelWith(m), 0, {"g.gltf", &warnings}); }),
            "g.gltf: materials[0].extensions.KHR_materials_volume.attenuationColor: is not an array of 3 numbers");
}

}  // namespace
}  // namespace eik
