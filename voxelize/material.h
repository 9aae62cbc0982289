// Optical material of one object (thesis §3.2, docs/volume-format.md): what a voxel fully inside it holds.
#pragma once

#include <string>

#include <glm/glm.hpp>

namespace eik {

struct Material {
  std::string name = "glass";
  float ior = 1.5f;                    // refractive index n at λ_d = 587.6 nm
  glm::vec3 sigma_a{0.0f};             // absorption coefficient per world unit, RGB
  glm::vec3 emission{0.0f};            // emitted radiance L_e, RGB
  float scatter = 0.0f;                // scatter strength (albedo) ω̂
  float g = 0.0f;                      // Henyey–Greenstein anisotropy
  float dispersion_b = 0.0f;           // Cauchy B in µm²: n(λ) = n + B·(1/λ² − 1/λ_d²)
  bool opaque = false;                 // opaque embedding / receiver: shaded with `albedo`
  glm::vec3 albedo{0.8f};              // diffuse albedo of an opaque material
};

// glTF KHR_materials_dispersion stores 20/V_d (V_d = Abbe number). docs/volume-format.md:
// B = 0.523655·(n − 1)·dispersion/20, i.e. B = 0.523655·(n − 1)/V_d.
inline float cauchyBFromAbbe(float ior, float abbe) {
  return abbe > 0.0f ? 0.523655f * (ior - 1.0f) / abbe : 0.0f;
}

}  // namespace eik
