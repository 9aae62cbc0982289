// glTF loading: materials (Blender's glass export in particular), node transforms, lights,
// cameras, GLB, and broken files that must give an InputError naming the file and the field.
#include "voxelize/gltf_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/testing.h"
#include "voxelize/mesh_scene.h"
#include "voxelize/test_meshes.h"

namespace eik {
namespace {

using nlohmann::json;

std::string_view asChars(const std::vector<unsigned char>& bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

std::string base64(const std::vector<unsigned char>& data) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < data.size(); i += 3) {
    const std::uint32_t b = (std::uint32_t(data[i]) << 16) | (i + 1 < data.size() ? std::uint32_t(data[i + 1]) << 8 : 0) |
                            (i + 2 < data.size() ? std::uint32_t(data[i + 2]) : 0);
    out += table[(b >> 18) & 63];
    out += table[(b >> 12) & 63];
    out += i + 1 < data.size() ? table[(b >> 6) & 63] : '=';
    out += i + 2 < data.size() ? table[b & 63] : '=';
  }
  return out;
}

// {"primitives": [{"attributes": {"POSITION": position}, "indices": indices}]}
json meshJson(int position, int indices = -1) {
  json primitive = {{"attributes", {{"POSITION", position}}}};
  if (indices >= 0) primitive["indices"] = indices;
  return {{"primitives", json::array({primitive})}};
}

// Builds small glTF documents with one binary buffer.
class GltfBuilder {
 public:
  json doc = {{"asset", {{"version", "2.0"}}}, {"bufferViews", json::array()}, {"accessors", json::array()},
              {"meshes", json::array()}, {"nodes", json::array()}};
  std::vector<unsigned char> bin;

