// 2D and 3D textures (RAII): formats, float uploads of 1–4 channels, downloads, sampling state.
// Defaults: linear filtering, clamp to edge, one mip level. Sizes are checked against the
// context's GL_MAX_TEXTURE_SIZE / GL_MAX_3D_TEXTURE_SIZE with an InputError naming both.
// Data layout everywhere: texels x fastest, then y (rows from the bottom, GL order), then z;
// `channels` floats a texel, interleaved.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "gl/handle.h"

namespace eik::gl {

enum class TextureFormat {
  R8, RG8, RGBA8,
  R16F, RG16F, RGB16F, RGBA16F,
  R32F, RG32F, RGB32F, RGBA32F,
  R32I, R32UI, RGBA32UI,
  Depth24, Depth32F,
};

struct TextureFormatInfo {
  GLenum internalFormat;
  GLenum pixelFormat;  // matching client format for uploads of `channels` components
  GLenum pixelType;
  int channels;
  int bytesPerTexel;   // in GPU memory (nominal)
  bool integer;
  const char* name;    // "RGBA32F"
};
const TextureFormatInfo& formatInfo(TextureFormat format);
// R32F/RG32F/RGB32F/RGBA32F for 1–4 channels (R16F... with half = true).
TextureFormat floatFormat(int channels, bool half = false);
// GL_RED / GL_RG / GL_RGB / GL_RGBA for 1–4 channels (the _INTEGER forms with integer = true).
GLenum pixelFormatForChannels(int channels, bool integer = false);

enum class Filter { Nearest, Linear };
enum class Wrap { ClampToEdge, Repeat, MirroredRepeat };
struct Sampling {
  Filter filter = Filter::Linear;
  Wrap wrap = Wrap::ClampToEdge;
};

namespace detail {
struct TextureTraits {
  static void destroy(GLuint name) { glDeleteTextures(1, &name); }
};
}  // namespace detail

class Texture2D {
 public:
  Texture2D() = default;
  // Allocates size.x × size.y texels of `format` (contents undefined).
  Texture2D(glm::ivec2 size, TextureFormat format, Sampling sampling = {});
  // Allocates and uploads `data` (size.x · size.y · channels floats).
  Texture2D(glm::ivec2 size, TextureFormat format, std::span<const float> data, int channels, Sampling sampling = {});

  void upload(std::span<const float> data, int channels);
  // Any client format/type (e.g. GL_RED_INTEGER/GL_UNSIGNED_INT); `bytes` is checked against the size.
  void uploadRaw(const void* data, std::size_t bytes, GLenum pixelFormat, GLenum pixelType);
  // The whole level 0 as floats, `channels` a texel (glGetTexImage).
  std::vector<float> download(int channels = 4) const;
  void setSampling(Sampling sampling);

  // Binds to texture unit `unit` (leaves GL_TEXTURE0 + unit active).
  void bind(int unit) const;

  GLuint id() const { return handle_.get(); }
  explicit operator bool() const { return bool(handle_); }
  glm::ivec2 size() const { return size_; }
  TextureFormat format() const { return format_; }

 private:
  GlHandle<detail::TextureTraits> handle_;
  glm::ivec2 size_{0};
  TextureFormat format_ = TextureFormat::RGBA32F;
};

class Texture3D {
 public:
  Texture3D() = default;
  // Allocates dims.x × dims.y × dims.z texels. InputError when a dimension exceeds
  // GL_MAX_3D_TEXTURE_SIZE; RuntimeError when GL runs out of memory.
  Texture3D(glm::ivec3 dims, TextureFormat format, Sampling sampling = {});
  Texture3D(glm::ivec3 dims, TextureFormat format, std::span<const float> data, int channels, Sampling sampling = {});

  void upload(std::span<const float> data, int channels);
  // A box of texels at `offset` of extent `extent` (data packed for that box).
  void uploadRegion(glm::ivec3 offset, glm::ivec3 extent, std::span<const float> data, int channels);
  void uploadRaw(const void* data, std::size_t bytes, GLenum pixelFormat, GLenum pixelType);
  std::vector<float> download(int channels = 4) const;
  void setSampling(Sampling sampling);
  void bind(int unit) const;

  GLuint id() const { return handle_.get(); }
  explicit operator bool() const { return bool(handle_); }
  glm::ivec3 dims() const { return dims_; }
  TextureFormat format() const { return format_; }
  std::size_t bytes() const;

 private:
  GlHandle<detail::TextureTraits> handle_;
  glm::ivec3 dims_{0};
  TextureFormat format_ = TextureFormat::RGBA32F;
};

// "64x64x4096 3D texture: 4096 exceeds GL_MAX_3D_TEXTURE_SIZE (2048) of llvmpipe (...)" checks,
// usable before allocating anything (the volume upload checks its whole set first).
void checkTexture3DSize(glm::ivec3 dims, const std::string& what);
void checkTexture2DSize(glm::ivec2 size, const std::string& what);

}  // namespace eik::gl
