// Tests of the RAII GL objects: create/destroy churn with error checks on, move semantics,
// binding restoration, buffers, framebuffer completeness messages, and a bit-exact Texture3D
// upload → fragment shader (texelFetch) → RGBA32F readback round trip for 1–4 channels.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "gl/buffer.h"
#include "gl/debug.h"
#include "gl/framebuffer.h"
#include "gl/program.h"
#include "gl/test_util.h"
#include "gl/texture.h"
#include "gl/vertex_array.h"

namespace eik::gl {
namespace {

class GlObjects : public ::testing::Test {
 protected:
  // Error checks on whatever the build type: every wrapper call is followed by a check.
  GlContext context_{ContextOptions{.backend = glBackendFromEnvironment(GlBackend::OSMesa), .debug = true}};
};

GLint getInt(GLenum name) {
  GLint value = 0;
  glGetIntegerv(name, &value);
  return value;
}

std::vector<float> randomData(std::size_t count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> value(-1000.0f, 1000.0f);
  std::vector<float> data(count);
  for (float& v : data) v = value(random);
  data[0] = 1e-30f;  // tiny and huge values too: the path must be exact, not just close
  if (count > 1) data[1] = -3.4e38f;
  return data;
}

bool bitEqual(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST_F(GlObjects, CreateAndDestroyManyWithoutErrors) {
  std::vector<GLuint> names;
  for (int round = 0; round < 50; ++round) {
    Texture2D texture2({8, 8}, TextureFormat::RGBA32F);
    Texture3D texture3({4, 4, 4}, TextureFormat::R32F);
    Buffer buffer(1024);
    VertexArray vao = VertexArray::create();
    Framebuffer framebuffer({8, 8}, {TextureFormat::RGBA32F, TextureFormat::R32F}, true);
    names.push_back(texture2.id());
    names.push_back(texture3.id());
    EXPECT_TRUE(glIsTexture(texture2.id()));
    EXPECT_TRUE(glIsBuffer(buffer.id()));
    EXPECT_TRUE(glIsFramebuffer(framebuffer.id()));
  }
  for (GLuint name : names) EXPECT_FALSE(glIsTexture(name)) << name;
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(GlObjects, MovedFromObjectsAreEmptyAndDeleteNothing) {
  Texture2D a({4, 4}, TextureFormat::RGBA8);
  GLuint name = a.id();
  Texture2D b = std::move(a);
  EXPECT_EQ(a.id(), 0u);  // NOLINT(bugprone-use-after-move): checking the moved-from state
  EXPECT_FALSE(a);
  EXPECT_EQ(b.id(), name);
  Texture2D c({2, 2}, TextureFormat::R32F);
  GLuint other = c.id();
  c = std::move(b);
  EXPECT_FALSE(glIsTexture(other));
  EXPECT_TRUE(glIsTexture(name));
  { Texture2D d = std::move(c); }
  EXPECT_FALSE(glIsTexture(name));
  checkErrorsAlways("after moves");
}

TEST_F(GlObjects, ObjectsOutlivingTheirContextDeleteNothing) {
  Texture2D survivor;
  {
    GlContext other(ContextOptions{.backend = glBackendFromEnvironment(GlBackend::OSMesa)});
    survivor = Texture2D({2, 2}, TextureFormat::R8);
  }
  // `other` is gone and nothing is current: the destructor must not call into GL.
  EXPECT_EQ(GlContext::current(), nullptr);
  survivor = Texture2D();
  context_.makeCurrent();
  checkErrorsAlways("after the other context");
}

TEST_F(GlObjects, WrappersRestoreBindings) {
  Texture3D bound({2, 2, 2}, TextureFormat::R32F);
  Texture2D bound2({2, 2}, TextureFormat::R32F);
  bound.bind(0);
  bound2.bind(0);
  Buffer array(16);
  array.bind(GL_ARRAY_BUFFER);
  Framebuffer target({4, 4}, {TextureFormat::RGBA32F});
  target.bind();

  Texture3D other({3, 3, 3}, TextureFormat::RGBA32F, std::vector<float>(27 * 4, 1.0f), 4);
  other.setSampling({Filter::Nearest, Wrap::Repeat});
  std::vector<float> back = other.download(4);
  Texture2D other2({2, 2}, TextureFormat::RG32F, std::vector<float>(8, 2.0f), 2);
  Buffer buffer{std::span<const float>(back)};
  buffer.upload(std::span<const float>(back).subspan(0, 4), 8);
  Framebuffer another({2, 2}, {TextureFormat::RGBA8});
  another.clear(0, glm::vec4(1.0f));
  std::vector<float> pixels = another.readRGBA();

  EXPECT_EQ(static_cast<GLuint>(getInt(GL_TEXTURE_BINDING_3D)), bound.id());
  EXPECT_EQ(static_cast<GLuint>(getInt(GL_TEXTURE_BINDING_2D)), bound2.id());
  EXPECT_EQ(static_cast<GLuint>(getInt(GL_ARRAY_BUFFER_BINDING)), array.id());
  EXPECT_EQ(static_cast<GLuint>(getInt(GL_DRAW_FRAMEBUFFER_BINDING)), target.id());
  EXPECT_EQ(static_cast<GLuint>(getInt(GL_READ_FRAMEBUFFER_BINDING)), target.id());
  EXPECT_EQ(getInt(GL_UNPACK_ALIGNMENT), 4);
  EXPECT_EQ(getInt(GL_PACK_ALIGNMENT), 4);
  EXPECT_EQ(pixels, std::vector<float>(16, 1.0f));
}

TEST_F(GlObjects, BufferRoundTrip) {
  std::vector<float> data = randomData(100, 7);
  Buffer buffer(std::span<const float>(data), GL_DYNAMIC_COPY);
  EXPECT_EQ(buffer.size(), 400u);
  EXPECT_EQ(buffer.download<float>(100), data);
  std::vector<float> part = {1, 2, 3};
  buffer.upload(std::span<const float>(part), 4 * sizeof(float));
  std::vector<float> back = buffer.download<float>(3, 4 * sizeof(float));
  EXPECT_EQ(back, part);
  EXPECT_THROW(buffer.upload(396, 8, part.data()), RuntimeError);
}

TEST_F(GlObjects, UniformSettersKeepTheProgramInUse) {
  ShaderLibrary library;
  Program a = library.program("common/fullscreen.vert", "test/pattern.frag");
  Program b = library.program("common/fullscreen.vert", "test/pattern.frag", {{"MODE", "1"}});
  a.use();
  b.set("uSize", glm::vec2(3.0f, 4.0f));
  b.set("uNotThere", 1.0f);  // ignored like GL does with location -1
  EXPECT_FALSE(b.hasUniform("uNotThere"));
  EXPECT_TRUE(b.hasUniform("uSize"));
  EXPECT_EQ(static_cast<GLuint>(getInt(GL_CURRENT_PROGRAM)), a.id());
  GLfloat value[2] = {0, 0};
  glGetUniformfv(b.id(), b.uniformLocation("uSize"), value);
  EXPECT_EQ(value[0], 3.0f);
  EXPECT_EQ(value[1], 4.0f);
}

// A program destroyed while in use is not left current: the next program's uniform setter saves
// and restores the current program, and restoring a deleted one was GL_INVALID_VALUE (found as an
// order-dependent failure of lightsim_tests run as one process).
TEST_F(GlObjects, AProgramDestroyedInUseIsNotLeftCurrent) {
  ShaderLibrary library;
  {
    Program a = library.program("common/fullscreen.vert", "test/pattern.frag");
    a.use();
  }
  EXPECT_EQ(getInt(GL_CURRENT_PROGRAM), 0);
  Program b = library.program("common/fullscreen.vert", "test/pattern.frag", {{"MODE", "1"}});
  EXPECT_NO_THROW(b.set("uSize", glm::vec2(3.0f, 4.0f)));
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(GlObjects, IncompleteFramebufferSaysWhy) {
  Framebuffer empty({4, 4});
  try {
    empty.checkComplete();
    FAIL() << "no exception";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("4x4"), std::string::npos) << e.what();
  }
  Texture2D wrongSize({8, 8}, TextureFormat::RGBA32F);
  EXPECT_THROW(empty.attach(0, wrongSize), RuntimeError);
  Texture2D right({4, 4}, TextureFormat::RGBA32F);
  empty.attach(0, right);
  EXPECT_NO_THROW(empty.checkComplete());
}

TEST_F(GlObjects, TooLarge3DTextureIsRejectedClearly) {
  const int limit = context_.info().max3DTextureSize;
  try {
    Texture3D texture({4, limit + 1, 4}, TextureFormat::RGBA32F);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("4x" + std::to_string(limit + 1) + "x4"), std::string::npos) << message;
    EXPECT_NE(message.find("GL_MAX_3D_TEXTURE_SIZE (" + std::to_string(limit) + ")"), std::string::npos) << message;
    EXPECT_NE(message.find(context_.info().renderer), std::string::npos) << message;
  }
  EXPECT_THROW(Texture2D({context_.info().maxTextureSize + 1, 1}, TextureFormat::R8), InputError);
  EXPECT_THROW(Texture3D({0, 1, 1}, TextureFormat::R8), InputError);
}

// Texture3D upload, then a fragment shader reads every voxel into an RGBA32F target.
void roundTrip3D(int channels, bool sampler) {
  const glm::ivec3 dims(7, 5, 3);
  const std::size_t voxels = static_cast<std::size_t>(dims.x * dims.y * dims.z);
  std::vector<float> data = randomData(voxels * static_cast<std::size_t>(channels), 11u + static_cast<unsigned>(channels));
  Texture3D texture(dims, floatFormat(channels), data, channels);
  EXPECT_EQ(texture.bytes(), voxels * static_cast<std::size_t>(channels) * 4);

  ShaderLibrary library;
  ShaderDefines defines;
  if (sampler) defines.push_back({"USE_SAMPLER", "1"});
  Program program = library.program("common/fullscreen.vert", "test/fetch3d.frag", defines);
  Framebuffer target({dims.x * dims.z, dims.y}, {TextureFormat::RGBA32F});
  FullscreenTriangle triangle;
  target.bind();
  program.use();
  texture.bind(3);
  program.setSampler("uTex", 3);
  program.set("uDims", dims);
  triangle.draw();
  std::vector<float> pixels = target.readRGBA();

  int bad = 0;
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        const std::size_t voxel = static_cast<std::size_t>(x + dims.x * (y + dims.y * z));
        const std::size_t pixel = static_cast<std::size_t>(x + dims.x * z + dims.x * dims.z * y);
        for (int c = 0; c < 4; ++c) {
          // Missing channels read as (0, 0, 1) for g, b, a.
          float want = c < channels ? data[voxel * static_cast<std::size_t>(channels) + static_cast<std::size_t>(c)]
                                    : (c == 3 ? 1.0f : 0.0f);
          float got = pixels[pixel * 4 + static_cast<std::size_t>(c)];
          if (!bitEqual(got, want) && ++bad <= 5) {
            ADD_FAILURE() << channels << " channels, voxel (" << x << "," << y << "," << z << ") channel " << c
                          << ": got " << got << ", want " << want;
          }
        }
      }
    }
  }
  EXPECT_EQ(bad, 0);
  // And glGetTexImage agrees.
  EXPECT_EQ(texture.download(channels), data);
}

