// `lightsim` as a user runs it: a bake on both back ends adds irradiance and light_dir with the
// light and statistics in the manifest; bad input exits 2 with a clear message and no output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/volume.h"
#include "tests/program_runner.h"

namespace eik::test {
namespace {

// A smoothed ball (the thesis' mode, which the GPU path bakes) and, with `sharp`, one with sharp
// interfaces (voxelize's default).
void makeSphere(const TempDir& dir, bool sharp = false) {
  ProgramResult r = runProgram(VOXELIZE_EXE,
                               {"procedural:sphere,r=0.5,ior=1.5,sigma_a=0.2:0.4:0.8", "-o",
                                sharp ? "sharp.vol.json" : "ball.vol.json", "--res", "16", "--interfaces",
                                sharp ? "sharp" : "smooth", "--quiet"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
}

TEST(LightsimCli, BakesOnBothBackends) {
  TempDir dir;
  makeSphere(dir);
  for (const char* backend : {"cpu", "gl"}) {
    const std::string out = std::string("baked_") + backend + ".vol.json";
    ProgramResult r = runProgram(LIGHTSIM_EXE,
                                 {"ball.vol.json", "-o", out, "--light", "directional:0,-1,0", "--power", "2,2,2",
                                  "--backend", backend, "--deposit-kernel", "point", "--max-depth", "3", "--at-max-depth",
                                  "kill", "--stats", "stats.json", "--quiet"},
                                 dir.path());
    ASSERT_EQ(r.exit_code, 0) << backend << ": " << r.output;
    Volume v = readVolume(dir / out);
    ASSERT_TRUE(v.has("irradiance") && v.has("light_dir") && v.has("sigma_a")) << backend;
    // Above the sphere the plane wave arrives untouched: irradiance ≈ the light's 2 W/m² in
    // accumulate mode (scalar irradiance of one sheet), travelling straight down.
    const GridSpec& g = v.grid;
    const std::size_t top = g.index(g.dims.x / 2, g.dims.y - 2, g.dims.z / 2);
    EXPECT_NEAR(v.fields.at("irradiance").voxel(top)[0], 2.0f, 0.3f) << backend;
    EXPECT_NEAR(v.fields.at("light_dir").voxel(top)[1], -1.0f, 1e-3f) << backend;
    EXPECT_EQ(v.metadata["light"]["type"], "directional");
    EXPECT_EQ(v.metadata["bake_options"]["max_depth"], 3);  // what the viewer window re-bakes with
    nlohmann::json stats = nlohmann::json::parse(readFile(dir / "stats.json"));
    EXPECT_GT(stats["steps"].get<int>(), 0);
    EXPECT_EQ(stats["backend"], backend);
  }
}

// --backend auto takes the CPU twin on a software rasterizer (llvmpipe) or a machine without a GPU
// device (this project's CI machines), and says so.
TEST(LightsimCli, AutoBackendPicksTheTwinOnASoftwareRasterizer) {
  TempDir dir;
  makeSphere(dir);
  ProgramResult r = runProgram(LIGHTSIM_EXE,
                               {"ball.vol.json", "-o", "auto.vol.json", "--light", "directional:0,-1,0", "--backend",
                                "auto", "--deposit-kernel", "point", "--max-depth", "2", "--stats", "auto.json"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("--backend auto:"), std::string::npos) << r.output;
  nlohmann::json stats = nlohmann::json::parse(readFile(dir / "auto.json"));
  const bool software = r.output.find("llvmpipe") != std::string::npos ||
                        r.output.find("no OpenGL context") != std::string::npos ||
                        r.output.find("no GPU device") != std::string::npos;
  EXPECT_EQ(stats["backend"], software ? "cpu" : "gl") << r.output;
}

// The GPU path bakes sharp interfaces with track deposits and a receiver map (the CPU twin's
// defaults); what it cannot do — a receiver map with point deposits — auto leaves to the twin and
// says why, and an explicit --backend gl refuses (exit 2) before any work.
TEST(LightsimCli, TheGpuPathBakesSharpInterfacesAndRefusesWhatItCannotDo) {
  TempDir dir;
  makeSphere(dir, true);
  ProgramResult r = runProgram(LIGHTSIM_EXE,
                               {"sharp.vol.json", "-o", "g.vol.json", "--light", "directional:0,-1,0", "--backend", "gl",
                                "--max-depth", "2", "--receiver", "0,-0.7,0:0,1,0", "--stats", "g.json"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json stats = nlohmann::json::parse(readFile(dir / "g.json"));
  EXPECT_EQ(stats["backend"], "gl");
  EXPECT_NE(r.output.find("lightsim: receiver '"), std::string::npos) << r.output;
  r = runProgram(LIGHTSIM_EXE,
                 {"sharp.vol.json", "-o", "p.vol.json", "--light", "directional:0,-1,0", "--max-depth", "2",
                  "--deposit-kernel", "point", "--receiver", "0,-0.7,0:0,1,0", "--stats", "p.json"},
                 dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the GPU path does not do receiver maps with point deposits"), std::string::npos) << r.output;
  EXPECT_EQ(nlohmann::json::parse(readFile(dir / "p.json"))["backend"], "cpu");
  r = runProgram(LIGHTSIM_EXE,
                 {"sharp.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0", "--backend", "gl",
                  "--deposit-kernel", "point", "--receiver", "0,-0.7,0:0,1,0"},
                 dir.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--backend: gl: the GPU path does not do receiver maps with point deposits"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.vol.json"));
}

// --smooth-irradiance is a normalised filter: the light's total stays (the sphere sits well inside
// its grid, so little lies near the faces), the voxel-to-voxel grain goes, and the manifest says so.
TEST(LightsimCli, SmoothedIrradianceKeepsTheTotalAndLosesTheGrain) {
  TempDir dir;
  makeSphere(dir);
  for (const char* sigma : {"0", "1"}) {
    ProgramResult r = runProgram(LIGHTSIM_EXE,
                                 {"ball.vol.json", "-o", std::string("s") + sigma + ".vol.json", "--light",
                                  "directional:0.3,-1,0.2", "--backend", "cpu", "--deposit-kernel", "point",
                                  "--smooth-irradiance", sigma, "--quiet"},
                                 dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const Volume raw = readVolume(dir / "s0.vol.json"), smooth = readVolume(dir / "s1.vol.json");
  EXPECT_FALSE(raw.metadata.contains("irradiance_smoothing_sigma_voxels"));
  EXPECT_EQ(smooth.metadata["irradiance_smoothing_sigma_voxels"], 1.0);
  const GridSpec& g = raw.grid;
  double total_raw = 0.0, total_smooth = 0.0, grain_raw = 0.0, grain_smooth = 0.0;
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x + 1 < g.dims.x; ++x) {
        const float* a = raw.fields.at("irradiance").voxel(g.index(x, y, z));
        const float* b = smooth.fields.at("irradiance").voxel(g.index(x, y, z));
        total_raw += a[1];
        total_smooth += b[1];
        grain_raw += std::abs(raw.fields.at("irradiance").voxel(g.index(x + 1, y, z))[1] - a[1]);
        grain_smooth += std::abs(smooth.fields.at("irradiance").voxel(g.index(x + 1, y, z))[1] - b[1]);
      }
  EXPECT_NEAR(total_smooth, total_raw, 0.03 * total_raw);
  EXPECT_LT(grain_smooth, 0.7 * grain_raw);
}

TEST(LightsimCli, BenchRepeatsTheBakeAndReportsItsFigures) {
  TempDir dir;
  makeSphere(dir);
  for (const char* backend : {"cpu", "gl"}) {
    ProgramResult r = runProgram(LIGHTSIM_EXE,
                                 {"ball.vol.json", "-o", "b.vol.json", "--light", "directional:0,-1,0", "--backend",
                                  backend, "--deposit-kernel", "point", "--max-depth", "2", "--bench", "3", "--stats",
                                  "bench.json", "--quiet"},
                                 dir.path());
    ASSERT_EQ(r.exit_code, 0) << backend << ": " << r.output;
    EXPECT_NE(r.output.find("lightsim bench:"), std::string::npos) << r.output;
    nlohmann::json stats = nlohmann::json::parse(readFile(dir / "bench.json"));
    const nlohmann::json& bench = stats.at("bench");
    EXPECT_EQ(bench.at("runs"), 3);
    ASSERT_EQ(bench.at("seconds").size(), 3u);
    std::vector<double> seconds = bench.at("seconds").get<std::vector<double>>();
    std::sort(seconds.begin(), seconds.end());
    EXPECT_EQ(bench.at("median_s").get<double>(), seconds[1]);
    EXPECT_NEAR(bench.at("patch_steps_per_s").get<double>(),
                stats.at("total_patches").get<double>() / seconds[1], 1e-6 * bench.at("patch_steps_per_s").get<double>());
    // Texture memory is reported for the GPU path only: at least the patch lists and the atlas.
    if (std::string(backend) == "gl") {
      EXPECT_GT(stats.at("texture_bytes").at("patch_lists_peak").get<double>(), 0.0);
      EXPECT_GE(stats.at("texture_bytes").at("total_peak").get<double>(),
                stats.at("texture_bytes").at("atlas").get<double>() + stats.at("texture_bytes").at("volume").get<double>());
    } else {
      EXPECT_FALSE(stats.contains("texture_bytes"));
    }
  }
}

// --volume-deposits auto (the default): a clear glass ball over a ground bakes only the ground's map
// and says so; with a receiver and an absorbing, scattering ball, or without a receiver, the fields
// are written. `on` forces them, and its map is the auto bake's.
TEST(LightsimCli, VolumeDepositsOnlyWhereTheViewerReadsThem) {
  TempDir dir;
  makeSphere(dir, true);
  ProgramResult r = runProgram(VOXELIZE_EXE,
                               {"procedural:sphere,r=0.5,sigma_a=0.2,scatter=1,g=0.3", "-o", "smoke.vol.json", "--res",
                                "16", "--quiet"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto bake = [&](const std::string& in, const std::string& out, std::vector<std::string> extra) {
    std::vector<std::string> args = {in, "-o", out, "--light", "directional:0,-1,0"};
    args.insert(args.end(), extra.begin(), extra.end());
    ProgramResult b = runProgram(LIGHTSIM_EXE, args, dir.path());
    EXPECT_EQ(b.exit_code, 0) << b.output;
    return b.output;
  };
  // Steps of Δt for both (straight steps, lightsim's default, need the volume deposits off).
  const std::vector<std::string> ground = {"--receiver", "0,-0.6,0:0,1,0:1", "--straight-step", "0"};
  const std::string said = bake("sharp.vol.json", "auto.vol.json", ground);
  EXPECT_NE(said.find("--volume-deposits auto"), std::string::npos) << said;
  bake("sharp.vol.json", "on.vol.json",
       {"--receiver", "0,-0.6,0:0,1,0:1", "--straight-step", "0", "--volume-deposits", "on", "--quiet"});
  bake("sharp.vol.json", "no_ground.vol.json", {"--quiet"});
  bake("smoke.vol.json", "smoke_baked.vol.json", {"--receiver", "0,-0.6,0:0,1,0:1", "--quiet"});
  const Volume glass = readVolume(dir / "auto.vol.json"), forced = readVolume(dir / "on.vol.json");
  EXPECT_FALSE(glass.has("irradiance") || glass.has("light_dir"));
  ASSERT_EQ(glass.receivers.size(), 1u);
  ASSERT_EQ(forced.receivers.size(), 1u);
  EXPECT_EQ(glass.receivers[0].irradiance, forced.receivers[0].irradiance);
  EXPECT_EQ(glass.metadata["bake_options"]["volume_deposits"], false);  // the window re-bakes the same way
  EXPECT_TRUE(forced.has("irradiance") && forced.has("light_dir"));
  EXPECT_TRUE(readVolume(dir / "no_ground.vol.json").has("irradiance"));
  EXPECT_TRUE(readVolume(dir / "smoke_baked.vol.json").has("irradiance"));
  // The CPU twin (this machine's back end) leaves a sharp constant-n volume's n (and ∇n, where the
  // volume has it) unread; they reach the baked volume as they were.
  const Volume input = readVolume(dir / "sharp.vol.json");
  EXPECT_FALSE(input.has("ior_grad"));  // voxelize leaves it out: 0 throughout
  for (const Volume* baked : {&glass, &forced}) {
    EXPECT_FALSE(baked->has("ior_grad"));
    for (const char* name : {"ior", "interfaces"}) {
      ASSERT_TRUE(baked->has(name)) << name;
      EXPECT_EQ(baked->fields.at(name).data, input.fields.at(name).data) << name;
    }
  }
}

TEST(LightsimCli, BadInputExitsTwo) {
  TempDir dir;
  makeSphere(dir);
  Volume v = readVolume(dir / "ball.vol.json");
  v.fields.erase("ior_grad");
  writeVolume(v, dir / "nograd.vol.json");
  makeSphere(dir, true);
  Volume bad_slot = readVolume(dir / "sharp.vol.json");
  bad_slot.metadata["interfaces"]["slots"][0]["sigma_a"] = {0.2, -0.4, 0.8};
  writeVolume(bad_slot, dir / "bad_slot.vol.json");
  // Hostile manifests (issue "Reliability"): a key nested 10⁶ deep, a number beyond double.
  {
    const std::string text = readFile(dir / "ball.vol.json");
    std::string deep = "{\"extra\": ";
    for (int i = 0; i < 1000000; ++i) deep += "[";
    std::ofstream(dir / "deep.vol.json") << deep;
    std::string huge = text;
    huge.insert(huge.find('{') + 1, "\"spacing_hint\": 1e999,");
    std::ofstream(dir / "huge.vol.json") << huge;
  }
  struct Case {
    std::vector<std::string> args;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {{"ball.vol.json", "-o", "x.vol.json"}, "--light"},
      {{"ball.vol.json", "-o", "x.vol.json", "--light", "directional:0,0,0"}, "--light"},
      {{"ball.vol.json", "-o", "x.vol.json", "--light", "spot:0,1,0"}, "--light"},
      {{"ball.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0", "--power", "0,0,0"}, "--power"},
      {{"ball.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0", "--power", "-1,1,1"}, "--power"},
      {{"nograd.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0"}, "ior_grad"},
      {{"bad_slot.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0"},
       "bad_slot.vol.json: interfaces.slots[0].sigma_a: must not be negative"},
      {{"missing.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0"}, "missing.vol.json"},
      {{"ball.vol.json", "-o", "x.nrrd", "--light", "directional:0,-1,0"}, ".vol.json"},
      {{"ball.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0", "--backend", "cuda"}, "--backend"},
      {{"ball.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0", "--volume-deposits", "off"},
       "--volume-deposits"},
      {{"deep.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0"}, "deep.vol.json: JSON: nested deeper"},
      {{"huge.vol.json", "-o", "x.vol.json", "--light", "directional:0,-1,0"},
       "huge.vol.json: spacing_hint: number out of range"},
  };
  for (const Case& c : cases) {
    ProgramResult r = runProgram(LIGHTSIM_EXE, c.args, dir.path());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in: " << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.vol.json"));
  }
}

// `lightsim SCENE.json -o OUT_DIR`: every object baked under its placement, into the folder with a
// SCENE.json naming the baked volumes that the viewer opens as it is. The same volume placed twice
// gets two baked volumes; the turned one records the sun as its own axes see it.
TEST(LightsimCli, BakesAWholeSceneIntoAFolderTheViewerOpens) {
  TempDir dir;
  makeSphere(dir, true);
  writeFile(dir / "SCENE.json", R"({
    "camera": {"eye": [0, 1.5, 3], "target": [0, 0, 0]},
    "environment": {"uniform": [0.1, 0.1, 0.1]},
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [2, 2, 2]}],
    "ground": {"point": [0, -0.6, 0], "normal": [0, 1, 0], "half_extent": 2},
    "objects": [{"volume": "sharp.vol.json", "translate": [-0.6, 0, 0]},
                {"volume": "sharp.vol.json", "translate": [0.6, 0, 0], "rotate_deg": [0, 0, 30], "scale": 0.8}]})");
  ProgramResult r = runProgram(LIGHTSIM_EXE, {"SCENE.json", "-o", "baked", "--quiet"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json scene = nlohmann::json::parse(readFile(dir / "baked" / "SCENE.json"));
  ASSERT_EQ(scene["objects"].size(), 2u);
  EXPECT_EQ(scene["objects"][0]["volume"], "sharp.baked.vol.json");
  EXPECT_EQ(scene["objects"][1]["volume"], "sharp-2.baked.vol.json");
  EXPECT_EQ(scene["objects"][1]["scale"], 0.8);
  const Volume upright = readVolume(dir / "baked" / "sharp.baked.vol.json");
  const Volume turned = readVolume(dir / "baked" / "sharp-2.baked.vol.json");
  ASSERT_EQ(upright.receivers.size(), 1u);
  ASSERT_EQ(turned.receivers.size(), 1u);
  // Rz(30°)⁻¹ · (0, −1, 0) = (−sin 30°, −cos 30°, 0): the sun as the turned volume sees it.
  const nlohmann::json& d = turned.metadata["light"]["direction"];
  EXPECT_NEAR(d[0].get<double>(), -0.5, 1e-9);
  EXPECT_NEAR(d[1].get<double>(), -std::sqrt(3.0) / 2.0, 1e-9);
  EXPECT_EQ(upright.metadata["light"]["direction"][1], -1.0);
  // The ground y = −0.6 in the turned volume's axes (world = T + R·s·p): the normal Rᵀ·(0, 1, 0) =
  // (sin 30°, cos 30°, 0), the plane n·p = −0.6 / 0.8 (T lies in the plane y = 0).
  const ReceiverMap& map = turned.receivers[0];
  EXPECT_NEAR(map.normal.x, 0.5, 1e-9);
  EXPECT_NEAR(map.normal.y, std::sqrt(3.0) / 2.0, 1e-9);
  EXPECT_NEAR(glm::dot(map.point, map.normal), -0.75, 1e-9);
  ProgramResult v = runProgram(VIEWER_EXE, {"baked/SCENE.json", "--render", "scene.png", "--size", "48x32"}, dir.path());
  EXPECT_EQ(v.exit_code, 0) << v.output;
  // Scaled differently along its axes: baked and written as the volume at world scale along each
  // axis (its box × (1.2, 0.6, 1)), placed with scale 1 in the baked SCENE.json; its map lies on
  // the ground y = −0.6 in world units.
  writeFile(dir / "uneven.json", R"({
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [2, 2, 2]}],
    "ground": {"point": [0, -0.6, 0], "normal": [0, 1, 0], "half_extent": 2},
    "objects": [{"volume": "sharp.vol.json", "rotate_deg": [0, 30, 0], "scale": [1.2, 0.6, 1]}]})");
  r = runProgram(LIGHTSIM_EXE, {"uneven.json", "-o", "uneven", "--quiet"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json uneven = nlohmann::json::parse(readFile(dir / "uneven" / "SCENE.json"));
  EXPECT_EQ(uneven["objects"][0]["scale"], 1.0);
  EXPECT_EQ(uneven["objects"][0]["rotate_deg"][1], 30.0);
  const Volume stretched = readVolume(dir / "uneven" / "sharp.baked.vol.json");
  const Volume input = readVolume(dir / "sharp.vol.json");
  EXPECT_NEAR(glm::length(stretched.grid.bounds_max - glm::dvec3(1.2, 0.6, 1.0) * input.grid.bounds_max), 0.0, 1e-9);
  ASSERT_EQ(stretched.receivers.size(), 1u);
  EXPECT_NEAR(glm::dot(stretched.receivers[0].point, stretched.receivers[0].normal), -0.6, 1e-9);
  v = runProgram(VIEWER_EXE, {"uneven/SCENE.json", "--render", "uneven.png", "--size", "48x32"}, dir.path());
  EXPECT_EQ(v.exit_code, 0) << v.output;
  // A scene input takes no light, receiver, stats or bench of its own, -o names a folder, and a
  // missing object's volume stops the bake before anything is written.
  writeFile(dir / "missing.json", R"({"lights": [{"type": "directional", "direction": [0, -1, 0]}],
    "objects": [{"volume": "sharp.vol.json"}, {"volume": "nowhere.vol.json"}]})");
  writeFile(dir / "afile", "x");
  for (const auto& [args, expected] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"SCENE.json", "-o", "x", "--light", "directional:0,-1,0"}, "--light"},
           {{"SCENE.json", "-o", "x", "--stats", "s.json"}, "--stats"},
           {{"SCENE.json", "-o", "afile"}, "folder"},
           {{"SCENE.json", "-o", "."}, "overwrite the input scene"},
           {{"missing.json", "-o", "x"}, "nowhere.vol.json"}}) {
    ProgramResult bad = runProgram(LIGHTSIM_EXE, args, dir.path());
    EXPECT_EQ(bad.exit_code, 2) << bad.output;
    EXPECT_NE(bad.output.find(expected), std::string::npos) << "expected '" << expected << "' in: " << bad.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "x")) << bad.output;
  }
}

