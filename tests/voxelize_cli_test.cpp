// `voxelize` as a user runs it: outputs, --stats, SCENE.json from glTF lights and cameras, and
// exit code 2 with a clear message and no output files for every kind of bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/volume.h"
#include "tests/program_runner.h"

namespace eik::test {
namespace {

using nlohmann::json;

ProgramResult voxelize(const TempDir& dir, std::vector<std::string> args) {
  args.push_back("--quiet");
  return runProgram(VOXELIZE_EXE, args, dir.path());
}

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    unsigned v = (unsigned(uint8_t(bytes[i])) << 16) | (unsigned(uint8_t(bytes[i + 1])) << 8) | uint8_t(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += table[(v >> (6 * k)) & 63];
  }
  if (i + 1 == bytes.size()) {
    unsigned v = unsigned(uint8_t(bytes[i])) << 16;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    unsigned v = (unsigned(uint8_t(bytes[i])) << 16) | (unsigned(uint8_t(bytes[i + 1])) << 8);
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

// A glTF cube of side 1 (outward-facing triangles), a directional light of 683 lux (1 W/m²) shining
// down and a camera, all in one .gltf with an embedded buffer.
std::string cubeGltf() {
  const float p[8][3] = {{-.5f, -.5f, -.5f}, {.5f, -.5f, -.5f}, {.5f, .5f, -.5f}, {-.5f, .5f, -.5f},
                         {-.5f, -.5f, .5f},  {.5f, -.5f, .5f},  {.5f, .5f, .5f},  {-.5f, .5f, .5f}};
  const uint16_t idx[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                            3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
  std::string bytes(reinterpret_cast<const char*>(p), sizeof p);
  bytes += std::string(reinterpret_cast<const char*>(idx), sizeof idx);
  json j = {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"KHR_lights_punctual", "KHR_materials_transmission", "KHR_materials_volume"}},
      {"extensions",
       {{"KHR_lights_punctual",
         {{"lights", {{{"type", "directional"}, {"intensity", 683.0}, {"color", {1.0, 0.5, 0.25}}}}}}}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0, 1, 2}}}}},
      {"nodes",
       {{{"mesh", 0}},
        // rotated -90° about X: the light's -Z axis points down (-Y)
        {{"rotation", {-0.7071067811865476, 0.0, 0.0, 0.7071067811865476}},
         {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}},
        {{"camera", 0}, {"translation", {0.0, 0.0, 4.0}}}}},
      {"cameras", {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}}},
      {"materials",
       {{{"name", "glass"},
         {"extensions",
          {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
           {"KHR_materials_volume",
            {{"attenuationColor", {1.0, 0.6065, 0.3679}}, {"attenuationDistance", 1.0}, {"thicknessFactor", 2.0}}}}}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}, {"material", 0}}}}}}},
      {"buffers", {{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}}},
      {"bufferViews",
       {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", sizeof p}},
        {{"buffer", 0}, {"byteOffset", sizeof p}, {"byteLength", sizeof idx}}}},
      {"accessors",
       {{{"bufferView", 0}, {"componentType", 5126}, {"count", 8}, {"type", "VEC3"},
         {"min", {-.5, -.5, -.5}}, {"max", {.5, .5, .5}}},
        {{"bufferView", 1}, {"componentType", 5123}, {"count", 36}, {"type", "SCALAR"}}}}};
  return j.dump(1);
}

