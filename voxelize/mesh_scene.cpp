#include "voxelize/mesh_scene.h"

#include <algorithm>
#include <cctype>

#include "core/error.h"
#include "voxelize/gltf_loader.h"
#include "voxelize/obj_loader.h"

namespace eik {

MeshScene loadMeshFile(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".gltf" || ext == ".glb") return loadGltf(path);
  if (ext == ".obj") return loadObj(path);
  throw InputError(path.string(), "extension",
                   "'" + ext + "' is not a mesh format (expected .gltf, .glb or .obj)");
}

}  // namespace eik