TEST_F(GlObjects, Texture3DRoundTripIsBitExactForOneToFourChannels) {
  for (int channels = 1; channels <= 4; ++channels) roundTrip3D(channels, false);
}

TEST_F(GlObjects, Texture3DLinearSamplingAtVoxelCentresIsExact) {
  for (int channels = 1; channels <= 4; ++channels) roundTrip3D(channels, true);
}

TEST_F(GlObjects, Texture3DRegionUploadAndHalfFloats) {
  Texture3D texture({4, 4, 4}, TextureFormat::RGBA16F, std::vector<float>(64 * 4, 0.0f), 4);
  std::vector<float> box(2 * 2 * 2, 0.5f);
  texture.uploadRegion({1, 1, 1}, {2, 2, 2}, box, 1);
  std::vector<float> back = texture.download(1);
  EXPECT_EQ(back[1 + 4 * (1 + 4 * 1)], 0.5f);
  EXPECT_EQ(back[0], 0.0f);
  EXPECT_THROW(texture.uploadRegion({3, 3, 3}, {2, 2, 2}, box, 1), RuntimeError);
  EXPECT_THROW(texture.upload(box, 1), RuntimeError);  // wrong size
  EXPECT_EQ(texture.bytes(), 64u * 8u);
}

}  // namespace
}  // namespace eik::gl
