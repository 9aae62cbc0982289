// glTF materials → Material (the loader is gltf_loader.h).
//
// Materials (docs/volume-format.md):
//   KHR_materials_transmission.transmissionFactor > 0 → dielectric:
//     n   = KHR_materials_ior.ior (1.5 when absent — Blender omits it at 1.5),
//     σa  = −ln(attenuationColor) / attenuationDistance per channel (KHR_materials_volume;
//           colour clamped to [1e-6, 1]; no or infinite distance → 0),
//     B   = 0.523655·(n − 1)·dispersion/20 (KHR_materials_dispersion, dispersion = 20/V_d),
//   otherwise opaque with albedo = baseColorFactor.rgb;
//   both: emission = emissiveFactor × KHR_materials_emissive_strength.emissiveStrength.
//   No material: glass, n = 1.5.
#pragma once

#include "voxelize/gltf_diagnostics.h"
#include "voxelize/material.h"

namespace tinygltf {
class Model;
}

namespace eik {

// The material `model.materials[index]` (index in range) becomes; bad extension values are
// InputErrors naming the field, odd ones (n < 1, a distance <= 0) warnings.
Material gltfMaterial(const tinygltf::Model& model, int index, const GltfDiagnostics& diag);

}  // namespace eik
