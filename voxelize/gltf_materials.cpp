#include "voxelize/gltf_materials.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace eik {
namespace {

// A number in an extension object; `fallback` when the key is absent.
double extNumber(const tinygltf::Value* obj, const char* key, double fallback, const std::string& field,
                 const GltfDiagnostics& diag) {
  if (!obj || !obj->IsObject() || !obj->Has(key)) return fallback;
  const tinygltf::Value& v = obj->Get(key);
  if (!v.IsNumber()) diag.fail(field + "." + key, "is not a number");
  const double d = v.GetNumberAsDouble();
  if (!std::isfinite(d)) diag.fail(field + "." + key, "is not finite");
  return d;
}

glm::dvec3 extColor(const tinygltf::Value* obj, const char* key, glm::dvec3 fallback, const std::string& field,
                    const GltfDiagnostics& diag) {
  if (!obj || !obj->IsObject() || !obj->Has(key)) return fallback;
  const tinygltf::Value& v = obj->Get(key);
  if (!v.IsArray() || v.ArrayLen() != 3) diag.fail(field + "." + key, "is not an array of 3 numbers");
  glm::dvec3 c;
  for (int i = 0; i < 3; ++i) {
    const tinygltf::Value& e = v.Get(i);
    if (!e.IsNumber() || !std::isfinite(e.GetNumberAsDouble())) diag.fail(field + "." + key, "is not an array of 3 numbers");
    c[i] = e.GetNumberAsDouble();
  }
  return c;
}

const tinygltf::Value* extension(const tinygltf::ExtensionMap& map, const char* name) {
  auto it = map.find(name);
  return it != map.end() && it->second.IsObject() ? &it->second : nullptr;
}

}  // namespace

Material gltfMaterial(const tinygltf::Model& model, int index, const GltfDiagnostics& diag) {
  const tinygltf::Material& m = model.materials[static_cast<std::size_t>(index)];
  const std::string field = indexed("materials", static_cast<std::size_t>(index));
  const std::string ext_field = field + ".extensions.";
  Material out;
  out.name = m.name.empty() ? field : m.name;

  const auto* transmission = extension(m.extensions, "KHR_materials_transmission");
  const auto* ior_ext = extension(m.extensions, "KHR_materials_ior");
  const auto* volume = extension(m.extensions, "KHR_materials_volume");
  const auto* dispersion_ext = extension(m.extensions, "KHR_materials_dispersion");
  const auto* strength_ext = extension(m.extensions, "KHR_materials_emissive_strength");

  glm::dvec3 base(1.0);
  if (m.pbrMetallicRoughness.baseColorFactor.size() >= 3)
    base = {m.pbrMetallicRoughness.baseColorFactor[0], m.pbrMetallicRoughness.baseColorFactor[1],
            m.pbrMetallicRoughness.baseColorFactor[2]};
  out.albedo = glm::vec3(glm::clamp(base, 0.0, 1.0));

  glm::dvec3 emissive(0.0);
  if (m.emissiveFactor.size() == 3) emissive = {m.emissiveFactor[0], m.emissiveFactor[1], m.emissiveFactor[2]};
  const double strength =
      extNumber(strength_ext, "emissiveStrength", 1.0, ext_field + "KHR_materials_emissive_strength", diag);
  out.emission = glm::vec3(glm::max(emissive * strength, 0.0));

  const double transmission_factor =
      extNumber(transmission, "transmissionFactor", 0.0, ext_field + "KHR_materials_transmission", diag);
  if (transmission_factor > 0.0) {
    double ior = extNumber(ior_ext, "ior", 1.5, ext_field + "KHR_materials_ior", diag);
    if (ior < 1.0) {
      diag.warn(ext_field + "KHR_materials_ior.ior: " + std::to_string(ior) + " < 1, using 1");
      ior = 1.0;
    }
    out.ior = static_cast<float>(ior);
    const std::string vfield = ext_field + "KHR_materials_volume";
    const glm::dvec3 color = extColor(volume, "attenuationColor", glm::dvec3(1.0), vfield, diag);
    const double distance =
        extNumber(volume, "attenuationDistance", std::numeric_limits<double>::infinity(), vfield, diag);
    if (distance > 0.0 && std::isfinite(distance)) {
      const glm::dvec3 c = glm::clamp(color, 1e-6, 1.0);
      out.sigma_a = glm::vec3(-glm::log(c) / distance);
    } else if (distance <= 0.0) {
      diag.warn(vfield + ".attenuationDistance: " + std::to_string(distance) + " is not positive; no absorption");
    }
    const double dispersion = extNumber(dispersion_ext, "dispersion", 0.0, ext_field + "KHR_materials_dispersion", diag);
    out.dispersion_b = static_cast<float>(0.523655 * (ior - 1.0) * std::max(dispersion, 0.0) / 20.0);
    out.opaque = false;
  } else {
    out.opaque = true;
  }
  return out;
}

}  // namespace eik
