#include "voxelize/gltf_loader.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "core/error.h"

namespace eik {
namespace {

constexpr std::uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr std::uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"
constexpr std::size_t kMaxElements = std::size_t(1) << 31;

std::string str(std::size_t v) { return std::to_string(v); }
std::string str(int v) { return std::to_string(v); }
std::string indexed(const char* array, std::size_t i) { return std::string(array) + "[" + str(i) + "]"; }

std::uint32_t readU32(const unsigned char* p) {
  return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16) |
         (std::uint32_t(p[3]) << 24);
}

std::vector<unsigned char> readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "file", "cannot be opened");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path.string(), "file", "read error");
  return bytes;
}

// Percent-decoding of a relative URI (tinygltf does the same when it opens the file).
std::string decodeUri(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out.push_back(static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

// The GLB container: header and chunk table checked against the file size (tinygltf trusts them).
struct GlbParts {
  std::string json;
  bool has_bin = false;
  std::size_t bin_size = 0;
};

GlbParts splitGlb(const std::string& file, const std::vector<unsigned char>& bytes) {
  const std::size_t size = bytes.size();
  if (size < 12) throw InputError(file, "glb header", "truncated: " + str(size) + " bytes, a GLB header needs 12");
  if (readU32(bytes.data()) != kGlbMagic) throw InputError(file, "glb header", "not a binary glTF (magic is not 'glTF')");
  if (std::uint32_t version = readU32(bytes.data() + 4); version != 2)
    throw InputError(file, "glb header", "version " + std::to_string(version) + " is not supported (expected 2)");
  const std::size_t length = readU32(bytes.data() + 8);
  if (length > size)
    throw InputError(file, "glb header", "truncated: the header says " + str(length) + " bytes, the file has " + str(size));
  if (length < 20) throw InputError(file, "glb chunk 0", "truncated: no JSON chunk");
  const std::size_t json_length = readU32(bytes.data() + 12);
  if (readU32(bytes.data() + 16) != kGlbChunkJson) throw InputError(file, "glb chunk 0", "the first chunk is not JSON");
  if (json_length > length - 20)
    throw InputError(file, "glb chunk 0",
                     "truncated: the JSON chunk of " + str(json_length) + " bytes runs past the end of the file (" +
                         str(length) + " bytes)");
  GlbParts parts;
  parts.json.assign(reinterpret_cast<const char*>(bytes.data()) + 20, json_length);
  std::size_t offset = 20 + json_length;
  if (offset < length) {
    if (length - offset < 8) throw InputError(file, "glb chunk 1", "truncated chunk header");
    const std::size_t chunk_length = readU32(bytes.data() + offset);
    if (chunk_length > length - offset - 8)
      throw InputError(file, "glb chunk 1",
                       "truncated: the chunk of " + str(chunk_length) + " bytes runs past the end of the file");
    if (readU32(bytes.data() + offset + 4) == kGlbChunkBin) {
      parts.has_bin = true;
      parts.bin_size = chunk_length;
    }
  }
  return parts;
}

// JSON syntax and external buffer files, checked with messages that name the field.
void precheckJson(const std::string& file, const std::string& text, const std::filesystem::path& base_dir,
                  const GlbParts* glb) {
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    std::string what = e.what();
    if (auto pos = what.find("] "); what.rfind("[json.exception", 0) == 0 && pos != std::string::npos)
      what = what.substr(pos + 2);
    throw InputError(file, "json", what);
  }
  if (!root.is_object()) throw InputError(file, "json", "the top level is not an object");
  auto buffers = root.find("buffers");
  if (buffers == root.end() || !buffers->is_array()) return;
  for (std::size_t i = 0; i < buffers->size(); ++i) {
    const nlohmann::json& buffer = (*buffers)[i];
    const std::string field = indexed("buffers", i);
    if (!buffer.is_object()) throw InputError(file, field, "is not an object");
    std::size_t byte_length = 0;
    if (auto bl = buffer.find("byteLength"); bl != buffer.end()) {
      if (!bl->is_number_unsigned()) throw InputError(file, field + ".byteLength", "is not a non-negative integer");
      byte_length = bl->get<std::size_t>();
    }
    auto uri = buffer.find("uri");
    if (uri == buffer.end()) {
      if (glb && i == 0) {
        if (!glb->has_bin) throw InputError(file, field, "refers to the GLB binary chunk, which the file lacks");
        if (glb->bin_size < byte_length)
          throw InputError(file, field, "byteLength " + str(byte_length) + " exceeds the GLB binary chunk (" +
                                            str(glb->bin_size) + " bytes)");
      }
      continue;
    }
    if (!uri->is_string()) throw InputError(file, field + ".uri", "is not a string");
    const std::string u = uri->get<std::string>();
    if (u.rfind("data:", 0) == 0) continue;  // embedded; tinygltf decodes and checks it
    const std::filesystem::path external = base_dir / decodeUri(u);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(external, ec))
      throw InputError(file, field + ".uri", "external buffer file '" + external.string() + "' not found");
    const auto bytes = std::filesystem::file_size(external, ec);
    if (!ec && bytes < byte_length)
      throw InputError(file, field, "'" + external.string() + "' has " + str(static_cast<std::size_t>(bytes)) +
                                        " bytes, byteLength says " + str(byte_length));
  }
}

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

