// glTF 2.0 (.gltf with external or embedded buffers, .glb) → MeshScene, through tinygltf.
//
// Every mesh primitive instanced by a node of the default scene becomes one world-space
// TriangleMesh (the node hierarchy's matrices or TRS applied; mirroring transforms keep normals
// outward). TRIANGLES primitives are read as they are, TRIANGLE_STRIP / TRIANGLE_FAN are
// unrolled into triangles, points and lines are skipped with a warning.
//
// Materials (DESIGN §4.1):
//   KHR_materials_transmission.transmissionFactor > 0 → dielectric:
//     n   = KHR_materials_ior.ior (1.5 when absent — Blender omits it at 1.5),
//     σa  = −ln(attenuationColor) / attenuationDistance per channel (KHR_materials_volume;
//           colour clamped to [1e-6, 1]; no or infinite distance → 0),
//     B   = 0.523655·(n − 1)·dispersion/20 (KHR_materials_dispersion, dispersion = 20/V_d),
//   otherwise opaque with albedo = baseColorFactor.rgb;
//   both: emission = emissiveFactor × KHR_materials_emissive_strength.emissiveStrength.
//   No material: glass, n = 1.5.
// Lights (KHR_lights_punctual) and perspective cameras placed by nodes come along in world space.
//
// Broken files never crash: the GLB container and the JSON are checked before tinygltf sees them,
// and every accessor (component type, element type, count, stride, offsets, sparse parts) is
// validated against its buffer view and buffer before a byte is read. Errors are InputErrors
// naming the file and the glTF field ("scene.gltf: accessors[2]: ...").
#pragma once

#include <filesystem>

#include "voxelize/mesh_scene.h"

namespace eik {

MeshScene loadGltf(const std::filesystem::path& path);

}  // namespace eik
