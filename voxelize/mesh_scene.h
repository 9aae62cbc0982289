// What a mesh file holds for the voxeliser: world-space triangle meshes with their materials, and
// the punctual lights and cameras the file places (glTF KHR_lights_punctual, glTF cameras).
// `loadMeshFile` picks the loader by extension: .gltf / .glb (gltf_loader.h), .obj (obj_loader.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "voxelize/mesh.h"

namespace eik {

// A KHR_lights_punctual light placed by a node. Intensity is the file's raw value: lux (lm/m²)
// for a directional light, candela (lm/sr) for point and spot lights; converting to the
// programs' radiometric units is the caller's business.
struct SceneLight {
  enum class Type { Directional, Point, Spot };
  Type type = Type::Directional;
  std::string name;
  glm::dvec3 position{0.0};           // world position of the node (point, spot)
  glm::dvec3 direction{0.0, 0.0, -1.0};  // unit direction the light travels: the node's −Z axis
  glm::dvec3 color{1.0};              // linear RGB
  double intensity = 1.0;             // lux (directional) or candela (point, spot)
  double range = 0.0;                 // 0 = infinite
  double inner_cone_rad = 0.0;        // spot only
  double outer_cone_rad = 0.7853981633974483;  // spot only (glTF default π/4)
};

// A perspective camera placed by a node: looks along the node's −Z with +Y up.
struct SceneCamera {
  std::string name;
  glm::dvec3 eye{0.0};
  glm::dvec3 target{0.0, 0.0, -1.0};  // eye + unit forward
  glm::dvec3 up{0.0, 1.0, 0.0};
  double fov_y_deg = 45.0;
  double aspect_ratio = 0.0;  // 0 = not given
  double znear = 0.0;
  double zfar = 0.0;  // 0 = infinite
};

struct MeshScene {
  std::vector<TriangleMesh> meshes;
  std::vector<SceneLight> lights;
  std::vector<SceneCamera> cameras;
  // Things skipped or approximated while loading ("meshes[2].primitives[0]: mode LINES skipped").
  std::vector<std::string> warnings;
};

// Loads a .gltf, .glb or .obj file. Throws InputError ("FILE: FIELD: what", exit 2) for an
// unknown extension, a file that cannot be read or parsed, indices or accessors out of range,
// a missing external buffer, and a file with no triangles at all.
MeshScene loadMeshFile(const std::filesystem::path& path);

}  // namespace eik