  int addView(const void* data, std::size_t bytes) {
    while (bin.size() % 4) bin.push_back(0);
    const std::size_t offset = bin.size();
    bin.resize(offset + bytes);
    std::memcpy(bin.data() + offset, data, bytes);
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
    return static_cast<int>(doc["bufferViews"].size() - 1);
  }
  int addAccessor(int view, int component_type, std::size_t count, const char* type) {
    doc["accessors"].push_back({{"bufferView", view}, {"componentType", component_type}, {"count", count}, {"type", type}});
    return static_cast<int>(doc["accessors"].size() - 1);
  }
  // A mesh primitive from a TriangleMesh (float positions, uint32 indices); returns the mesh index.
  int addMesh(const TriangleMesh& mesh, int material = -1, const std::string& name = "") {
    std::vector<float> xyz;
    for (const glm::dvec3& p : mesh.positions) xyz.insert(xyz.end(), {float(p.x), float(p.y), float(p.z)});
    std::vector<std::uint32_t> idx;
    for (const glm::uvec3& t : mesh.triangles) idx.insert(idx.end(), {t[0], t[1], t[2]});
    const int pos = addAccessor(addView(xyz.data(), xyz.size() * 4), 5126, mesh.positions.size(), "VEC3");
    const int ind = addAccessor(addView(idx.data(), idx.size() * 4), 5125, idx.size(), "SCALAR");
    json prim = {{"attributes", {{"POSITION", pos}}}, {"indices", ind}};
    if (material >= 0) prim["material"] = material;
    json m = {{"primitives", json::array({prim})}};
    if (!name.empty()) m["name"] = name;
    doc["meshes"].push_back(m);
    return static_cast<int>(doc["meshes"].size() - 1);
  }
  int addNode(const json& node) {
    doc["nodes"].push_back(node);
    return static_cast<int>(doc["nodes"].size() - 1);
  }
  void setScene(const std::vector<int>& roots) {
    doc["scenes"] = json::array({{{"nodes", roots}}});
    doc["scene"] = 0;
  }
  std::string embedded() const {
    json d = doc;
    if (!bin.empty())
      d["buffers"] = json::array({{{"byteLength", bin.size()},
                                   {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    return d.dump();
  }
  void writeExternal(const std::filesystem::path& gltf, const std::string& bin_name) const {
    json d = doc;
    d["buffers"] = json::array({{{"byteLength", bin.size()}, {"uri", bin_name}}});
    test_support::writeFile(gltf, d.dump());
    test_support::writeFile(gltf.parent_path() / bin_name, asChars(bin));
  }
  std::vector<unsigned char> glb() const {
    json d = doc;
    d["buffers"] = json::array({{{"byteLength", bin.size()}}});
    std::string text = d.dump();
    while (text.size() % 4) text.push_back(' ');
    std::vector<unsigned char> body = bin;
    while (body.size() % 4) body.push_back(0);
    std::vector<unsigned char> out;
    auto u32 = [&](std::uint32_t v) {
      for (int i = 0; i < 4; ++i) out.push_back(static_cast<unsigned char>(v >> (8 * i)));
    };
    u32(0x46546C67);
    u32(2);
    u32(static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + body.size()));
    u32(static_cast<std::uint32_t>(text.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), text.begin(), text.end());
    u32(static_cast<std::uint32_t>(body.size()));
    u32(0x004E4942);
    out.insert(out.end(), body.begin(), body.end());
    return out;
  }
};

class GltfLoader : public ::testing::Test {
 protected:
  std::filesystem::path write(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    test_support::writeFile(path, text);
    return path;
  }
  std::filesystem::path writeBytes(const std::string& name, const std::vector<unsigned char>& bytes) {
    const auto path = dir_ / name;
    test_support::writeFile(path, asChars(bytes));
    return path;
  }
  // Expects an InputError whose message names the file and contains every one of `parts`.
  void expectInputError(const std::filesystem::path& path, std::initializer_list<const char*> parts) {
    try {
      loadMeshFile(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;
      for (const char* part : parts) EXPECT_NE(message.find(part), std::string::npos) << message << " lacks " << part;
    }
  }

  test_support::TempDir dir_{"eikonal-gltf"};
};

// A closed tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) as float VEC3 + uint16 indices, base64.
constexpr const char* kTetraBuffer =
    "data:application/octet-stream;base64,"
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AAACAAEAAAABAAMAAAADAAIAAQACAAMA";

TEST_F(GltfLoader, BlenderGlassIsN15WithVolumeAbsorption) {
  // What Blender 3.4 writes for a glass material of IOR 1.5 (no KHR_materials_ior at 1.5).
  const std::string text = std::string(R"({
    "asset": {"version": "2.0", "generator": "Khronos glTF Blender I/O v3.4.50"},
    "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume"],
    "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"name": "Glass", "mesh": 0}],
    "materials": [{"name": "Glass",
      "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                     "KHR_materials_volume": {"attenuationColor": [1, 0.6065, 0.3679],
                                              "attenuationDistance": 1, "thicknessFactor": 2}},
      "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0}}],
    "meshes": [{"name": "Tetra", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,1]},
      {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
    "buffers": [{"byteLength": 72, "uri": ")") + kTetraBuffer + R"("}]
  })";
  const MeshScene scene = loadMeshFile(write("blender_glass.gltf", text));
  ASSERT_EQ(scene.meshes.size(), 1u);
  const TriangleMesh& mesh = scene.meshes[0];
  EXPECT_EQ(mesh.name, "Glass");
  EXPECT_EQ(mesh.triangleCount(), 4u);
  EXPECT_TRUE(mesh.isClosed());
  EXPECT_NEAR(mesh.signedVolume(), 1.0 / 6.0, 1e-6);
  const Material& m = mesh.material;
  EXPECT_FALSE(m.opaque);
  EXPECT_FLOAT_EQ(m.ior, 1.5f);
  EXPECT_NEAR(m.sigma_a.x, 0.0, 1e-3);
  EXPECT_NEAR(m.sigma_a.y, 0.5, 1e-3);
  EXPECT_NEAR(m.sigma_a.z, 1.0, 1e-3);
  EXPECT_EQ(m.dispersion_b, 0.0f);
  EXPECT_EQ(m.emission, glm::vec3(0.0f));
}

TEST_F(GltfLoader, MaterialExtensions) {
  GltfBuilder b;
  const TriangleMesh cube = makeBox({0, 0, 0}, {1, 1, 1});
  b.doc["materials"] = json::array({
      {{"name", "flint"},
       {"extensions",
        {{"KHR_materials_transmission", {{"transmissionFactor", 0.9}}},
         {"KHR_materials_ior", {{"ior", 1.7}}},
         {"KHR_materials_dispersion", {{"dispersion", 20.0 / 30.0}}},
         {"KHR_materials_volume", {{"attenuationColor", {0.5, 0.0, 1.0}}, {"attenuationDistance", 2.0}}},
         {"KHR_materials_emissive_strength", {{"emissiveStrength", 5.0}}}}},
       {"emissiveFactor", {1.0, 0.5, 0.0}}},
      {{"name", "red paint"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.1, 0.1, 1.0}}}},
       {"extensions", {{"KHR_materials_ior", {{"ior", 1.4}}}}}},
      {{"name", "clear, no volume"}, {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1}}}}}},
  });
  const int m0 = b.addMesh(cube, 0), m1 = b.addMesh(cube, 1), m2 = b.addMesh(cube, 2), m3 = b.addMesh(cube);
  b.setScene({b.addNode({{"mesh", m0}}), b.addNode({{"mesh", m1}}), b.addNode({{"mesh", m2}}), b.addNode({{"mesh", m3}})});
  const MeshScene scene = loadMeshFile(write("materials.gltf", b.embedded()));
  ASSERT_EQ(scene.meshes.size(), 4u);

  const Material& flint = scene.meshes[0].material;
  EXPECT_EQ(flint.name, "flint");
  EXPECT_FALSE(flint.opaque);
  EXPECT_FLOAT_EQ(flint.ior, 1.7f);
  EXPECT_NEAR(flint.dispersion_b, cauchyBFromAbbe(1.7f, 30.0f), 1e-6);
  EXPECT_NEAR(flint.dispersion_b, 0.523655 * 0.7 / 30.0, 1e-6);
  EXPECT_NEAR(flint.sigma_a.x, std::log(2.0) / 2.0, 1e-5);
  EXPECT_NEAR(flint.sigma_a.y, -std::log(1e-6) / 2.0, 1e-3);  // colour 0 clamped to 1e-6
  EXPECT_NEAR(flint.sigma_a.z, 0.0, 1e-7);
  EXPECT_NEAR(flint.emission.x, 5.0, 1e-6);
  EXPECT_NEAR(flint.emission.y, 2.5, 1e-6);
  EXPECT_NEAR(flint.emission.z, 0.0, 1e-6);

  const Material& red = scene.meshes[1].material;  // no transmission: opaque, ior ignored
  EXPECT_TRUE(red.opaque);
  EXPECT_NEAR(red.albedo.x, 0.8, 1e-6);
  EXPECT_NEAR(red.albedo.y, 0.1, 1e-6);

  const Material& clear = scene.meshes[2].material;  // transmission alone: n = 1.5, no absorption
  EXPECT_FALSE(clear.opaque);
  EXPECT_FLOAT_EQ(clear.ior, 1.5f);
  EXPECT_EQ(clear.sigma_a, glm::vec3(0.0f));

  const Material& none = scene.meshes[3].material;  // no material: glass n = 1.5 (docs/programs.md)
  EXPECT_FALSE(none.opaque);
  EXPECT_FLOAT_EQ(none.ior, 1.5f);
  EXPECT_EQ(none.name, "glass");
}

