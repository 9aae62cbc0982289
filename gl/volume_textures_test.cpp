// Tests of gl/volume_textures: the packing layout for several field sets, its GLSL defines, the
// size and budget checks, and an upload sampled back through shaders/common/volume.glsl.
#include "gl/volume_textures.h"

#include <gtest/gtest.h>

#include <random>

#include "core/testing.h"
#include "gl/test_util.h"

namespace eik::gl {
namespace {

using Fields = std::vector<std::pair<std::string, int>>;

std::string describe(const VolumeTextureLayout& layout) {
  std::string text;
  for (const VolumeTextureSlot& texture : layout.textures()) {
    text += texture.group + "[" + std::to_string(texture.channels) + "]:";
    for (const VolumeFieldSlot& slot : texture.fields) text += " " + slot.field + "." + slot.swizzle();
    text += "; ";
  }
  return text;
}

TEST(VolumeTextureLayoutTest, AllKnownFields) {
  Fields fields = {{"ior", 1},        {"ior_grad", 3},   {"sigma_a", 3},   {"emission", 3},  {"scatter", 2},
                   {"opaque", 4},     {"reflect", 4},    {"dispersion", 1}, {"irradiance", 3}, {"light_dir", 3}};
  VolumeTextureLayout layout = VolumeTextureLayout::plan(fields);
  EXPECT_EQ(describe(layout),
            "optics[4]: ior.r ior_grad.gba; absorption[4]: sigma_a.rgb dispersion.a; emission[3]: emission.rgb; "
            "scatter[2]: scatter.rg; irradiance[3]: irradiance.rgb; light_dir[3]: light_dir.rgb; "
            "opaque[4]: opaque.rgba; reflect[4]: reflect.rgba; ");
  EXPECT_EQ(layout.textureCount(), 8);
  EXPECT_TRUE(layout.ignored().empty());
  const VolumeFieldSlot* sigma = layout.find("sigma_a");
  ASSERT_NE(sigma, nullptr);
  EXPECT_EQ(sigma->texture, 1);
  EXPECT_EQ(sigma->channel, 0);
  EXPECT_EQ(sigma->components, 3);
}

TEST(VolumeTextureLayoutTest, RefractionOnlyIsOneTexture) {
  VolumeTextureLayout layout = VolumeTextureLayout::plan(Fields{{"ior_grad", 3}, {"ior", 1}});
  EXPECT_EQ(describe(layout), "optics[4]: ior.r ior_grad.gba; ");
  EXPECT_EQ(layout.glslDefines(),
            "#define VOLUME_TEXTURE_COUNT 1\n"
            "#define HAS_IOR 1\n#define IOR_TEX 0\n#define IOR_SAMPLER uVolumeTex0\n#define IOR_CHANNEL 0\n"
            "#define IOR_SWZ r\n"
            "#define HAS_IOR_GRAD 1\n#define IOR_GRAD_TEX 0\n#define IOR_GRAD_SAMPLER uVolumeTex0\n"
            "#define IOR_GRAD_CHANNEL 1\n#define IOR_GRAD_SWZ gba\n");
}

TEST(VolumeTextureLayoutTest, PartialGroupsCompactAndNumberConsecutively) {
  VolumeTextureLayout layout =
      VolumeTextureLayout::plan(Fields{{"ior_grad", 3}, {"dispersion", 1}, {"opaque", 4}, {"temperature", 1}});
  EXPECT_EQ(describe(layout), "optics[3]: ior_grad.rgb; absorption[1]: dispersion.r; opaque[4]: opaque.rgba; ");
  EXPECT_EQ(layout.find("opaque")->texture, 2);
  EXPECT_EQ(layout.find("ior"), nullptr);
  EXPECT_EQ(layout.ignored(), std::vector<std::string>{"temperature"});
  std::string defines = layout.glslDefines();
  EXPECT_EQ(defines.find("HAS_IOR "), std::string::npos);
  EXPECT_EQ(defines.find("TEMPERATURE"), std::string::npos);
  EXPECT_NE(defines.find("#define OPAQUE_SAMPLER uVolumeTex2\n"), std::string::npos);
  EXPECT_NE(defines.find("#define DISPERSION_SWZ r\n"), std::string::npos);
}

TEST(VolumeTextureLayoutTest, BakedVolumeAndPadding) {
  Fields fields = {{"ior", 1}, {"sigma_a", 3}, {"irradiance", 3}, {"light_dir", 3}, {"scatter", 2}};
  EXPECT_EQ(describe(VolumeTextureLayout::plan(fields)),
            "optics[1]: ior.r; absorption[3]: sigma_a.rgb; scatter[2]: scatter.rg; irradiance[3]: irradiance.rgb; "
            "light_dir[3]: light_dir.rgb; ");
  EXPECT_EQ(describe(VolumeTextureLayout::plan(fields, true)),
            "optics[4]: ior.r; absorption[4]: sigma_a.rgb; scatter[4]: scatter.rg; irradiance[4]: irradiance.rgb; "
            "light_dir[4]: light_dir.rgb; ");
  EXPECT_EQ(VolumeTextureLayout::plan(Fields{}).textureCount(), 0);
  EXPECT_EQ(VolumeTextureLayout::plan(Fields{}).glslDefines(), "#define VOLUME_TEXTURE_COUNT 0\n");
}

// A field left out (VolumeTextureOptions::leave_out: what the shader takes elsewhere) is not in the
// layout: its group goes when nothing else is in it, and no HAS_ define names it.
TEST(VolumeTextureLayoutTest, AFieldLeftOutIsNotUploaded) {
  Volume volume;
  volume.grid.dims = {2, 2, 2};
  volume.addField("ior", 1);
  volume.addField("ior_grad", 3);
  volume.addField("sigma_a", 3);
  EXPECT_EQ(VolumeTextureLayout::plan(volume, true).textureCount(), 2);
  const VolumeTextureLayout without = VolumeTextureLayout::plan(volume, true, {"sigma_a"});
  EXPECT_EQ(without.textureCount(), 1);
  EXPECT_EQ(without.find("sigma_a"), nullptr);
  EXPECT_EQ(without.glslDefines().find("SIGMA_A"), std::string::npos);
  volume.addField("dispersion", 1);  // shares the absorption texture, which stays for it
  EXPECT_EQ(describe(VolumeTextureLayout::plan(volume, false, {"sigma_a"})),
            "optics[4]: ior.r ior_grad.gba; absorption[1]: dispersion.r; ");
}

TEST(VolumeTextureLayoutTest, TheUsedSlotsDistancesAloneAreOneOrTwoChannels) {
  Volume volume;
  volume.grid.dims = {2, 2, 2};
  for (const auto& [name, components] : Fields{{"ior", 1}, {"ior_grad", 3}, {"interfaces", 4}}) volume.addField(name, components);
  // One used slot: an R texture, not padded to RGBA; its swizzle reads the first distance.
  const VolumeTextureLayout one = VolumeTextureLayout::plan(volume, true, {"ior", "ior_grad"}, 1);
  EXPECT_EQ(describe(one), "interfaces[1]: interfaces.r; ");
  EXPECT_NE(one.glslDefines().find("#define INTERFACES_SWZ r\n"), std::string::npos);
  EXPECT_EQ(describe(VolumeTextureLayout::plan(volume, true, {"ior", "ior_grad"}, 2)), "interfaces[2]: interfaces.rg; ");
  // Three slots: RGB would be slow to sample, so RGBA as before; 0 or 4: the whole field.
  EXPECT_EQ(describe(VolumeTextureLayout::plan(volume, true, {"ior", "ior_grad"}, 3)), "interfaces[4]: interfaces.rgb; ");
  EXPECT_EQ(describe(VolumeTextureLayout::plan(volume, true, {"ior", "ior_grad"}, 0)), "interfaces[4]: interfaces.rgba; ");
  EXPECT_EQ(describe(VolumeTextureLayout::plan(volume, true, {"ior", "ior_grad"}, 4)), "interfaces[4]: interfaces.rgba; ");
  // Another field cannot be cut short.
  EXPECT_THROW(VolumeTextureLayout::plan(Fields{{"sigma_a", 2}}), RuntimeError);
}

TEST(VolumeTextureLayoutTest, WrongComponentCountIsAnError) {
  EXPECT_THROW(VolumeTextureLayout::plan(Fields{{"ior_grad", 4}}), RuntimeError);
}

Volume makeVolume(glm::ivec3 dims, const Fields& fields, unsigned seed) {
  Volume volume;
  volume.grid.dims = dims;
  volume.grid.bounds_min = glm::dvec3(-1.0);
  volume.grid.bounds_max = glm::dvec3(1.0);
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> value(-2.0f, 2.0f);
  for (const auto& [name, components] : fields) {
    Field field;
    field.components = components;
    field.data.resize(volume.grid.count() * static_cast<std::size_t>(components));
    for (float& v : field.data) v = value(random);
    volume.fields[name] = std::move(field);
  }
  return volume;
}

class VolumeTexturesGl : public ::testing::Test {
 protected:
  GlContext context_{ContextOptions{.backend = glBackendFromEnvironment(GlBackend::OSMesa), .debug = true}};
};

// Samples every voxel centre through common/volume.glsl with PROBE(uvw) and compares with the
// field values (linear filtering at a centre returns the texel exactly).
void probe(const Volume& volume, const VolumeTextures& textures, const std::string& expression,
           const std::vector<std::pair<std::string, int>>& expected /* field, component; "" = constant */,
           const std::vector<float>& constants = {}, const std::string& extra_defines = "") {
  ShaderLibrary library;
  Program program = library.program("common/fullscreen.vert", "test/volume_probe.frag", {{"PROBE(uvw)", expression}},
                                    textures.layout().glslDefines() + extra_defines);
  const glm::ivec3 dims = volume.grid.dims;
  Framebuffer target({dims.x * dims.z, dims.y}, {TextureFormat::RGBA32F});
  FullscreenTriangle triangle;
  target.bind();
  program.use();
  EXPECT_EQ(textures.bind(program, 2), 2 + textures.layout().textureCount());
  program.set("uDims", dims);
  triangle.draw();
  std::vector<float> pixels = target.readRGBA();
  int bad = 0;
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        const std::size_t voxel = volume.grid.index(x, y, z);
        const std::size_t pixel = static_cast<std::size_t>(x + dims.x * z + dims.x * dims.z * y);
        for (std::size_t c = 0; c < 4; ++c) {
          float want = constants.size() > c ? constants[c] : 0.0f;
          if (!expected[c].first.empty()) {
            const Field& field = volume.fields.at(expected[c].first);
            want = field.data[voxel * static_cast<std::size_t>(field.components) +
                              static_cast<std::size_t>(expected[c].second)];
          }
          if (pixels[pixel * 4 + c] != want && ++bad <= 5) {
            ADD_FAILURE() << expression << ": voxel (" << x << "," << y << "," << z << ") channel " << c << ": got "
                          << pixels[pixel * 4 + c] << ", want " << want;
          }
        }
      }
    }
  }
  EXPECT_EQ(bad, 0) << expression;
}