TEST(VoxelizeCli, HelpListsEveryFlag) {
  TempDir dir;
  ProgramResult r = runProgram(VOXELIZE_EXE, {"--help"}, dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  for (const char* flag : {"--res", "--bounds", "--pad", "--smooth", "--material", "--stats", "--quiet", "-o"})
    EXPECT_NE(r.output.find(flag), std::string::npos) << flag;
  ProgramResult shapes = runProgram(VOXELIZE_EXE, {"--list-shapes"}, dir.path());
  EXPECT_EQ(shapes.exit_code, 0);
  for (const char* shape : {"sphere", "box", "rounded_cube", "layered_cube", "wine_glass", "logo_block", "luneburg",
                            "gradient_slab", "floor"})
    EXPECT_NE(shapes.output.find(shape), std::string::npos) << shape;
}

TEST(VoxelizeCli, ProceduralSphereWritesAVolumeAndStats) {
  TempDir dir;
  ProgramResult r = voxelize(dir, {"procedural:sphere,r=0.5,ior=1.5,sigma_a=0:0.5:1", "-o", "ball.vol.json", "--res",
                                   "32", "--stats", "stats.json"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Volume v = readVolume(dir / "ball.vol.json");
  EXPECT_TRUE(v.has("ior") && v.has("sigma_a"));
  // Sharp (the default) and of one constant n: one distance a voxel, no ∇n (0 throughout).
  EXPECT_FALSE(v.has("ior_grad"));
  EXPECT_EQ(v.fields.at("interfaces").components, 1);
  EXPECT_EQ(v.grid.dims.x, 32 + 2 * 3);  // --res on the longest axis plus 3 voxels of padding per side
  json stats = json::parse(readFile(dir / "stats.json"));
  EXPECT_GT(stats["time_total_s"].get<double>(), 0.0);
  EXPECT_EQ(stats["voxels"].get<std::size_t>(), v.grid.count());
  EXPECT_GT(stats["peak_memory_mib"].get<double>(), 1.0);
  ASSERT_EQ(stats["materials"].size(), 1u);
  const double inside = stats["materials"][0]["volume"].get<double>();
  EXPECT_NEAR(inside, 4.0 / 3.0 * M_PI * 0.125, 0.02 * 4.0 / 3.0 * M_PI * 0.125);
}

TEST(VoxelizeCli, GltfLightsAndCamerasGoIntoASceneFile) {
  TempDir dir;
  writeFile(dir / "cube.gltf", cubeGltf());
  ProgramResult r = voxelize(dir, {"cube.gltf", "-o", "cube.vol.json", "--res", "24"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  json scene = json::parse(readFile(dir / "cube.scene.json"));
  ASSERT_EQ(scene["lights"].size(), 1u);
  const json& light = scene["lights"][0];
  EXPECT_EQ(light["type"], "directional");
  // 683 lux of colour (1, 0.5, 0.25) is 1 W/m² times the colour.
  EXPECT_NEAR(light["irradiance"][0].get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(light["irradiance"][1].get<double>(), 0.5, 1e-9);
  EXPECT_NEAR(light["direction"][1].get<double>(), -1.0, 1e-6);
  EXPECT_NEAR(scene["camera"]["eye"][2].get<double>(), 4.0, 1e-9);
  EXPECT_NEAR(scene["camera"]["fov_y_deg"].get<double>(), 0.5 * 180.0 / M_PI, 1e-6);
  EXPECT_EQ(scene["objects"][0]["volume"], "cube.vol.json");
  // The Blender-style glass: n = 1.5 and σa = (0, 0.5, 1) deep inside the cube.
  Volume v = readVolume(dir / "cube.vol.json");
  const GridSpec& g = v.grid;
  std::size_t c = g.index(g.dims.x / 2, g.dims.y / 2, g.dims.z / 2);
  EXPECT_NEAR(v.fields.at("ior").data[c], 1.5f, 1e-3f);
  EXPECT_NEAR(v.fields.at("sigma_a").voxel(c)[0], 0.0f, 1e-3f);
  EXPECT_NEAR(v.fields.at("sigma_a").voxel(c)[1], 0.5f, 1e-3f);
  EXPECT_NEAR(v.fields.at("sigma_a").voxel(c)[2], 1.0f, 1e-3f);
}

TEST(VoxelizeCli, MaterialOverridesObjAndProceduralInputs) {
  TempDir dir;
  writeFile(dir / "tet.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  ProgramResult r = voxelize(dir, {"tet.obj", "--material", "ior=1.7,sigma_a=0.1:0.2:0.3", "-o", "t.vol.json", "--res", "24"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Volume v = readVolume(dir / "t.vol.json");
  ASSERT_TRUE(v.metadata.contains("materials"));
  EXPECT_NEAR(v.metadata["materials"][0]["ior"].get<double>(), 1.7, 1e-6);
  // Per-input overrides: the i-th --material goes with the i-th OBJ/procedural input.
  r = voxelize(dir, {"procedural:sphere,r=0.3", "procedural:box,size=1:1:1", "--material", "ior=1.3", "--material",
                     "ior=1.6", "-o", "two.vol.json", "--res", "24"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Volume two = readVolume(dir / "two.vol.json");
  // The sphere is inside the box: the innermost wins, so the centre has the sphere's n.
  const GridSpec& g = two.grid;
  EXPECT_NEAR(two.fields.at("ior").data[g.index(g.dims.x / 2, g.dims.y / 2, g.dims.z / 2)], 1.3f, 1e-3f);
  EXPECT_NEAR(two.fields.at("ior").data[g.index(g.dims.x / 2, g.dims.y / 2, 5)], 1.6f, 1e-3f);
}

struct BadCase {
  const char* name;
  std::vector<std::string> args;
  const char* file_name;      // written into the temp dir first when not null
  std::string file_content;
  const char* expected;       // must appear in the message
};

// gtest prints a parameter in test names and failures: show its name, not its bytes.
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name; }

class VoxelizeBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(VoxelizeBadInput, ExitsTwoNamingTheProblemAndWritesNothing) {
  const BadCase& c = GetParam();
  TempDir dir;
  if (c.file_name) writeFile(dir / c.file_name, c.file_content);
  const auto before = dir.entries();
  ProgramResult r = voxelize(dir, c.args);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in: " << r.output;
  EXPECT_EQ(dir.entries(), before) << "a failed run left files behind";
  EXPECT_EQ(r.output.find("terminate"), std::string::npos) << r.output;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, VoxelizeBadInput,
    ::testing::Values(
        BadCase{"NoInput", {"-o", "x.vol.json"}, nullptr, "", "no input"},
        BadCase{"NoOutput", {"procedural:sphere"}, nullptr, "", "-o"},
        BadCase{"OutputNotManifest", {"procedural:sphere", "-o", "x.nrrd"}, nullptr, "", ".vol.json"},
        BadCase{"OutputDirMissing", {"procedural:sphere", "-o", "nowhere/x.vol.json"}, nullptr, "", "does not exist"},
        BadCase{"UnknownShape", {"procedural:teapot", "-o", "x.vol.json"}, nullptr, "", "teapot"},
        BadCase{"UnknownShapeKey", {"procedural:sphere,radius=2", "-o", "x.vol.json"}, nullptr, "", "radius"},
        BadCase{"BadNumber", {"procedural:sphere,r=abc", "-o", "x.vol.json"}, nullptr, "", "abc"},
        BadCase{"ZeroRes", {"procedural:sphere", "-o", "x.vol.json", "--res", "0"}, nullptr, "", "--res"},
        BadCase{"BadBounds", {"procedural:sphere", "-o", "x.vol.json", "--bounds", "1,2,3"}, nullptr, "", "--bounds"},
        BadCase{"BadMaterial", {"procedural:sphere", "-o", "x.vol.json", "--material", "ior=0.5"}, nullptr, "", "ior"},
        BadCase{"UnknownMaterialKey", {"procedural:sphere", "-o", "x.vol.json", "--material", "colour=1"}, nullptr, "",
                "colour"},
        BadCase{"MissingMesh", {"nothere.obj", "-o", "x.vol.json"}, nullptr, "", "nothere.obj"},
        BadCase{"UnknownExtension", {"mesh.stl", "-o", "x.vol.json"}, "mesh.stl", "solid x\n", "mesh.stl"},
        BadCase{"ObjBadIndex", {"bad.obj", "-o", "x.vol.json"}, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
                "bad.obj"},
        BadCase{"ObjNotANumber", {"bad.obj", "-o", "x.vol.json"}, "bad.obj", "v 0 zero 0\n", "bad.obj"},
        BadCase{"GltfTruncated", {"bad.gltf", "-o", "x.vol.json"}, "bad.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"mes",
                "bad.gltf"},
        BadCase{"GlbTruncated", {"bad.glb", "-o", "x.vol.json"}, "bad.glb", std::string("glTF\x02\0\0\0", 8), "bad.glb"},
        BadCase{"GltfMissingBuffer",
                {"bad.gltf", "-o", "x.vol.json"},
                "bad.gltf",
                R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
                    "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
                    "buffers":[{"byteLength":36,"uri":"missing.bin"}],
                    "bufferViews":[{"buffer":0,"byteLength":36}],
                    "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}]})",
                "missing.bin"}),
    [](const ::testing::TestParamInfo<BadCase>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace eik::test