// --- accessors ------------------------------------------------------------------------------------

double readComponent(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto v = static_cast<std::int8_t>(p[0]);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? v / 4294967295.0 : v;
    }
    default:
      return 0.0;
  }
}

std::string componentTypeName(int t) {
  switch (t) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "DOUBLE";
    default: return std::to_string(t);
  }
}

class GltfReader {
 public:
  GltfReader(std::string file, const tinygltf::Model& model, MeshScene& scene)
      : file_(std::move(file)), model_(model), scene_(scene) {}

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
  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError(file_, field, what);
  }
  void warn(const std::string& what) { scene_.warnings.push_back(file_ + ": " + what); }

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

  void visit(int index, const glm::dmat4& parent) {
    const auto n = static_cast<std::size_t>(index);
    const std::string field = indexed("nodes", n);
    if (on_path_[n]) fail(field + ".children", "cycle in the node hierarchy");
    on_path_[n] = true;
    const tinygltf::Node& node = model_.nodes[n];
    const glm::dmat4 world = parent * localMatrix(node, field);
    if (node.mesh >= 0) instanceMesh(node, field, world);
    if (node.camera >= 0) placeCamera(node, field, world);
    if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end())
      placeLight(node, it->second, field, world);
    for (int c : node.children) {
      checkNodeIndex(c, field + ".children");
      visit(c, world);
    }
    on_path_[n] = false;
  }

  // Reads accessor `index` into `components` values per element, after checking everything the
  // read relies on. `usage` says what it is for, in messages.
  template <typename T>
  std::vector<T> readAccessor(int index, std::initializer_list<int> types, std::initializer_list<int> component_types,
                              const std::string& usage, int* components_out = nullptr) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model_.accessors.size())
      fail(usage, "accessor " + str(index) + " out of range (the file has " + str(model_.accessors.size()) +
                      " accessors)");
    const tinygltf::Accessor& acc = model_.accessors[static_cast<std::size_t>(index)];
    const std::string field = indexed("accessors", static_cast<std::size_t>(index));
    const int components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(acc.type));
    if (components <= 0 || std::find(types.begin(), types.end(), acc.type) == types.end())
      fail(field + ".type", "element type " + str(acc.type) + " cannot be used as " + usage);
    const int csize = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(acc.componentType));
    if (csize <= 0 ||
        std::find(component_types.begin(), component_types.end(), acc.componentType) == component_types.end())
      fail(field + ".componentType", componentTypeName(acc.componentType) + " cannot be used as " + usage);
    const std::size_t element_size = static_cast<std::size_t>(components) * static_cast<std::size_t>(csize);
    const std::size_t count = acc.count;
    if (count > kMaxElements) fail(field + ".count", str(count) + " elements is more than this program reads");
    if (components_out) *components_out = components;

    std::vector<T> values(count * static_cast<std::size_t>(components), T(0));
    auto read = [&](const unsigned char* element, std::size_t i) {
      for (int c = 0; c < components; ++c)
        values[i * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)] =
            static_cast<T>(readComponent(element + static_cast<std::size_t>(c * csize), acc.componentType, acc.normalized));
    };

    if (acc.bufferView >= 0) {
      const std::size_t stride_default = element_size;
      const auto [data, view_length, stride] = bufferView(acc.bufferView, field + ".bufferView", stride_default);
      if (stride < element_size)
        fail(indexed("bufferViews", static_cast<std::size_t>(acc.bufferView)) + ".byteStride",
             str(stride) + " is smaller than the " + str(element_size) + "-byte elements of " + field);
      if (count > 0) {
        const unsigned __int128 need = static_cast<unsigned __int128>(acc.byteOffset) +
                                       static_cast<unsigned __int128>(stride) * (count - 1) + element_size;
        if (need > view_length)
          fail(field, "reads past the end of bufferViews[" + str(acc.bufferView) + "]: " + str(count) +
                          " elements from byteOffset " + str(acc.byteOffset) + " need " +
                          str(static_cast<std::size_t>(need)) + " bytes, the view has " + str(view_length));
        for (std::size_t i = 0; i < count; ++i) read(data + acc.byteOffset + i * stride, i);
      }
    } else if (!acc.sparse.isSparse && count > 0) {
      fail(field + ".bufferView", "missing (and the accessor is not sparse)");
    }

    if (acc.sparse.isSparse) {
      const std::string sfield = field + ".sparse";
      const int scount = acc.sparse.count;
      if (scount < 0 || static_cast<std::size_t>(scount) > count)
        fail(sfield + ".count", str(scount) + " is not in [0, " + str(count) + "]");
      const int itype = acc.sparse.indices.componentType;
      const int isize = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(itype));
      if (itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
          itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail(sfield + ".indices.componentType", componentTypeName(itype) + " is not an unsigned integer type");
      if (acc.sparse.indices.byteOffset < 0 || acc.sparse.values.byteOffset < 0)
        fail(sfield, "negative byteOffset");
      const auto [idata, ilength, istride] =
          bufferView(acc.sparse.indices.bufferView, sfield + ".indices.bufferView", static_cast<std::size_t>(isize));
      const auto [vdata, vlength, vstride] =
          bufferView(acc.sparse.values.bufferView, sfield + ".values.bufferView", element_size);
      (void)istride;
      (void)vstride;
      const auto ioff = static_cast<std::size_t>(acc.sparse.indices.byteOffset);
      const auto voff = static_cast<std::size_t>(acc.sparse.values.byteOffset);
      const auto n = static_cast<std::size_t>(scount);
      if (ioff + n * static_cast<std::size_t>(isize) > ilength)
        fail(sfield + ".indices", "reads past the end of its buffer view");
      if (voff + n * element_size > vlength) fail(sfield + ".values", "reads past the end of its buffer view");
      for (std::size_t s = 0; s < n; ++s) {
        const auto target = static_cast<std::size_t>(readComponent(idata + ioff + s * static_cast<std::size_t>(isize), itype, false));
        if (target >= count)
          fail(sfield + ".indices", "index " + str(target) + " is out of range (count " + str(count) + ")");
        read(vdata + voff + s * element_size, target);
      }
    }
    return values;
  }

  struct ViewBytes {
    const unsigned char* data;
    std::size_t length;
    std::size_t stride;
  };

  ViewBytes bufferView(int index, const std::string& usage, std::size_t default_stride) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model_.bufferViews.size())
      fail(usage, "buffer view " + str(index) + " out of range (the file has " + str(model_.bufferViews.size()) +
                      " buffer views)");
    const tinygltf::BufferView& view = model_.bufferViews[static_cast<std::size_t>(index)];
    const std::string field = indexed("bufferViews", static_cast<std::size_t>(index));
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model_.buffers.size())
      fail(field + ".buffer", "buffer " + str(view.buffer) + " out of range (the file has " +
                                  str(model_.buffers.size()) + " buffers)");
    const std::vector<unsigned char>& data = model_.buffers[static_cast<std::size_t>(view.buffer)].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
      fail(field, "byteOffset " + str(view.byteOffset) + " + byteLength " + str(view.byteLength) +
                      " runs past the end of buffers[" + str(view.buffer) + "] (" + str(data.size()) + " bytes)");
    return {data.data() + view.byteOffset, view.byteLength, view.byteStride ? view.byteStride : default_stride};
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
    const std::vector<double> xyz = readAccessor<double>(
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
      indices = readAccessor<std::uint32_t>(prim.indices, {TINYGLTF_TYPE_SCALAR},
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

  // --- materials ----------------------------------------------------------------------------------

  // A number in an extension object; `fallback` when the key is absent.
  double extNumber(const tinygltf::Value* obj, const char* key, double fallback, const std::string& field) const {
    if (!obj || !obj->IsObject() || !obj->Has(key)) return fallback;
    const tinygltf::Value& v = obj->Get(key);
    if (!v.IsNumber()) fail(field + "." + key, "is not a number");
    const double d = v.GetNumberAsDouble();
    if (!std::isfinite(d)) fail(field + "." + key, "is not finite");
    return d;
  }

  glm::dvec3 extColor(const tinygltf::Value* obj, const char* key, glm::dvec3 fallback, const std::string& field) const {
    if (!obj || !obj->IsObject() || !obj->Has(key)) return fallback;
    const tinygltf::Value& v = obj->Get(key);
    if (!v.IsArray() || v.ArrayLen() != 3) fail(field + "." + key, "is not an array of 3 numbers");
    glm::dvec3 c;
    for (int i = 0; i < 3; ++i) {
      const tinygltf::Value& e = v.Get(i);
      if (!e.IsNumber() || !std::isfinite(e.GetNumberAsDouble())) fail(field + "." + key, "is not an array of 3 numbers");
      c[i] = e.GetNumberAsDouble();
    }
    return c;
  }

  static const tinygltf::Value* extension(const tinygltf::ExtensionMap& map, const char* name) {
    auto it = map.find(name);
    return it != map.end() && it->second.IsObject() ? &it->second : nullptr;
  }

  Material material(int index) {
    auto cached = material_cache_.find(index);
    if (cached != material_cache_.end()) return cached->second;
    const tinygltf::Material& m = model_.materials[static_cast<std::size_t>(index)];
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
        extNumber(strength_ext, "emissiveStrength", 1.0, ext_field + "KHR_materials_emissive_strength");
    out.emission = glm::vec3(glm::max(emissive * strength, 0.0));

    const double transmission_factor =
        extNumber(transmission, "transmissionFactor", 0.0, ext_field + "KHR_materials_transmission");
    if (transmission_factor > 0.0) {
      double ior = extNumber(ior_ext, "ior", 1.5, ext_field + "KHR_materials_ior");
      if (ior < 1.0) {
        warn(ext_field + "KHR_materials_ior.ior: " + std::to_string(ior) + " < 1, using 1");
        ior = 1.0;
      }
      out.ior = static_cast<float>(ior);
      const std::string vfield = ext_field + "KHR_materials_volume";
      const glm::dvec3 color = extColor(volume, "attenuationColor", glm::dvec3(1.0), vfield);
      const double distance =
          extNumber(volume, "attenuationDistance", std::numeric_limits<double>::infinity(), vfield);
      if (distance > 0.0 && std::isfinite(distance)) {
        const glm::dvec3 c = glm::clamp(color, 1e-6, 1.0);
        out.sigma_a = glm::vec3(-glm::log(c) / distance);
      } else if (distance <= 0.0) {
        warn(vfield + ".attenuationDistance: " + std::to_string(distance) + " is not positive; no absorption");
      }
      const double dispersion = extNumber(dispersion_ext, "dispersion", 0.0, ext_field + "KHR_materials_dispersion");
      out.dispersion_b = static_cast<float>(0.523655 * (ior - 1.0) * std::max(dispersion, 0.0) / 20.0);
      out.opaque = false;
    } else {
      out.opaque = true;
    }
    material_cache_.emplace(index, out);
    return out;
  }

  // --- lights and cameras -------------------------------------------------------------------------

  void placeLight(const tinygltf::Node& node, const tinygltf::Value& ext, const std::string& field,
                  const glm::dmat4& world) {
    const std::string lfield = field + ".extensions.KHR_lights_punctual.light";
    if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber())
      fail(lfield, "missing or not a number");
    const int index = ext.Get("light").GetNumberAsInt();
    if (index < 0 || static_cast<std::size_t>(index) >= model_.lights.size())
      fail(lfield, "light " + str(index) + " out of range (the file has " + str(model_.lights.size()) + " lights)");
    const tinygltf::Light& l = model_.lights[static_cast<std::size_t>(index)];
    SceneLight light;
    if (l.type == "directional") light.type = SceneLight::Type::Directional;
    else if (l.type == "point") light.type = SceneLight::Type::Point;
    else if (l.type == "spot") light.type = SceneLight::Type::Spot;
    else {
      warn(indexed("KHR_lights_punctual.lights", static_cast<std::size_t>(index)) + ": type '" + l.type +
           "' skipped");
      return;
    }
    light.name = !l.name.empty() ? l.name : !node.name.empty() ? node.name : indexed("light", static_cast<std::size_t>(index));
    light.position = glm::dvec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    glm::dvec3 dir = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
    light.direction = glm::length(dir) > 0.0 ? glm::normalize(dir) : glm::dvec3(0.0, 0.0, -1.0);
    if (l.color.size() == 3) light.color = {l.color[0], l.color[1], l.color[2]};
    light.intensity = l.intensity;
    light.range = l.range;
    light.inner_cone_rad = l.spot.innerConeAngle;
    light.outer_cone_rad = l.spot.outerConeAngle;
    scene_.lights.push_back(light);
  }

  void placeCamera(const tinygltf::Node& node, const std::string& field, const glm::dmat4& world) {
    if (static_cast<std::size_t>(node.camera) >= model_.cameras.size())
      fail(field + ".camera", "camera " + str(node.camera) + " out of range (the file has " +
                                  str(model_.cameras.size()) + " cameras)");
    const tinygltf::Camera& c = model_.cameras[static_cast<std::size_t>(node.camera)];
    if (c.type != "perspective") {
      warn(indexed("cameras", static_cast<std::size_t>(node.camera)) + ": " + c.type + " camera skipped");
      return;
    }
    SceneCamera cam;
    cam.name = !c.name.empty() ? c.name : !node.name.empty() ? node.name : indexed("camera", static_cast<std::size_t>(node.camera));
    cam.eye = glm::dvec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    glm::dvec3 forward = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
    glm::dvec3 up = glm::dmat3(world) * glm::dvec3(0.0, 1.0, 0.0);
    if (!(glm::length(forward) > 0.0)) fail(field, "camera transform is singular");
    forward = glm::normalize(forward);
    up -= glm::dot(up, forward) * forward;  // orthonormalise (non-uniform scale)
    if (!(glm::length(up) > 0.0)) fail(field, "camera transform is singular");
    cam.up = glm::normalize(up);
    cam.target = cam.eye + forward;
    cam.fov_y_deg = glm::degrees(c.perspective.yfov);
    cam.aspect_ratio = c.perspective.aspectRatio;
    cam.znear = c.perspective.znear;
    cam.zfar = c.perspective.zfar;
    scene_.cameras.push_back(cam);
  }

  std::string file_;
  const tinygltf::Model& model_;
  MeshScene& scene_;
  std::vector<bool> on_path_;
  std::map<int, std::vector<PrimitiveMesh>> primitive_cache_;
  std::map<int, Material> material_cache_;
  std::map<std::string, int> name_uses_;
  std::set<std::string> warned_;
};

}  // namespace

MeshScene loadGltf(const std::filesystem::path& path) {
  const std::string file = path.string();
  const std::vector<unsigned char> bytes = readBytes(path);
  if (bytes.size() > std::numeric_limits<unsigned int>::max())
    throw InputError(file, "file", "larger than 4 GiB; glTF loading is limited to 4 GiB");
  std::filesystem::path base_dir = path.parent_path();
  if (base_dir.empty()) base_dir = ".";
  const bool glb = bytes.size() >= 4 && readU32(bytes.data()) == kGlbMagic;
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".glb" && !glb) {
    if (bytes.size() < 4) throw InputError(file, "glb header", "truncated: " + str(bytes.size()) + " bytes");
    throw InputError(file, "glb header", "not a binary glTF (magic is not 'glTF')");
  }

  if (glb) {
    const GlbParts parts = splitGlb(file, bytes);
    precheckJson(file, parts.json, base_dir, &parts);
  } else {
    if (bytes.empty()) throw InputError(file, "json", "the file is empty");
    precheckJson(file, std::string(bytes.begin(), bytes.end()), base_dir, nullptr);
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