TEST_F(VolumeTexturesGl, UploadedFieldsSampleBackExactly) {
  Volume volume = makeVolume({5, 4, 3},
                             {{"ior", 1}, {"ior_grad", 3}, {"sigma_a", 3}, {"dispersion", 1}, {"scatter", 2},
                              {"opaque", 4}, {"notes", 2}},
                             3);
  VolumeTextures textures(volume);
  EXPECT_EQ(textures.layout().textureCount(), 4);
  EXPECT_EQ(textures.bytes(), 60u * (16 + 16 + 8 + 16));
  probe(volume, textures, "vec4(volumeIor(uvw), volumeIorGrad(uvw))",
        {{"ior", 0}, {"ior_grad", 0}, {"ior_grad", 1}, {"ior_grad", 2}});
  probe(volume, textures, "vec4(volumeSigmaA(uvw), volumeDispersion(uvw))",
        {{"sigma_a", 0}, {"sigma_a", 1}, {"sigma_a", 2}, {"dispersion", 0}});
  probe(volume, textures, "vec4(volumeScatter(uvw), volumeEmission(uvw).x, volumeIrradiance(uvw).y)",
        {{"scatter", 0}, {"scatter", 1}, {"", 0}, {"", 0}});
  probe(volume, textures, "volumeOpaque(uvw)", {{"opaque", 0}, {"opaque", 1}, {"opaque", 2}, {"opaque", 3}});
  probe(volume, textures, "volumeReflect(uvw) + vec4(0.0, 0.0, 0.0, volumeLightDir(uvw).x)",
        {{"", 0}, {"", 0}, {"", 0}, {"", 0}});
}