TEST_F(GltfLoader, NodeTransformsThroughTheHierarchy) {
  GltfBuilder b;
  const TriangleMesh box = makeBox({0, 0, 0}, {1, 2, 3});
  const int mesh = b.addMesh(box, -1, "Box");
  // child: matrix (translation 0,0,5); parent: TRS; grandparent: translation only.
  json matrix = json::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) matrix.push_back(c == r ? 1.0 : (c == 3 && r == 2 ? 5.0 : 0.0));
  const int child = b.addNode({{"name", "child"}, {"mesh", mesh}, {"matrix", matrix}});
  const double s = std::sqrt(0.5);
  const int parent = b.addNode({{"name", "parent"},
                                {"translation", {1.0, 2.0, 3.0}},
                                {"rotation", {0.0, 0.0, s, s}},  // 90° about z
                                {"scale", {2.0, 2.0, 2.0}},
                                {"children", {child}}});
  const int root = b.addNode({{"name", "root"}, {"translation", {0.0, 0.0, -1.0}}, {"children", {parent}}});
  const int mirrored = b.addNode({{"name", "mirrored"}, {"mesh", mesh}, {"scale", {-1.0, 1.0, 1.0}}});
  b.setScene({root, mirrored});
  const MeshScene scene = loadMeshFile(write("hierarchy.gltf", b.embedded()));
  ASSERT_EQ(scene.meshes.size(), 2u);
  EXPECT_EQ(scene.meshes[0].name, "child");
  EXPECT_EQ(scene.meshes[1].name, "mirrored");

  const glm::dmat4 expected = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, -1)) *
                              glm::translate(glm::dmat4(1.0), glm::dvec3(1, 2, 3)) *
                              glm::rotate(glm::dmat4(1.0), glm::radians(90.0), glm::dvec3(0, 0, 1)) *
                              glm::scale(glm::dmat4(1.0), glm::dvec3(2.0)) *
                              glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, 5));
  for (std::size_t v = 0; v < box.positions.size(); ++v) {
    const glm::dvec3 want = glm::dvec3(expected * glm::dvec4(box.positions[v], 1.0));
    EXPECT_NEAR(glm::length(scene.meshes[0].positions[v] - want), 0.0, 1e-5) << v;
  }
  EXPECT_NEAR(scene.meshes[0].signedVolume(), 6.0 * 8.0, 1e-4);  // uniform scale 2
  // A mirroring transform keeps the normals outward.
  EXPECT_NEAR(scene.meshes[1].signedVolume(), 6.0, 1e-5);
  EXPECT_LT(scene.meshes[1].bounds().max.x, 1e-6);
}