// A tiny museum: a dark glass slab (σa = 6 per unit: e^−1.2 through its 0.2 thickness) hangs
// over a sphere in the sun. Baked as one scene the sphere stands in the slab's shadow and gets the
// light that came through it (scene_bake.h SceneLightChain): its baked irradiance, summed over its
// grid, is e^−1.2 ≈ 0.30 of what it gets with the slab moved aside (less: the slab's faces reflect
// a little). Tolerance: the slab's box is wider than the sphere's (its sides' light misses the
// sphere alike in both scenes); 0.25–0.40 would hold any reasonable discretisation, while a sphere
// baked in the full sun (the chain off) gets 1.0.
TEST(LightsimCli, AnObjectBehindAnotherFromTheLightGetsLessLight) {
  TempDir dir;
  makeSphere(dir, true);
  ProgramResult slab = runProgram(VOXELIZE_EXE,
                                  {"procedural:box,size=1.6:0.2:1.6,ior=1.5,sigma_a=6:6:6", "-o", "slab.vol.json",
                                   "--res", "24", "--interfaces", "sharp", "--quiet"},
                                  dir.path());
  ASSERT_EQ(slab.exit_code, 0) << slab.output;
  double sums[2] = {0.0, 0.0};
  for (int aside = 0; aside < 2; ++aside) {
    writeFile(dir / "SCENE.json", std::string(R"({
      "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}],
      "ground": {"point": [0, -0.6, 0], "normal": [0, 1, 0], "half_extent": 3},
      "objects": [{"volume": "sharp.vol.json"},
                  {"volume": "slab.vol.json", "translate": [)") + (aside ? "2.5" : "0") + R"(, 1.2, 0]}]})");
    const std::string out = aside ? "aside" : "above";
    ProgramResult r = runProgram(LIGHTSIM_EXE, {"SCENE.json", "-o", out, "--volume-deposits", "on"}, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // The slab is baked first (the light meets it first), then the sphere with what came through.
    EXPECT_LT(r.output.find("slab.vol.json"), r.output.find("sharp.vol.json")) << r.output;
    EXPECT_EQ(r.output.find("in their shade") != std::string::npos, aside == 0) << r.output;
    const Volume sphere = readVolume(dir / out / "sharp.baked.vol.json");
    const Field& e = sphere.require("irradiance", 3);
    for (float v : e.data) sums[aside] += v;
  }
  std::printf("the sphere's irradiance under the slab / beside it: %.4f\n", sums[0] / sums[1]);
  EXPECT_GT(sums[0] / sums[1], 0.25);
  EXPECT_LT(sums[0] / sums[1], 0.40);
}

// Every light of a scene, summed: a dark glass slab (σa = 6 per unit, 0.2 thick) over the ground
// under a sun straight down (E = 1) and one 45° off it (E = 0.5), one bake with both lights against
// a bake of each with the other dimmed to 10⁻⁶: the same map lattice (the union of the lights'
// own), so the two-light map is their sum texel by texel (a run's light is what it would be
// alone): under the slab in the first sun's shadow and the second's light, in the second sun's
// shadow and the first's light, and out in the open (1 + 0.5·cos 45° = 1.354). Each sun baked
// alone, on its own lattice, gets what exact optics puts under the slab. (The alone maps are not
// the summed map's terms to better than a few per cent near the slab: where the patch lattice lies
// against the slab's edges moves light that enters within a voxel of an edge, whose normals the
// distance field blurs, up to 0.3 inward.) The manifest names both lights, the first as "light" (the one
// whose direct light the viewer takes off exactly; the others it takes off the map, ground_map.h),
// and the viewer draws the ground from them.
TEST(LightsimCli, EveryLightOfTheSceneIsBakedAndSummed) {
  TempDir dir;
  ProgramResult slab = runProgram(VOXELIZE_EXE,
                                  {"procedural:box,size=1.6:0.2:1.6,ior=1.5,sigma_a=6:6:6", "-o", "slab.vol.json",
                                   "--res", "24", "--interfaces", "sharp", "--quiet"},
                                  dir.path());
  ASSERT_EQ(slab.exit_code, 0) << slab.output;
  const std::string overhead = R"({"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]})";
  const std::string tilted = R"({"type": "directional", "direction": [1, -1, 0], "irradiance": [0.5, 0.5, 0.5]})";
  const std::string overhead_dim = R"({"type": "directional", "direction": [0, -1, 0], "irradiance": [1e-6, 1e-6, 1e-6]})";
  const std::string tilted_dim = R"({"type": "directional", "direction": [1, -1, 0], "irradiance": [1e-6, 1e-6, 1e-6]})";
  const std::vector<std::pair<std::string, std::string>> scenes = {{"both", overhead + ", " + tilted},
                                                                   {"first", overhead},
                                                                   {"second", tilted},
                                                                   {"first_of_two", overhead + ", " + tilted_dim},
                                                                   {"second_of_two", overhead_dim + ", " + tilted}};
  for (const auto& [name, lights] : scenes) {
    writeFile(dir / (name + ".json"), R"({
      "camera": {"eye": [0, 1.5, 4], "target": [0, -0.8, 0]},
      "lights": [)" + lights + R"(],
      "ground": {"point": [0, -1.2, 0], "normal": [0, 1, 0], "half_extent": 4},
      "objects": [{"volume": "slab.vol.json"}]})");
    ProgramResult r = runProgram(LIGHTSIM_EXE, {name + ".json", "-o", name}, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("light 2/2") != std::string::npos, name != "first" && name != "second") << r.output;
  }
  const Volume both = readVolume(dir / "both" / "slab.baked.vol.json");
  const Volume first = readVolume(dir / "first" / "slab.baked.vol.json");
  const Volume second = readVolume(dir / "second" / "slab.baked.vol.json");
  const Volume first_of_two = readVolume(dir / "first_of_two" / "slab.baked.vol.json");
  const Volume second_of_two = readVolume(dir / "second_of_two" / "slab.baked.vol.json");
  ASSERT_TRUE(both.metadata.contains("lights"));
  ASSERT_EQ(both.metadata["lights"].size(), 2u);
  EXPECT_EQ(both.metadata["lights"][0], both.metadata["light"]);
  EXPECT_EQ(both.metadata["lights"][1]["irradiance"][0], 0.5);
  EXPECT_FALSE(first.metadata.contains("lights"));
  // Irradiance (green) at a ground point of each map, from its texel (the maps' lattices differ).
  auto at = [](const Volume& v, double x) {
    const ReceiverMap& map = v.receivers.at(0);
    const glm::dvec2 uv = (map.planeCoordinates(glm::dvec3(x, -1.2, 0.0)) - map.origin) / map.pitch;
    const int i = static_cast<int>(uv.x), j = static_cast<int>(uv.y);
    EXPECT_TRUE(i >= 0 && j >= 0 && i < map.texels.x && j < map.texels.y) << x;
    return map.rgb(static_cast<std::size_t>(j) * map.texels.x + i).y;
  };
  // x = −0.4: under the slab for the first sun, in the open for the second (its shadow, through the
  // slab, lies over 0.4–1.8); x = 1.3: the other way round; x = 2.4: open to both. Each a few
  // voxels (0.067) from any shadow's edge.
  for (const double x : {-0.4, 1.3, 2.4}) {
    const double sum = at(first_of_two, x) + at(second_of_two, x);
    std::printf("x = %.1f: both %.6f, first + second %.6f (%.6f + %.6f); alone %.4f + %.4f\n", x, at(both, x), sum,
                at(first_of_two, x), at(second_of_two, x), at(first, x), at(second, x));
    // Tolerance: the dimmed light's 10⁻⁶ in each term and the maps' float sums (measured 1.6·10⁻⁶);
    // a dropped or doubled light would be 35 % off at least.
    EXPECT_NEAR(at(both, x) / sum, 1.0, 1e-4) << x;
  }
  EXPECT_NEAR(at(both, 2.4), 1.0 + 0.5 * std::sqrt(0.5), 0.01);
  // Through the slab: e^−1.2 ≈ 0.30 of the first sun, (1 − R)² e^−1.2 = 0.2776 with the faces'
  // reflections at normal incidence (R = 0.04): measured 0.2776 (0.313 while the look ahead for a
  // torn patch asked its chord's end only, and every patch at the slab, 3 voxels thick, tore);
  // 0.5 % for the map's float sums and texels a voxel or more from the slab's edges. Of the
  // second's 0.354 e^−6·0.227 (refracted to 28°) ≈ 0.26, 0.081 with the reflections.
  EXPECT_NEAR(at(first, -0.4), 0.9216 * std::exp(-1.2), 0.005 * 0.2776);
  EXPECT_NEAR(at(second, 1.3), 0.081, 0.02);
  // The summed ledger closes.
  EXPECT_LT(both.metadata["bake_stats"]["flux"]["ledger_relative_residual"].get<double>(), 1e-6);
  ProgramResult v = runProgram(VIEWER_EXE, {"both/SCENE.json", "--render", "both.png", "--size", "96x64"}, dir.path());
  EXPECT_EQ(v.exit_code, 0) << v.output;
}

