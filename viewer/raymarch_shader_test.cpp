// The assembly of the viewer's ray-casting shader, as text (no GL): the program-wide defines, one
// instance of object.glsl per object inside its own scope of defines, the dispatch repeated per
// object, no template mark left behind, and the #line bookkeeping back into raymarch.frag.
#include "viewer/raymarch_shader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/testing.h"

namespace eik {
namespace {

bool hasDefine(const gl::ShaderDefines& defines, const std::string& name, const std::string& value = "1") {
  return std::find(defines.begin(), defines.end(), std::make_pair(name, value)) != defines.end();
}

bool definesName(const gl::ShaderDefines& defines, const std::string& name) {
  return std::any_of(defines.begin(), defines.end(), [&](const auto& d) { return d.first == name; });
}

std::size_t occurrences(const std::string& text, const std::string& part) {
  std::size_t count = 0;
  for (std::size_t pos = text.find(part); pos != std::string::npos; pos = text.find(part, pos + part.size())) ++count;
  return count;
}

RaymarchObject glassObject() {
  return {gl::VolumeTextureLayout::plan({{"ior", 1}, {"ior_grad", 3}}, true), false, ""};
}

TEST(RaymarchDefines, FollowTheSettingsAndTheScene) {
  RaymarchScene scene;
  scene.objects = 3;
  scene.lights = 10;
  scene.ground = true;
  scene.dispersive = true;
  scene.environment = {{"ENV_SKY", "1"}};
  const gl::ShaderDefines all = raymarchDefines(RenderSettings{}, scene);
  EXPECT_TRUE(hasDefine(all, "OBJECT_COUNT", "3"));
  EXPECT_TRUE(hasDefine(all, "MAX_SEGMENTS", "14"));  // 2·3 + 1, twice: the ray and its reflection
  EXPECT_TRUE(hasDefine(all, "LIGHT_COUNT", "8"));  // kMaxLights
  for (const char* name :
       {"GROUND", "FRESNEL", "REFLECT_OBJECTS", "ATTENUATION", "EMISSION", "SCATTERING", "DISPERSION", "ENV_SKY"})
    EXPECT_TRUE(hasDefine(all, name)) << name;
  for (const char* name : {"NO_REFRACTION", "RK4", "SKIP_HOMOGENEOUS", "OUTPUT_EXIT_POSITION", "OUTPUT_EXIT_DIRECTION"})
    EXPECT_FALSE(definesName(all, name)) << name;

  RenderSettings settings;
  settings.integrator = RayIntegrator::RK4;
  settings.refraction = false;
  settings.fresnel = false;
  settings.ground = false;
  settings.homogeneous_bricks = true;
  settings.output = RenderOutput::ExitDirection;  // a debug output has no dispersion
  const gl::ShaderDefines some = raymarchDefines(settings, scene);
  for (const char* name : {"RK4", "NO_REFRACTION", "SKIP_HOMOGENEOUS", "OUTPUT_EXIT_DIRECTION"})
    EXPECT_TRUE(hasDefine(some, name)) << name;
  for (const char* name : {"FRESNEL", "REFLECT_OBJECTS", "GROUND", "DISPERSION"})
    EXPECT_FALSE(definesName(some, name)) << name;
  EXPECT_TRUE(hasDefine(some, "MAX_SEGMENTS", "7"));
  RenderSettings sky_only;
  sky_only.reflect_objects = false;
  EXPECT_FALSE(definesName(raymarchDefines(sky_only, scene), "REFLECT_OBJECTS"));
  EXPECT_TRUE(hasDefine(raymarchDefines(sky_only, scene), "MAX_SEGMENTS", "7"));

  scene.ground = false;
  scene.dispersive = false;
  EXPECT_FALSE(definesName(raymarchDefines(RenderSettings{}, scene), "GROUND"));
  EXPECT_FALSE(definesName(raymarchDefines(RenderSettings{}, scene), "DISPERSION"));
}

TEST(RaymarchShader, OneObject) {
  const gl::ShaderLibrary shaders;
  RaymarchScene scene;
  const gl::ShaderSource source =
      raymarchFragmentSource(shaders, raymarchDefines(RenderSettings{}, scene), {glassObject()});
  const std::string& text = source.text;
  EXPECT_EQ(text.find('@'), std::string::npos) << "a template mark or '@' was left";
  EXPECT_CONTAINS(text, "#define OBJECT_COUNT 1");
  EXPECT_CONTAINS(text, "void march0(inout Ray r, float cauchy)");
  EXPECT_CONTAINS(text, "  if (k == 0) march0(r, cauchy);\n");
  EXPECT_CONTAINS(text, "weight = bakedGroundIrradiance0(xw, E); if (weight > 0.0) return weight;\n");
  // The object's scope: common/volume.glsl's sampler and accessors renamed, its layout, undone.
  EXPECT_CONTAINS(text, "#define uVolumeTex0 uO0Tex0\n");
  EXPECT_CONTAINS(text, "#define volumeSigmaA volumeSigmaA0\n");
  EXPECT_CONTAINS(text, "#define IOR_SAMPLER uVolumeTex0\n");
  EXPECT_CONTAINS(text, "uniform sampler3D uVolumeTex0;");
  EXPECT_CONTAINS(text, "uniform sampler3D uO0Bricks;");
  for (const char* name : {"uVolumeTex0", "volumeSigmaA", "HAS_IOR", "IOR_SAMPLER", "VOLUME_TEXTURE_COUNT"})
    EXPECT_CONTAINS(text, std::string("#undef ") + name + "\n");
  EXPECT_EQ(occurrences(text, "SHARP_FACES 1"), 0u);
  EXPECT_EQ(objectTextureSampler(0, 0), "uO0Tex0");
  EXPECT_EQ(objectBricksSampler(0), "uO0Bricks");
}

TEST(RaymarchShader, ThreeObjectsEachInItsOwnScope) {
  const gl::ShaderLibrary shaders;
  RaymarchScene scene;
  scene.objects = 3;
  RaymarchObject medium{gl::VolumeTextureLayout::plan(
                            {{"ior", 1}, {"ior_grad", 3}, {"sigma_a", 3}, {"scatter", 2}, {"irradiance", 3},
                             {"light_dir", 3}},
                            true),
                        true, ""};
  RaymarchObject prism{gl::VolumeTextureLayout::plan({{"ior", 1}, {"ior_grad", 3}, {"dispersion", 1}}, true), false, ""};
  const gl::ShaderSource source =
      raymarchFragmentSource(shaders, raymarchDefines(RenderSettings{}, scene), {glassObject(), medium, prism});
  const std::string& text = source.text;
  EXPECT_EQ(text.find('@'), std::string::npos) << "a template mark or '@' was left";
  EXPECT_CONTAINS(text, "#define OBJECT_COUNT 3");
  EXPECT_CONTAINS(text, "  if (k == 0) march0(r, cauchy); if (k == 1) march1(r, cauchy); if (k == 2) march2(r, cauchy);\n");
  EXPECT_CONTAINS(text, "bakedGroundIrradiance2(xw, E)");
  EXPECT_EQ(occurrences(text, "#define HAS_IOR 1\n"), 3u);
  EXPECT_EQ(occurrences(text, "#undef HAS_IOR\n"), 3u);
  EXPECT_EQ(occurrences(text, "struct March"), 3u);

  // Object 1's fields, samplers and sharp faces are defined around its march only.
  const std::size_t march0 = text.find("void march0("), march1 = text.find("void march1("),
                    march2 = text.find("void march2(");
  ASSERT_TRUE(march0 < march1 && march1 < march2 && march2 != std::string::npos);
  const std::size_t sigma = text.find("#define HAS_SIGMA_A 1\n"), sigma_end = text.find("#undef HAS_SIGMA_A\n");
  EXPECT_TRUE(march0 < sigma && sigma < march1 && march1 < sigma_end && sigma_end < march2);
  EXPECT_EQ(occurrences(text, "#define HAS_SIGMA_A 1\n"), 1u);
  EXPECT_EQ(occurrences(text, "#define HAS_DISPERSION 1\n"), 1u);
  EXPECT_GT(text.find("#define HAS_DISPERSION 1\n"), march1);
  EXPECT_CONTAINS(text, "#define uVolumeTex4 uO1Tex4\n");  // optics, absorption, scatter, irradiance, light_dir
  EXPECT_EQ(occurrences(text, "#define uVolumeTex4 "), 1u);
  // Sharp faces belong to object 1 only: object 2 (whose material keeps clear of its box) must not
  // inherit them.
  const std::size_t sharp = text.find("#define SHARP_FACES 1\n"), sharp_end = text.find("#undef SHARP_FACES\n");
  EXPECT_TRUE(march0 < sharp && sharp < march1 && march1 < sharp_end && sharp_end < march2);
  EXPECT_EQ(occurrences(text, "#define SHARP_FACES 1\n"), 1u);
  EXPECT_EQ(objectTextureSampler(2, 1), "uO2Tex1");

  // Compiler messages name each instance, and raymarch.frag's numbering resumes after them.
  for (const char* file : {"viewer/object.glsl (object 2)", "common/volume.glsl (object 1)"})
    EXPECT_NE(std::find(source.files.begin(), source.files.end(), file), source.files.end()) << file;
  const std::string main_text = shaders.read("viewer/raymarch.frag");
  std::vector<std::string> main_lines;
  std::istringstream main_stream(main_text);
  for (std::string line; std::getline(main_stream, line);) main_lines.push_back(line);
  const std::size_t resume = text.find("\n#line ", march2);
  ASSERT_NE(resume, std::string::npos);
  std::istringstream after(text.substr(resume + 1));
  std::string directive, line;
  int number = 0, file = -1;
  after >> directive >> number >> file;
  std::getline(after, line);  // the rest of the #line line
  std::getline(after, line);
  EXPECT_EQ(file, 0);
  ASSERT_GT(number, 1);
  ASSERT_LE(number, static_cast<int>(main_lines.size()));
  EXPECT_EQ(main_lines[static_cast<std::size_t>(number - 1)], line);
  EXPECT_NE(main_lines[static_cast<std::size_t>(number - 2)].find("@OBJECTS@"), std::string::npos);
}

TEST(RaymarchShader, ConstantMediaAreSelectsOnTheMaterialAndLeaveWithTheirObject) {
  SlotMedia media;
  media.sigma_a_constant = true;
  media.media = {MaterialMedium{}, MaterialMedium{{1.0, 2.0, 0.5}, {0.25, 0.5}}};
  EXPECT_EQ(slotMediumDefines(media), "#define MEDIUM_SIGMA_A(k) ((k) == 0 ? vec3(1, 2, 0.5) : vec3(0, 0, 0))\n");
  media.scatter_constant = true;
  const std::string both = slotMediumDefines(media);
  EXPECT_CONTAINS(both, "#define MEDIUM_SCATTER(k) ((k) == 0 ? vec2(0.25, 0.5) : vec2(0, 0))\n");
  EXPECT_EQ(slotMediumDefines(SlotMedia{}), "");
  // Two objects each with its own function-like macro: each is #undef'd by its name after its
  // object (a GLSL preprocessor rejects "#undef NAME(k)" and a redefinition alike).
  RaymarchObject first = glassObject(), second = glassObject();
  first.defines = both;
  second.defines = slotMediumDefines(media);
  RaymarchScene scene;
  scene.objects = 2;
  const gl::ShaderLibrary shaders;
  const std::string text = raymarchFragmentSource(shaders, raymarchDefines(RenderSettings{}, scene), {first, second}).text;
  EXPECT_EQ(occurrences(text, "#undef MEDIUM_SIGMA_A\n"), 2u);
  EXPECT_EQ(occurrences(text, "#undef MEDIUM_SCATTER\n"), 2u);
  EXPECT_EQ(text.find("#undef MEDIUM_SIGMA_A("), std::string::npos);
}

TEST(RaymarchShader, NeedsItsSegmentAndAnObject) {
  const gl::ShaderLibrary shaders;
  EXPECT_THROW(raymarchFragmentSource(shaders, {}, {}), RuntimeError);
  test_support::TempDir dir;
  std::filesystem::create_directories(dir / "viewer");
  test_support::writeFile(dir / "viewer" / "raymarch.frag", "#version 330 core\nvoid main() {}\n");
  gl::ShaderLibraryOptions options;
  options.directories = {dir.path()};
  const gl::ShaderLibrary without_segment(options);
  try {
    raymarchFragmentSource(without_segment, {}, {glassObject()});
    FAIL() << "expected a RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_CONTAINS(e.what(), "@OBJECTS@");
  }
}

}  // namespace
}  // namespace eik
