#include "voxelize/mesh_scene.h"

#include "core/error.h"
#include "core/text.h"
#include "voxelize/gltf_loader.h"
#include "voxelize/obj_loader.h"

namespace eik {

MeshScene loadMeshFile(const std::filesystem::path& path) {
  const std::string ext = lower(path.extension().string());
  if (ext == ".gltf" || ext == ".glb") return loadGltf(path);
  if (ext == ".obj") return loadObj(path);
  throw InputError(path.string(), "extension",
                   "'" + ext + "' is not a mesh format (expected .gltf, .glb or .obj)");
}

}  // namespace eik