// `--bands N`: a dispersive volume (here a flint sphere, Abbe 20) is baked band by band, the bands'
// bakes summed: the manifest says how many, the summed ledger closes (in = out + absorbed +
// reflected + killed + unfinished + received + blocked, to float rounding of the bands' sums), and
// the map's total is that of the one-band bake within 1 % (every band carries its share of the
// light; they land in different places, not with different power). A volume without dispersion
// is baked once whatever --bands says; 2 and 17 bands are refused.
TEST(LightsimCli, BakesADispersiveVolumeBandByBand) {
  TempDir dir;
  ProgramResult v = runProgram(VOXELIZE_EXE,
                               {"procedural:sphere,r=0.4,ior=1.7,abbe=20", "-o", "flint.vol.json", "--res", "20",
                                "--interfaces", "sharp", "--quiet"},
                               dir.path());
  ASSERT_EQ(v.exit_code, 0) << v.output;
  makeSphere(dir, true);  // no dispersion
  double totals[2] = {0.0, 0.0};
  for (const int bands : {1, 16}) {
    const std::string out = "flint" + std::to_string(bands) + ".vol.json";
    ProgramResult r = runProgram(LIGHTSIM_EXE,
                                 {"flint.vol.json", "-o", out, "--light", "directional:0,-1,0", "--receiver",
                                  "0,-0.6,0:0,1,0:1.5", "--bands", std::to_string(bands)},
                                 dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("16 spectral bands") != std::string::npos, bands == 16) << r.output;
    const Volume baked = readVolume(dir / out);
    EXPECT_EQ(baked.metadata.contains("bake_bands"), bands == 16);
    if (bands == 16) EXPECT_EQ(baked.metadata["bake_bands"], 16);
    const nlohmann::json& f = baked.metadata["bake_stats"]["flux"];
    const double in = f["in"][1].get<double>();
    double rest = 0.0;
    for (const char* key : {"out", "absorbed", "reflected", "killed", "unfinished", "received", "blocked"})
      rest += f[key][1].get<double>();
    EXPECT_NEAR(rest / in, 1.0, 1e-6) << bands;
    EXPECT_LT(f["ledger_relative_residual"].get<double>(), 1e-6) << bands;
    for (std::size_t t = 0; t < baked.receivers.at(0).texelCount(); ++t)
      totals[bands == 16] += baked.receivers[0].rgb(t).y;
  }
  EXPECT_NEAR(totals[1] / totals[0], 1.0, 0.01);
  ProgramResult plain = runProgram(LIGHTSIM_EXE,
                                   {"sharp.vol.json", "-o", "plain.vol.json", "--light", "directional:0,-1,0", "--bands", "16"},
                                   dir.path());
  EXPECT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_EQ(plain.output.find("spectral bands"), std::string::npos) << plain.output;
  for (const char* bad : {"2", "17"}) {
    ProgramResult r = runProgram(LIGHTSIM_EXE,
                                 {"flint.vol.json", "-o", "bad.vol.json", "--light", "directional:0,-1,0", "--bands", bad},
                                 dir.path());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--bands"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.vol.json"));
  }
}

