// `viewer` headless as a user runs it: a rendered EXR with the right numbers, a PNG, and exit code 2
// with a clear message for bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "core/image_io.h"
#include "core/volume.h"
#include "tests/program_runner.h"

namespace eik::test {
namespace {

// A sphere of radius 0.5 with σa = (0, 0.5, 1) per unit, 32³.
void makeSphere(const TempDir& dir) {
  ProgramResult r = runProgram(VOXELIZE_EXE,
                               {"procedural:sphere,r=0.5,ior=1.5,sigma_a=0:0.5:1", "-o", "ball.vol.json", "--res", "32", "--quiet"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
}

// A clear glass ball of radius 0.4, 24³, with room below it for a ground at y = −0.8.
void makeGlassBall(const TempDir& dir) {
  ProgramResult r = runProgram(VOXELIZE_EXE,
                               {"procedural:sphere,r=0.4,ior=1.5", "-o", "glass.vol.json", "--res", "24",
                                "--bounds", "-1,-0.9,-1,1,1.1,1", "--quiet"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
}

TEST(ViewerCli, RendersBeerLambertThroughTheCentre) {
  TempDir dir;
  makeSphere(dir);
  // Looking straight through the centre along -z: the central ray is not bent and crosses 2r = 1
  // of material at normal incidence. With R = 0.04 at each face and T = exp(-σa·1) per crossing,
  // summing every internal bounce, the exact radiance from a white environment is
  //   R + (1 - R)²·T / (1 - R·T)
  // (1 exactly for σa = 0: no light is lost).
  ProgramResult r = runProgram(VIEWER_EXE,
                               {"ball.vol.json", "--render", "ball.exr", "--size", "65x65", "--camera",
                                "0,0,4:0,0,0:30", "--env", "uniform:1,1,1", "--quiet"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image image = readImage(dir / "ball.exr");
  ASSERT_EQ(image.width, 65);
  ASSERT_EQ(image.height, 65);
  const float* centre = image.at(32, 32);
  const float R = 0.04f;
  auto exact = [R](float sigma_a) {
    const float T = std::exp(-sigma_a);
    return R + (1 - R) * (1 - R) * T / (1 - R * T);
  };
  // The sharp-interface viewer follows the stronger branch at each face and takes the other as the
  // environment along it; the one bounce it cuts short misses one more pass of absorption, at most
  // R·(1 - R)·T·(1 - T) ≈ 0.009 (σa = 0.5, 1) above the exact value. The tolerance 0.015 holds that
  // and the EXR's half-float rounding (< 0.001); dropping the internal bounce altogether (R + (1 - R)²·T) would
  // miss red by 0.038.
  EXPECT_NEAR(centre[0], exact(0.0f), 0.01f);
  EXPECT_NEAR(centre[1], exact(0.5f), 0.015f);
  EXPECT_NEAR(centre[2], exact(1.0f), 0.015f);
  const float* corner = image.at(0, 0);  // misses the sphere: the environment itself
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(corner[c], 1.0f, 1e-3f);

  r = runProgram(VIEWER_EXE, {"ball.vol.json", "--render", "ball.png", "--size", "48x32", "--quiet"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image png = readImage(dir / "ball.png");
  EXPECT_EQ(png.width, 48);
  EXPECT_EQ(png.height, 32);
}

TEST(ViewerCli, BadInputExitsTwo) {
  TempDir dir;
  makeSphere(dir);
  struct Case {
    std::vector<std::string> args;
    const char* expected;
  };
  writeFile(dir / "unknown_key.json", R"({"objects": [{"volume": "ball.vol.json"}], "camera": {"fov": 40}})");
  writeFile(dir / "wrong_type.json", R"({"objects": [{"volume": "ball.vol.json", "scale": "big"}]})");
  writeFile(dir / "no_volume.json", R"({"objects": [{"volume": "missing.vol.json"}]})");
  writeFile(dir / "env_missing.json",
            R"({"objects": [{"volume": "ball.vol.json"}], "environment": {"file": "nowhere.exr"}})");
  writeFile(dir / "env_unknown.json",
            R"({"objects": [{"volume": "ball.vol.json"}], "environment": {"procedural": "nebula"}})");
  writeFile(dir / "ground_type.json",
            R"({"objects": [{"volume": "ball.vol.json"}], "ground": {"albedo": "grey"}})");
  writeFile(dir / "garbage.exr", "this is not an image");
  // Radiance headers that claim far more pixels than the file holds.
  writeFile(dir / "huge.hdr", std::string("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 32768 +X 32768\n") + "\x02\x02\x80\x00");
  writeFile(dir / "big.hdr", std::string("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 16000 +X 16000\n") + "\x02\x02\x80\x00");
  // The reader is the extension's: a PNG named .exr is refused as an EXR (no other reader tried),
  // an extension no reader has is refused before the file is opened.
  Image tiny;
  tiny.width = tiny.height = 2;
  tiny.channels = 3;
  tiny.pixels.assign(12, 0.5f);
  writeImage(dir / "real.png", tiny);
  std::filesystem::copy_file(dir / "real.png", dir / "png_named.exr");
  writeFile(dir / "map.txt", "0.5 0.5 0.5");
  writeFile(dir / "map.jpg", "\xff\xd8\xff\xe0");
  Volume no_ior = readVolume(dir / "ball.vol.json");
  no_ior.fields.erase("ior");
  writeVolume(no_ior, dir / "noior.vol.json");
  // A volume without ior_grad whose n is not constant in every material (here: no interface table,
  // so a smoothed n): ∇n is needed. (voxelize leaves ∇n out where the table says it is 0.)
  Volume v = readVolume(dir / "ball.vol.json");
  v.fields.erase("ior_grad");
  v.fields.erase("interfaces");
  v.metadata.erase("interfaces");
  writeVolume(v, dir / "nograd.vol.json");
  const std::vector<Case> cases = {
      {{"unknown_key.json", "--render", "x.png"}, "camera.fov"},
      {{"wrong_type.json", "--render", "x.png"}, "objects[0].scale"},
      {{"no_volume.json", "--render", "x.png"}, "missing.vol.json"},
      {{"nograd.vol.json", "--render", "x.png"}, "ior_grad"},
      {{"ball.vol.json", "--render", "x.png", "--size", "10by10"}, "--size"},
      {{"ball.vol.json", "--render", "x.jpg"}, ".png or .exr"},
      {{"ball.vol.json", "--render", "x.png", "--env", "nebula"}, "--env"},
      {{"ball.vol.json", "--render", "x.png", "--env", "uniform:1,-1,0"}, "--env"},
      {{"ball.vol.json", "--render", "x.png", "--env", "missing.exr"}, "missing.exr"},
      {{"ball.vol.json", "--render", "x.png", "--env", "garbage.exr"}, "garbage.exr"},
      {{"ball.vol.json", "--render", "x.png", "--env", "png_named.exr"}, "png_named.exr: not an OpenEXR file"},
      {{"ball.vol.json", "--render", "x.png", "--env", "map.txt"}, "map.txt: unknown image type '.txt'"},
      {{"ball.vol.json", "--render", "x.png", "--env", "map.jpg"}, "map.jpg: unknown image type '.jpg' (read: .exr, .hdr, .png)"},
      {{"env_missing.json", "--render", "x.png"}, "nowhere.exr"},
      {{"ball.vol.json", "--render", "x.png", "--env", "huge.hdr"}, "huge.hdr: size: 32768x32768 is larger than 16384"},
      {{"env_unknown.json", "--render", "x.png"}, "environment.procedural"},
      {{"ground_type.json", "--render", "x.png"}, "ground.albedo"},
      {{"noior.vol.json", "--render", "x.png"}, "ior"},
      {{"ball.vol.json", "--render", "x.png", "--integrator", "leapfrog"}, "--integrator"},
      {{"ball.vol.json", "--render", "x.png", "--camera", "0,0,1:0,0"}, "--camera"},
      {{"ball.vol.json", "--render", "x.png", "--bands", "2"}, "--bands"},
      {{"ball.vol.json", "--render", "x.png", "--bands", "17"}, "--bands"},
  };
  for (const Case& c : cases) {
    ProgramResult r = runProgram(VIEWER_EXE, c.args, dir.path());
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << ": " << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in: " << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
  }
  // Within the axis limit but over the machine's memory (here said to be 1 GiB; 16000² RGB floats
  // and their mipmaps need 5.7 GiB): refused before a pixel is allocated.
  {
    test_support::ScopedEnv memory("EIKONAL_MEMORY_LIMIT_BYTES", "1073741824");
    ProgramResult r = runProgram(VIEWER_EXE, {"ball.vol.json", "--render", "x.png", "--env", "big.hdr"}, dir.path());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("big.hdr: size"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
  }
}

// A volume of 1024³ voxels declared in files of a few hundred bytes (issue "Reliability": a 250-byte
// NRRD so declared took 9.4 s and 4.15 GiB before it was refused): refused with exit 2 before its
// 4 GiB (ior) and 12 GiB (ior_grad) are allocated. The bound is on what reading adds to the
// program's own peak memory (its `--help` run: the libraries alone, 56 MB for lightsim with Mesa's,
// about as much for the viewer): under 50 MB. Sanitizer builds reserve memory of their
// own, so the bound is checked without them.
TEST(ViewerCli, A1024CubedVolumeInTinyFilesIsRefusedBeforeItsMemory) {
  TempDir dir;
  const std::string geometry = "space: right-anterior-superior\nspace origin: (-0.9990234375,-0.9990234375,-0.9990234375)\n";
  const std::string axes = "(0.001953125,0,0) (0,0.001953125,0) (0,0,0.001953125)\n";
  writeFile(dir / "big.ior.nrrd", "NRRD0004\ntype: float\nendian: little\ndimension: 3\nsizes: 1024 1024 1024\n" +
                                       geometry + "space directions: " + axes + "encoding: raw\n\n" +
                                       std::string(16, '\0'));
  writeFile(dir / "big.ior_grad.nrrd", "NRRD0004\ntype: float\nendian: little\ndimension: 4\nsizes: 3 1024 1024 1024\n" +
                                           geometry + "space directions: none " + axes + "encoding: ascii\n\n0 0 0 0\n");
  writeFile(dir / "big.vol.json",
            R"({"format": "eikonal-volume", "version": 1, "dims": [1024, 1024, 1024], "bounds_min": [-1, -1, -1],
                "bounds_max": [1, 1, 1], "fields": {"ior": {"file": "big.ior.nrrd", "components": 1},
                "ior_grad": {"file": "big.ior_grad.nrrd", "components": 3}}})");
  for (const auto& [program, args] :
       {std::pair<const char*, std::vector<std::string>>{LIGHTSIM_EXE, {"big.vol.json", "-o", "x.vol.json", "--light",
                                                                         "directional:0,-1,0"}},
        std::pair<const char*, std::vector<std::string>>{VIEWER_EXE, {"big.vol.json", "--render", "x.png"}}}) {
    const ProgramResult help = runProgram(program, {"--help"}, dir.path());
    ProgramResult r = runProgram(program, args, dir.path());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("big.vol.json: fields.ior: ./big.ior.nrrd: data: truncated: sizes need 4294967296 bytes"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / args[2])) << args[2];
#if !defined(__SANITIZE_ADDRESS__)
    // 50 MB over --help, and for the viewer 60 MB more: it loads its OpenGL driver (OSMesa with Mesa
    // and LLVM, about 55 MB resident) while it reads the volume. Either is far below the 4 GiB the
    // sizes ask for.
    const long margin_kib = (std::string(program) == VIEWER_EXE ? 110 : 50) * 1000;
    EXPECT_LT(r.peak_rss_kib, help.peak_rss_kib + margin_kib) << program << " (KiB; --help: " << help.peak_rss_kib << ")";
#endif
  }
}

// A scene as a user writes it: two baked objects (the second seen through the first), a ground
// plane, the procedural sky; the flags that switch terms off run too.
TEST(ViewerCli, RendersABakedSceneWithGroundSkyAndTwoObjects) {
  TempDir dir;
  makeGlassBall(dir);
  ProgramResult r;
  r = runProgram(LIGHTSIM_EXE,
                 {"glass.vol.json", "-o", "baked.vol.json", "--light", "directional:0,-1,0", "--backend", "cpu", "--quiet"},
                 dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  writeFile(dir / "scene.json", R"({
    "camera": {"eye": [0, 2.5, 4.5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40},
    "environment": {"procedural": "sky", "intensity": 0.5},
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}],
    "ground": {"point": [0, -0.8, 0], "normal": [0, 1, 0], "albedo": [0.8, 0.8, 0.8], "half_extent": 4},
    "objects": [{"volume": "baked.vol.json", "translate": [0, 0, 1]},
                {"volume": "baked.vol.json", "translate": [0.5, 0, -1], "rotate_deg": [0, 30, 0], "scale": 1.2}],
    "render": {"size": [64, 48], "step_voxels": 0.5, "exposure": 0, "tonemap": "aces"}
  })");
  r = runProgram(VIEWER_EXE, {"scene.json", "--render", "scene.exr", "--quiet"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The same scene with an environment map beside it, named from the folder above: every path
  // inside the scene is the scene folder's, and is resolved once (it used to be joined to the
  // folder twice, "dir/dir/env.exr", and the render failed).
  {
    Image env;
    env.width = 8;
    env.height = 4;
    env.channels = 3;
    env.pixels.assign(8 * 4 * 3, 0.5f);
    writeImage(dir / "env.exr", env);
    std::string text = readFile(dir / "scene.json");
    const std::string sky = R"("procedural": "sky")";
    text.replace(text.find(sky), sky.size(), R"("file": "env.exr")");
    writeFile(dir / "env_scene.json", text);
    const std::filesystem::path relative = dir.path().filename() / "env_scene.json";
    ProgramResult nested = runProgram(VIEWER_EXE, {relative.string(), "--render", (dir / "nested.png").string(),
                                                   "--size", "16x12", "--quiet"},
                                      dir.path().parent_path());
    EXPECT_EQ(nested.exit_code, 0) << nested.output;
  }
  Image image = readImage(dir / "scene.exr");
  ASSERT_EQ(image.width, 64);
  ASSERT_EQ(image.height, 48);
  // The bottom row sees the lit ground: ρE/π = 0.8/π from the light plus the sky's share.
  const float* ground = image.at(2, 47);
  EXPECT_GT(ground[1], 0.8f / 3.1416f);
  EXPECT_LT(ground[1], 1.0f);
  // Every term switched off and the other integrator: only the environment and straight rays are
  // left, so the bottom row sees the checkerboard's lower cells (no ground).
  r = runProgram(VIEWER_EXE,
                 {"scene.json", "--render", "flags.exr", "--no-fresnel", "--no-ground", "--no-refraction",
                  "--no-scattering", "--no-attenuation", "--no-emission", "--no-dispersion", "--no-skip",
                  "--integrator", "rk4", "--env", "checker:1,1,1", "--step", "1", "--quiet"},
                 dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image flags = readImage(dir / "flags.exr");
  const float cell = flags.at(2, 47)[1];
  EXPECT_TRUE(std::abs(cell - 1.0f) < 1e-3f || std::abs(cell - 0.2f) < 1e-3f) << cell;
}

// A white light through clear glass bakes a grey receiver map, written with one value a texel
// (ReceiverMap::makeGrey) and uploaded as RG16F (RECEIVER_GREY); the same map written as RGB,
// which the viewer uploads as RGBA16F, must give the same image to the bit. A coloured light
// keeps its map RGB.
TEST(ViewerCli, AGreyReceiverMapRendersAsItsRgbTwin) {
  TempDir dir;
  makeGlassBall(dir);
  ProgramResult r;
  for (const char* power : {"1,1,1", "1,0.5,0.25"}) {
    r = runProgram(LIGHTSIM_EXE,
                   {"glass.vol.json", "-o", std::string(power) == "1,1,1" ? "grey.vol.json" : "coloured.vol.json",
                    "--light", "directional:0,-1,0", "--power", power, "--receiver", "0,-0.8,0:0,1,0:2", "--quiet"},
                   dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  EXPECT_EQ(readVolume(dir / "coloured.vol.json").receivers.at(0).components, 3);
  Volume rgb = readVolume(dir / "grey.vol.json");
  ASSERT_EQ(rgb.receivers.at(0).components, 1);
  ReceiverMap& map = rgb.receivers[0];
  std::vector<float> expanded(3 * map.texelCount());
  for (std::size_t t = 0; t < map.texelCount(); ++t)
    for (int c = 0; c < 3; ++c) expanded[3 * t + static_cast<std::size_t>(c)] = map.irradiance[t];
  map.irradiance = std::move(expanded);
  map.components = 3;
  writeVolume(rgb, dir / "rgb.vol.json");
  ASSERT_EQ(readVolume(dir / "rgb.vol.json").receivers.at(0).components, 3);
  auto render = [&](const std::string& volume) {
    writeFile(dir / "scene.json", R"({
      "camera": {"eye": [0, 2.0, 2.5], "target": [0, -0.8, 0], "up": [0, 1, 0], "fov_y_deg": 40},
      "environment": {"uniform": [0.2, 0.2, 0.2]},
      "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}],
      "ground": {"point": [0, -0.8, 0], "normal": [0, 1, 0], "albedo": [0.8, 0.8, 0.8], "half_extent": 4},
      "objects": [{"volume": ")" + volume + R"("}],
      "render": {"size": [48, 40], "tonemap": "linear"}})");
    ProgramResult v = runProgram(VIEWER_EXE, {"scene.json", "--render", volume + ".exr", "--quiet"}, dir.path());
    EXPECT_EQ(v.exit_code, 0) << v.output;
    return readImage(dir / (volume + ".exr"));
  };
  const Image grey = render("grey.vol.json"), twin = render("rgb.vol.json");
  ASSERT_EQ(grey.pixels.size(), twin.pixels.size());
  EXPECT_EQ(grey.pixels, twin.pixels);
  // The map is read: the ground under the ball (its caustic and shadow) differs from the open ground.
  float hi = 0.0f;  // the open ground in the bottom row
  for (int x = 0; x < grey.width; ++x) hi = std::max(hi, grey.at(x, grey.height - 1)[1]);
  float centre_lo = 1e30f, centre_hi = 0.0f;
  for (int y = grey.height / 2; y < grey.height; ++y) {
    centre_lo = std::min(centre_lo, grey.at(grey.width / 2, y)[1]);
    centre_hi = std::max(centre_hi, grey.at(grey.width / 2, y)[1]);
  }
  EXPECT_GT(centre_hi - centre_lo, 0.5f * hi) << "no caustic or shadow on the ground";
}

}  // namespace
}  // namespace eik::test
