// glTF 2.0 (.gltf with external or embedded buffers, .glb) → MeshScene, through tinygltf.
//
// Every mesh primitive instanced by a node of the default scene becomes one world-space
// TriangleMesh (the node hierarchy's matrices or TRS applied; mirroring transforms keep normals
// outward). TRIANGLES primitives are read as they are, TRIANGLE_STRIP / TRIANGLE_FAN are
// unrolled into triangles, points and lines are skipped with a warning.
//
// Materials become ours as gltf_materials.h says (dielectric with n, σa and B from the
// KHR_materials_* extensions when transmissive, else opaque; no material: glass, n = 1.5).
// Lights (KHR_lights_punctual) and perspective cameras placed by nodes come along in world space
// (gltf_lights_cameras.h).
//
// Broken files never crash: the GLB container and the JSON are checked before tinygltf sees them
// (gltf_container.h), and every accessor (component type, element type, count, stride, offsets,
// sparse parts) is validated against its buffer view and buffer before a byte is read
// (gltf_accessors.h). Errors are InputErrors naming the file and the glTF field
// ("scene.gltf: accessors[2]: ...", gltf_diagnostics.h).
#pragma once

#include <filesystem>

#include "voxelize/mesh_scene.h"

namespace eik {

MeshScene loadGltf(const std::filesystem::path& path);

}  // namespace eik