// A scene's sun with an angular size: the bake follows --sun-samples directions over its disc
// (sun_disc.h; the penumbra against geometry is ExactOpticsSoftSun), the baked manifest records
// the light with its size, and the viewer renders it (drawing the map's penumbra as baked, without
// sharpening the edge). The same scene without the size bakes once.
TEST(LightsimCli, ASunWithADiscBakesSoftShadows) {
  TempDir dir;
  makeSphere(dir, true);
  for (const bool disc : {true, false}) {
    writeFile(dir / "SCENE.json", std::string(R"({
      "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1])") +
                                     (disc ? R"(, "angular_diameter_deg": 5)" : "") + R"(}],
      "ground": {"point": [0, -0.6, 0], "normal": [0, 1, 0], "half_extent": 2},
      "objects": [{"volume": "sharp.vol.json"}]})");
    ProgramResult r = runProgram(LIGHTSIM_EXE, {"SCENE.json", "-o", "out", "--sun-samples", "6"}, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("from 6 directions (soft shadows)") != std::string::npos, disc) << r.output;
    const Volume baked = readVolume(dir / "out" / "sharp.baked.vol.json");
    EXPECT_EQ(baked.metadata["light"].value("angular_diameter_deg", 0.0), disc ? 5.0 : 0.0);
    ProgramResult v = runProgram(VIEWER_EXE, {"out/SCENE.json", "--render", "soft.png", "--size", "48x32"}, dir.path());
    EXPECT_EQ(v.exit_code, 0) << v.output;
  }
  // A point light with a radius, on an object the scene scales by 2: points in its ball, and the
  // radius in the volume's own units in the manifest (0.4 / 2).
  writeFile(dir / "SCENE.json", R"({
    "lights": [{"type": "point", "position": [0, 3, 0], "intensity": [9, 9, 9], "radius": 0.4}],
    "ground": {"point": [0, -1.2, 0], "normal": [0, 1, 0], "half_extent": 3},
    "objects": [{"volume": "sharp.vol.json", "scale": 2}]})");
  ProgramResult r = runProgram(LIGHTSIM_EXE, {"SCENE.json", "-o", "lamp", "--sun-samples", "5"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("ball of radius 0.4 from 5 points"), std::string::npos) << r.output;
  const Volume baked = readVolume(dir / "lamp" / "sharp.baked.vol.json");
  EXPECT_NEAR(baked.metadata["light"].value("radius", 0.0), 0.2, 1e-12);
  ProgramResult v = runProgram(VIEWER_EXE, {"lamp/SCENE.json", "--render", "lamp.png", "--size", "48x32"}, dir.path());
  EXPECT_EQ(v.exit_code, 0) << v.output;
}

