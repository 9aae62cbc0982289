#include "voxelize/gltf_loader.h"

#include <tiny_gltf.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/error.h"
#include "core/text.h"
#include "voxelize/gltf_accessors.h"
#include "voxelize/gltf_container.h"
#include "voxelize/gltf_diagnostics.h"
#include "voxelize/gltf_lights_cameras.h"
#include "voxelize/gltf_materials.h"

namespace eik {
namespace {

// Images are irrelevant to the voxeliser: skip decoding them.
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
               void*) {
  return true;
}

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  return lines;
}

class GltfReader {
 public:
  GltfReader(std::string file, const tinygltf::Model& model, MeshScene& scene)
      : file_(std::move(file)), model_(model), scene_(scene), diag_{file_, &scene_.warnings}, accessors_(model_, diag_) {}

  void read() {
    checkRequiredExtensions();
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      int s = model_.defaultScene;
      if (s < 0 || static_cast<std::size_t>(s) >= model_.scenes.size()) {
        if (s >= 0) warn("scene " + str(s) + " does not exist; using scenes[0]");
        s = 0;
      }
      roots = model_.scenes[static_cast<std::size_t>(s)].nodes;
      for (int r : roots) checkNodeIndex(r, indexed("scenes", static_cast<std::size_t>(s)) + ".nodes");
    } else {  // no scenes: every node that is nobody's child
      std::vector<bool> is_child(model_.nodes.size(), false);
      for (std::size_t n = 0; n < model_.nodes.size(); ++n)
        for (int c : model_.nodes[n].children) {
          checkNodeIndex(c, indexed("nodes", n) + ".children");
          is_child[static_cast<std::size_t>(c)] = true;
        }
      for (std::size_t n = 0; n < model_.nodes.size(); ++n)
        if (!is_child[n]) roots.push_back(static_cast<int>(n));
    }
    on_path_.assign(model_.nodes.size(), false);
    for (int r : roots) visit(r, glm::dmat4(1.0));
    if (scene_.meshes.empty()) {
      throw InputError(file_, "meshes",
                       model_.meshes.empty() ? "empty mesh: the file has no meshes"
                                             : "empty mesh: the scene instances no triangles");
    }
  }

 private:
  [[noreturn]] void fail(const std::string& field, const std::string& what) const { diag_.fail(field, what); }
  void warn(const std::string& what) { diag_.warn(what); }

  void checkRequiredExtensions() {
    static const std::set<std::string> unsupported = {"KHR_draco_mesh_compression", "EXT_meshopt_compression",
                                                      "KHR_meshopt_compression"};
    for (const std::string& ext : model_.extensionsRequired)
      if (unsupported.count(ext)) fail("extensionsRequired", "'" + ext + "' (compressed geometry) is not supported");
  }

  void checkNodeIndex(int n, const std::string& field) const {
    if (n < 0 || static_cast<std::size_t>(n) >= model_.nodes.size())
      fail(field, "node " + str(n) + " out of range (the file has " + str(model_.nodes.size()) + " nodes)");
  }

  glm::dmat4 localMatrix(const tinygltf::Node& node, const std::string& field) const {
    glm::dmat4 m(1.0);
    if (!node.matrix.empty()) {
      if (node.matrix.size() != 16) fail(field + ".matrix", "needs 16 numbers, has " + str(node.matrix.size()));
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[static_cast<std::size_t>(c * 4 + r)];
    } else {
      glm::dvec3 t(0.0), s(1.0);
      glm::dquat q(1.0, 0.0, 0.0, 0.0);
      if (!node.translation.empty()) {
        if (node.translation.size() != 3) fail(field + ".translation", "needs 3 numbers");
        t = {node.translation[0], node.translation[1], node.translation[2]};
      }
      if (!node.rotation.empty()) {
        if (node.rotation.size() != 4) fail(field + ".rotation", "needs 4 numbers (x, y, z, w)");
        q = glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
        const double len = glm::length(q);
        if (!(len > 0.0)) fail(field + ".rotation", "is not a unit quaternion");
        q /= len;
      }
      if (!node.scale.empty()) {
        if (node.scale.size() != 3) fail(field + ".scale", "needs 3 numbers");
        s = {node.scale[0], node.scale[1], node.scale[2]};
      }
      m = glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(q) * glm::scale(glm::dmat4(1.0), s);
    }
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(m[c][r])) fail(field, "transform has a non-finite value");
    return m;
  }

  // The node hierarchy, depth first in the file's order, with an explicit stack (a chain of 10⁵
  // nodes must not overflow the call stack): each node's world matrix, mesh, camera and light.
  // A hierarchy deeper than kMaxNodeDepth levels or with a cycle is refused.
  static constexpr std::size_t kMaxNodeDepth = 1024;
  void visit(int root, const glm::dmat4& parent) {
    struct Frame {
      std::size_t node;
      glm::dmat4 world;
      std::size_t next_child = 0;
    };
    std::vector<Frame> stack;
    auto enter = [&](int index, const glm::dmat4& above) {
      const auto n = static_cast<std::size_t>(index);
      const std::string field = indexed("nodes", n);
      if (on_path_[n]) fail(field + ".children", "cycle in the node hierarchy");
      if (stack.size() >= kMaxNodeDepth)
        fail(field, "the node hierarchy is deeper than " + str(kMaxNodeDepth) + " levels (the limit)");
      on_path_[n] = true;
      const tinygltf::Node& node = model_.nodes[n];
      const glm::dmat4 world = above * localMatrix(node, field);
      if (node.mesh >= 0) instanceMesh(node, field, world);
      if (node.camera >= 0)
        if (std::optional<SceneCamera> camera = gltfCamera(model_, node, field, world, diag_)) scene_.cameras.push_back(*camera);
      if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end())
        if (std::optional<SceneLight> light = gltfLight(model_, node, it->second, field, world, diag_))
          scene_.lights.push_back(*light);
      stack.push_back({n, world});
    };
    enter(root, parent);
    while (!stack.empty()) {
      Frame& top = stack.back();
      const tinygltf::Node& node = model_.nodes[top.node];
      if (top.next_child == node.children.size()) {
        on_path_[top.node] = false;
        stack.pop_back();
        continue;
      }
      const int child = node.children[top.next_child++];
      checkNodeIndex(child, indexed("nodes", top.node) + ".children");
      const glm::dmat4 world = top.world;  // `top` may move when the stack grows
      enter(child, world);
    }
  }

  // --- meshes -------------------------------------------------------------------------------------

  // One primitive in mesh space (cached: a mesh instanced by several nodes is read once).
  struct PrimitiveMesh {
    bool triangles = false;
    TriangleMesh mesh;
  };

  const std::vector<PrimitiveMesh>& meshPrimitives(int mesh_index, const std::string& node_field) {
    if (static_cast<std::size_t>(mesh_index) >= model_.meshes.size())
      fail(node_field + ".mesh", "mesh " + str(mesh_index) + " out of range (the file has " +
                                     str(model_.meshes.size()) + " meshes)");
    auto cached = primitive_cache_.find(mesh_index);
    if (cached != primitive_cache_.end()) return cached->second;
    const tinygltf::Mesh& mesh = model_.meshes[static_cast<std::size_t>(mesh_index)];
    std::vector<PrimitiveMesh> out(mesh.primitives.size());
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
      out[p] = readPrimitive(mesh.primitives[p], indexed("meshes", static_cast<std::size_t>(mesh_index)) + "." +
                                                     indexed("primitives", p));
    return primitive_cache_.emplace(mesh_index, std::move(out)).first->second;
  }

  PrimitiveMesh readPrimitive(const tinygltf::Primitive& prim, const std::string& field) {
    PrimitiveMesh result;
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      static const char* names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
      warn(field + ": mode " + (mode >= 0 && mode < 4 ? names[mode] : str(mode)) +
           " skipped (only triangles are voxelised)");
      return result;
    }
    auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) fail(field + ".attributes", "no POSITION attribute");
    if (!prim.targets.empty()) warnOnce("morph targets ignored: meshes are voxelised without morphing");
    const std::string pos_usage = field + ".attributes.POSITION";
    const std::vector<double> xyz = accessors_.read<double>(
        pos->second, {TINYGLTF_TYPE_VEC3},
        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
         TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
        pos_usage);
    const std::size_t vertex_count = xyz.size() / 3;
    TriangleMesh& mesh = result.mesh;
    mesh.positions.resize(vertex_count);
    for (std::size_t v = 0; v < vertex_count; ++v) {
      mesh.positions[v] = {xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]};
      if (!std::isfinite(xyz[3 * v]) || !std::isfinite(xyz[3 * v + 1]) || !std::isfinite(xyz[3 * v + 2]))
        fail(indexed("accessors", static_cast<std::size_t>(pos->second)),
             "vertex " + str(v) + " has a non-finite coordinate (" + pos_usage + ")");
    }

    std::vector<std::uint32_t> indices;
    if (prim.indices >= 0) {
      indices = accessors_.read<std::uint32_t>(prim.indices, {TINYGLTF_TYPE_SCALAR},
                                            {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                                            field + ".indices");
      for (std::size_t i = 0; i < indices.size(); ++i)
        if (indices[i] >= vertex_count)
          fail(indexed("accessors", static_cast<std::size_t>(prim.indices)),
               "index " + str(static_cast<std::size_t>(indices[i])) + " (element " + str(i) +
                   ") is out of range: POSITION has " + str(vertex_count) + " vertices (" + field + ".indices)");
    } else {
      indices.resize(vertex_count);
      for (std::size_t i = 0; i < vertex_count; ++i) indices[i] = static_cast<std::uint32_t>(i);
    }

    auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
      if (a != b && b != c && c != a) mesh.triangles.emplace_back(a, b, c);
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (indices.size() % 3 != 0)
        warn(field + ": " + str(indices.size()) + " indices is not a multiple of 3; the last " +
             str(indices.size() % 3) + " ignored");
      for (std::size_t i = 0; i + 2 < indices.size(); i += 3) add(indices[i], indices[i + 1], indices[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (std::size_t i = 0; i + 2 < indices.size(); ++i)
        if (i % 2 == 0) add(indices[i], indices[i + 1], indices[i + 2]);
        else add(indices[i + 1], indices[i], indices[i + 2]);
    } else {
      for (std::size_t i = 1; i + 1 < indices.size(); ++i) add(indices[0], indices[i], indices[i + 1]);
    }
    if (mesh.triangles.empty()) {
      warn(field + ": no triangles");
      return result;
    }
    if (prim.material >= 0) {
      if (static_cast<std::size_t>(prim.material) >= model_.materials.size())
        fail(field + ".material", "material " + str(prim.material) + " out of range (the file has " +
                                      str(model_.materials.size()) + " materials)");
      mesh.material = material(prim.material);
    }
    result.triangles = true;
    return result;
  }

  void instanceMesh(const tinygltf::Node& node, const std::string& field, const glm::dmat4& world) {
    const std::vector<PrimitiveMesh>& prims = meshPrimitives(node.mesh, field);
    if (node.skin >= 0) warnOnce("skins ignored: meshes are voxelised in their bind pose");
    const tinygltf::Mesh& gltf_mesh = model_.meshes[static_cast<std::size_t>(node.mesh)];
    std::size_t triangle_prims = 0;
    for (const PrimitiveMesh& p : prims) triangle_prims += p.triangles ? 1 : 0;
    std::string base = !node.name.empty()       ? node.name
                       : !gltf_mesh.name.empty() ? gltf_mesh.name
                                                 : indexed("mesh", static_cast<std::size_t>(node.mesh));
    for (std::size_t p = 0; p < prims.size(); ++p) {
      if (!prims[p].triangles) continue;
      TriangleMesh mesh = prims[p].mesh;
      mesh.transform(world);
      std::string name = triangle_prims > 1 ? base + "#" + str(p) : base;
      if (const int uses = name_uses_[name]++; uses > 0) name += " (" + str(uses + 1) + ")";
      mesh.name = name;
      scene_.meshes.push_back(std::move(mesh));
    }
  }

  void warnOnce(const std::string& what) {
    if (warned_.insert(what).second) warn(what);
  }

  // The material of a primitive (cached: many primitives share one).
  Material material(int index) {
    auto cached = material_cache_.find(index);
    if (cached != material_cache_.end()) return cached->second;
    const Material out = gltfMaterial(model_, index, diag_);
    material_cache_.emplace(index, out);
    return out;
  }

  std::string file_;
  const tinygltf::Model& model_;
  MeshScene& scene_;
  std::vector<bool> on_path_;
  std::map<int, std::vector<PrimitiveMesh>> primitive_cache_;
  std::map<int, Material> material_cache_;
  std::map<std::string, int> name_uses_;
  std::set<std::string> warned_;
  GltfDiagnostics diag_;
  GltfAccessors accessors_;
};

}  // namespace

