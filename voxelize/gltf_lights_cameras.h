// glTF lights (KHR_lights_punctual) and perspective cameras, placed by the nodes that use them →
// SceneLight and SceneCamera in world space (the loader is gltf_loader.h).
#pragma once

#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "voxelize/gltf_diagnostics.h"
#include "voxelize/mesh_scene.h"

namespace tinygltf {
class Model;
class Value;
class Node;
}  // namespace tinygltf

namespace eik {

// The light that `node`'s KHR_lights_punctual extension `ext` names, at `world` (the node's
// transform): its origin, its −Z axis as the direction. Unknown light types are skipped with a
// warning (nullopt); a missing or out-of-range light index is an InputError naming `field`.
std::optional<SceneLight> gltfLight(const tinygltf::Model& model, const tinygltf::Node& node, const tinygltf::Value& ext,
                                    const std::string& field, const glm::dmat4& world, const GltfDiagnostics& diag);

// `node`'s camera at `world`: eye at its origin, looking along −Z with +Y up (orthonormalised).
// Orthographic cameras are skipped with a warning (nullopt); an out-of-range index or a singular
// transform is an InputError naming `field`.
std::optional<SceneCamera> gltfCamera(const tinygltf::Model& model, const tinygltf::Node& node, const std::string& field,
                                      const glm::dmat4& world, const GltfDiagnostics& diag);

}  // namespace eik