// Ctrl-C (SIGINT) or a kill (SIGTERM) during a bake: exit 130 / 143, a message, and no output file
// or temporary left (core/interrupt.h). The bake repeats (--bench); the signal is sent once the first
// repetition has reported, so it finds the program at work whatever the machine's load.
TEST(LightsimCli, AnInterruptedBakeExits130Or143AndLeavesNothing) {
  TempDir dir;
  makeSphere(dir, true);
  const std::vector<std::string> before = dir.entries();
  for (const auto& [signal_number, code, word] : {std::tuple<int, int, const char*>{SIGINT, 130, "interrupted"},
                                                  std::tuple<int, int, const char*>{SIGTERM, 143, "terminated"}}) {
    ProgramResult r = runProgram(LIGHTSIM_EXE,
                                 {"sharp.vol.json", "-o", "out.vol.json", "--light", "directional:0,-1,0", "--backend",
                                  "cpu", "--bench", "1000"},
                                 dir.path(), signal_number, "bench run 1 of 1000");
    EXPECT_EQ(r.exit_code, code) << r.output;
    EXPECT_NE(r.output.find(std::string("lightsim: ") + word), std::string::npos) << r.output;
    EXPECT_EQ(dir.entries(), before) << "an interrupted bake left files behind";
  }
}

}  // namespace
}  // namespace eik::test