TEST_F(GltfLoader, LightsAndCamerasInWorldSpace) {
  GltfBuilder b;
  const int mesh = b.addMesh(makeBox({0, 0, 0}, {1, 1, 1}));
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"] = {
      {"KHR_lights_punctual",
       {{"lights", json::array({{{"type", "directional"}, {"name", "sun"}, {"color", {1.0, 0.9, 0.8}}, {"intensity", 3.5}},
                                {{"type", "point"}, {"name", "bulb"}, {"intensity", 40.0}, {"range", 10.0}}})}}}};
  b.doc["cameras"] = json::array(
      {{{"type", "perspective"}, {"name", "cam"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"aspectRatio", 1.5}}}}});
  const double s = std::sqrt(0.5);
  // The sun node is rotated −90° about x: its −Z axis points down (−Y).
  const int sun = b.addNode({{"rotation", {-s, 0.0, 0.0, s}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  const int bulb = b.addNode({{"translation", {1.0, 2.0, 3.0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  const int cam = b.addNode({{"translation", {0.0, 1.0, 5.0}}, {"camera", 0}});
  const int group = b.addNode({{"translation", {10.0, 0.0, 0.0}}, {"children", {bulb}}});
  b.setScene({b.addNode({{"mesh", mesh}}), sun, group, cam});
  const MeshScene scene = loadMeshFile(write("lights.gltf", b.embedded()));

  ASSERT_EQ(scene.lights.size(), 2u);
  const SceneLight& sunlight = scene.lights[0];
  EXPECT_EQ(sunlight.type, SceneLight::Type::Directional);
  EXPECT_EQ(sunlight.name, "sun");
  EXPECT_NEAR(glm::length(sunlight.direction - glm::dvec3(0, -1, 0)), 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(sunlight.intensity, 3.5);  // lux, unconverted
  EXPECT_NEAR(sunlight.color.y, 0.9, 1e-12);
  const SceneLight& point = scene.lights[1];
  EXPECT_EQ(point.type, SceneLight::Type::Point);
  EXPECT_NEAR(glm::length(point.position - glm::dvec3(11, 2, 3)), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(point.intensity, 40.0);  // candela
  EXPECT_DOUBLE_EQ(point.range, 10.0);
  EXPECT_EQ(point.color, glm::dvec3(1.0));

  ASSERT_EQ(scene.cameras.size(), 1u);
  const SceneCamera& camera = scene.cameras[0];
  EXPECT_EQ(camera.name, "cam");
  EXPECT_NEAR(glm::length(camera.eye - glm::dvec3(0, 1, 5)), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(camera.target - glm::dvec3(0, 1, 4)), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(camera.up - glm::dvec3(0, 1, 0)), 0.0, 1e-12);
  EXPECT_NEAR(camera.fov_y_deg, 0.5 * 180.0 / 3.141592653589793, 1e-9);
  EXPECT_DOUBLE_EQ(camera.aspect_ratio, 1.5);
}

TEST_F(GltfLoader, NonTriangleModesAreSkippedWithAWarning) {
  GltfBuilder b;
  const int mesh = b.addMesh(makeBox({0, 0, 0}, {1, 1, 1}));
  json lines = b.doc["meshes"][mesh]["primitives"][0];
  lines["mode"] = 1;  // LINES
  b.doc["meshes"][mesh]["primitives"].push_back(lines);
  json strip = b.doc["meshes"][mesh]["primitives"][0];
  strip["mode"] = 5;  // TRIANGLE_STRIP over the same indices: unrolled into triangles
  b.doc["meshes"][mesh]["primitives"].push_back(strip);
  b.setScene({b.addNode({{"mesh", mesh}, {"name", "n"}})});
  const MeshScene scene = loadMeshFile(write("modes.gltf", b.embedded()));
  ASSERT_EQ(scene.meshes.size(), 2u);
  EXPECT_EQ(scene.meshes[0].name, "n#0");
  EXPECT_EQ(scene.meshes[1].name, "n#2");
  ASSERT_FALSE(scene.warnings.empty());
  EXPECT_NE(scene.warnings[0].find("meshes[0].primitives[1]: mode LINES skipped"), std::string::npos)
      << scene.warnings[0];
}

TEST_F(GltfLoader, GlbAndExternalBuffersLoadLikeEmbedded) {
  GltfBuilder b;
  const TriangleMesh sphere = makeUvSphere(glm::dvec3(0.5, 0, 0), 1.0, 16, 8);
  b.setScene({b.addNode({{"mesh", b.addMesh(sphere, -1, "ball")}})});
  b.writeExternal(dir_ / "external.gltf", "external data.bin");  // a space: percent-encoding is not needed
  const MeshScene from_glb = loadMeshFile(writeBytes("binary.glb", b.glb()));
  const MeshScene from_external = loadMeshFile(dir_ / "external.gltf");
  const MeshScene from_embedded = loadMeshFile(write("embedded.gltf", b.embedded()));
  for (const MeshScene* scene : {&from_glb, &from_external, &from_embedded}) {
    ASSERT_EQ(scene->meshes.size(), 1u);
    EXPECT_EQ(scene->meshes[0].name, "ball");
    EXPECT_EQ(scene->meshes[0].triangles, sphere.triangles);
    EXPECT_NEAR(scene->meshes[0].signedVolume(), sphere.signedVolume(), 1e-5);
  }
}

// --- broken input ---------------------------------------------------------------------------------

TEST_F(GltfLoader, TruncatedGlbIsAnInputError) {
  GltfBuilder b;
  b.setScene({b.addNode({{"mesh", b.addMesh(makeBox({0, 0, 0}, {1, 1, 1}))}})});
  std::vector<unsigned char> glb = b.glb();
  glb.resize(glb.size() - 10);
  expectInputError(writeBytes("truncated.glb", glb), {"glb", "truncated"});
  // Any cut, anywhere, is an InputError (or, cut at a chunk boundary, a valid file) — never a crash.
  const std::vector<unsigned char> whole = b.glb();
  for (std::size_t cut = 0; cut < whole.size(); cut += cut < 32 ? 1 : 17) {
    const auto path = writeBytes("cut.glb", std::vector<unsigned char>(whole.begin(), whole.begin() + cut));
    try {
      loadMeshFile(path);
    } catch (const InputError&) {
    }
  }
}

// A hierarchy is walked with an explicit stack: a chain of 10⁵ nodes (which overflowed the call
// stack of the recursive walk) is refused past the depth limit with the node named, and a chain
// within the limit loads with its transforms composed.
TEST_F(GltfLoader, DeepNodeChainIsRefusedWithoutACrash) {
  for (const int length : {100000, 1000}) {
    GltfBuilder b;
    const int mesh = b.addMesh(makeBox({0, 0, 0}, {1, 1, 1}), -1, "Box");
    int child = b.addNode({{"mesh", mesh}});
    for (int i = 1; i < length; ++i) child = b.addNode({{"translation", {0.001, 0.0, 0.0}}, {"children", {child}}});
    b.setScene({child});
    const std::filesystem::path file = write("chain.gltf", b.embedded());
    if (length > 1024) {
      expectInputError(file, {"nodes[", "deeper than 1024 levels"});
    } else {
      const MeshScene scene = loadMeshFile(file);
      ASSERT_EQ(scene.meshes.size(), 1u);
      EXPECT_NEAR(scene.meshes[0].bounds().min.x, 0.001 * (length - 1), 1e-6);
    }
  }
}

TEST_F(GltfLoader, TruncatedJsonIsAnInputError) {
  GltfBuilder b;
  b.setScene({b.addNode({{"mesh", b.addMesh(makeBox({0, 0, 0}, {1, 1, 1}))}})});
  const std::string text = b.embedded();
  expectInputError(write("truncated.gltf", text.substr(0, text.size() / 2)), {"json", "parse error"});
  for (std::size_t cut = 0; cut < text.size(); cut += 23) {
    try {
      loadMeshFile(write("cut.gltf", text.substr(0, cut)));
    } catch (const InputError&) {
    }
  }
}

TEST_F(GltfLoader, IndexOutOfRangeIsAnInputError) {
  GltfBuilder b;
  const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::vector<std::uint16_t> idx = {0, 1, 7};
  const int pos = b.addAccessor(b.addView(xyz.data(), 36), 5126, 3, "VEC3");
  const int ind = b.addAccessor(b.addView(idx.data(), 6), 5123, 3, "SCALAR");
  b.doc["meshes"].push_back(meshJson(pos, ind));
  b.setScene({b.addNode({{"mesh", 0}})});
  expectInputError(write("bad_index.gltf", b.embedded()), {"accessors[1]", "index 7", "out of range"});

  // An accessor index that does not exist.
  b.doc["meshes"][0]["primitives"][0]["indices"] = 9;
  expectInputError(write("bad_accessor.gltf", b.embedded()), {"accessor"});
  // A node pointing at a missing mesh.
  b.doc["meshes"][0]["primitives"][0]["indices"] = ind;
  b.doc["nodes"][0]["mesh"] = 4;
  expectInputError(write("bad_mesh.gltf", b.embedded()), {"mesh"});
}

TEST_F(GltfLoader, MissingExternalBufferIsAnInputError) {
  GltfBuilder b;
  b.setScene({b.addNode({{"mesh", b.addMesh(makeBox({0, 0, 0}, {1, 1, 1}))}})});
  b.writeExternal(dir_ / "scene.gltf", "scene.bin");
  std::filesystem::remove(dir_ / "scene.bin");
  expectInputError(dir_ / "scene.gltf", {"buffers[0].uri", "scene.bin", "not found"});
}

TEST_F(GltfLoader, AccessorPastItsBufferViewIsAnInputError) {
  GltfBuilder b;
  const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const int view = b.addView(xyz.data(), 36);
  b.addAccessor(view, 5126, 100, "VEC3");  // 1200 bytes from a 36-byte view
  b.doc["meshes"].push_back(meshJson(0));
  b.setScene({b.addNode({{"mesh", 0}})});
  expectInputError(write("past_view.gltf", b.embedded()), {"accessors[0]", "past the end of bufferViews[0]"});

  // A buffer view past its buffer.
  b.doc["accessors"][0]["count"] = 3;
  b.doc["bufferViews"][0]["byteLength"] = 400;
  expectInputError(write("past_buffer.gltf", b.embedded()), {"bufferView"});

  // A wrong component type for positions.
  b.doc["bufferViews"][0]["byteLength"] = 36;
  b.doc["accessors"][0]["componentType"] = 5125;
  expectInputError(write("bad_type.gltf", b.embedded()), {"accessors[0].componentType", "UNSIGNED_INT"});
}

TEST_F(GltfLoader, EmptyMeshIsAnInputError) {
  GltfBuilder b;
  b.setScene({});
  expectInputError(write("empty.gltf", b.embedded()), {"meshes", "empty"});
  // A mesh whose only primitive has no triangles.
  const std::vector<float> xyz = {0, 0, 0, 1, 0, 0};
  const int pos = b.addAccessor(b.addView(xyz.data(), 24), 5126, 2, "VEC3");
  b.doc["meshes"].push_back(meshJson(pos));
  b.setScene({b.addNode({{"mesh", 0}})});
  expectInputError(write("no_triangles.gltf", b.embedded()), {"meshes", "empty"});
}

TEST_F(GltfLoader, UnknownExtensionIsAnInputError) {
  expectInputError(write("mesh.ply", "ply\n"), {"extension", ".ply"});
  expectInputError(dir_ / "does_not_exist.gltf", {"cannot be opened"});
}

}  // namespace
}  // namespace eik