MeshScene loadGltf(const std::filesystem::path& path) {
  const std::string file = path.string();
  const std::vector<unsigned char> bytes = readGltfBytes(path);
  if (bytes.size() > std::numeric_limits<unsigned int>::max())
    throw InputError(file, "file", "larger than 4 GiB; glTF loading is limited to 4 GiB");
  std::filesystem::path base_dir = path.parent_path();
  if (base_dir.empty()) base_dir = ".";
  const bool glb = isGlb(bytes);
  const std::string ext = lower(path.extension().string());
  if (ext == ".glb" && !glb) {
    if (bytes.size() < 4) throw InputError(file, "glb header", "truncated: " + str(bytes.size()) + " bytes");
    throw InputError(file, "glb header", "not a binary glTF (magic is not 'glTF')");
  }

  if (glb) {
    const GlbParts parts = splitGlb(file, bytes);
    precheckGltfJson(file, parts.json, base_dir, &parts);
  } else {
    if (bytes.empty()) throw InputError(file, "json", "the file is empty");
    precheckGltfJson(file, std::string(bytes.begin(), bytes.end()), base_dir, nullptr);
  }

  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&skipImage, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const bool ok =
      glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), static_cast<unsigned int>(bytes.size()),
                                        base_dir.string())
          : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                       static_cast<unsigned int>(bytes.size()), base_dir.string());
  if (!ok) {
    std::vector<std::string> lines = splitLines(err);
    std::string message;
    for (const std::string& line : lines) message += (message.empty() ? "" : "; ") + line;
    if (message.empty()) message = "tinygltf could not load the file";
    throw InputError(file, "gltf", message);
  }
  MeshScene scene;
  for (const std::string& line : splitLines(warn)) scene.warnings.push_back(file + ": " + line);
  GltfReader(file, model, scene).read();
  return scene;
}

}  // namespace eik