// The used slots' distances alone (VolumeTextureOptions::interface_slots): an RG32F texture of the
// first two, the shader filling the others in with INTERFACES_UNUSED.
TEST_F(VolumeTexturesGl, TheUsedSlotsDistancesAloneSampleBackWithTheUnusedConstant) {
  Volume volume = makeVolume({5, 4, 3}, {{"interfaces", 4}}, 7);
  VolumeTextureOptions options;
  options.padToRGBA = true;
  options.interface_slots = 2;
  VolumeTextures textures(volume, options);
  ASSERT_EQ(textures.textures().size(), 1u);
  EXPECT_EQ(textures.texture(0).format(), TextureFormat::RG32F);
  EXPECT_EQ(textures.bytes(), 60u * 8);
  probe(volume, textures, "volumeInterfaces(uvw)", {{"interfaces", 0}, {"interfaces", 1}, {"", 0}, {"", 0}},
        {0.0f, 0.0f, 0.25f, 0.25f}, "#define INTERFACES_UNUSED 0.25\n");
}

TEST_F(VolumeTexturesGl, RefractionOnlyVolumeAndHalfFloats) {
  Volume volume = makeVolume({4, 3, 2}, {{"ior", 1}}, 5);
  VolumeTextureOptions options;
  options.half = true;
  VolumeTextures textures(volume, options);
  ASSERT_EQ(textures.textures().size(), 1u);
  EXPECT_EQ(textures.texture(0).format(), TextureFormat::R16F);
  // Absent fields read as neutral values.
  for (float& v : volume.fields["ior"].data) v = 1.5f;  // exactly representable in half floats
  VolumeTextures exact(volume, options);
  probe(volume, exact, "vec4(volumeIor(uvw), volumeIorGrad(uvw))", {{"ior", 0}, {"", 0}, {"", 0}, {"", 0}});
}

TEST_F(VolumeTexturesGl, TooLargeVolumeNamesSizeAndLimit) {
  const int limit = context_.info().max3DTextureSize;
  Volume volume;
  volume.grid.dims = {8, limit + 1, 8};
  volume.fields["ior"] = Field{1, {}};  // never read: the size check comes first
  VolumeTextureOptions options;
  options.source = "big.vol.json";
  try {
    VolumeTextures textures(volume, options);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("big.vol.json"), std::string::npos) << message;
    EXPECT_NE(message.find("8x" + std::to_string(limit + 1) + "x8"), std::string::npos) << message;
    EXPECT_NE(message.find("GL_MAX_3D_TEXTURE_SIZE (" + std::to_string(limit) + ")"), std::string::npos) << message;
  }
}

TEST_F(VolumeTexturesGl, OverBudgetVolumeNamesSizeAndBudget) {
  Volume volume = makeVolume({8, 8, 8}, {{"ior", 1}, {"ior_grad", 3}}, 1);
  VolumeTextureOptions options;
  options.budgetBytes = 4096;  // 8 KiB needed
  options.source = "sphere.vol.json";
  try {
    VolumeTextures textures(volume, options);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("sphere.vol.json"), std::string::npos) << message;
    EXPECT_NE(message.find("8x8x8"), std::string::npos) << message;
    EXPECT_NE(message.find("budget"), std::string::npos) << message;
  }
  test_support::ScopedEnv env("EIKONAL_GL_TEXTURE_BUDGET_MB", "1");
  EXPECT_EQ(defaultTextureBudget(), std::size_t(1) << 20);
  EXPECT_NO_THROW(VolumeTextures(volume, VolumeTextureOptions{}));
}

TEST_F(VolumeTexturesGl, FieldOfTheWrongSizeIsAnInputError) {
  Volume volume = makeVolume({4, 4, 4}, {{"ior", 1}}, 1);
  volume.fields["ior"].data.pop_back();
  try {
    VolumeTextures textures(volume);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ior"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace eik::gl
