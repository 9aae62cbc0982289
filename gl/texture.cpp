// 2D and 3D textures (see texture.h).
#include "gl/texture.h"

#include <array>
#include <string>

#include <glm/glm.hpp>

#include "core/error.h"
#include "gl/debug.h"

namespace eik::gl {
namespace {

const std::array<TextureFormatInfo, 16> kFormats = {{
    {GL_R8, GL_RED, GL_UNSIGNED_BYTE, 1, 1, false, "R8"},
    {GL_RG8, GL_RG, GL_UNSIGNED_BYTE, 2, 2, false, "RG8"},
    {GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, 4, 4, false, "RGBA8"},
    {GL_R16F, GL_RED, GL_FLOAT, 1, 2, false, "R16F"},
    {GL_RG16F, GL_RG, GL_FLOAT, 2, 4, false, "RG16F"},
    {GL_RGB16F, GL_RGB, GL_FLOAT, 3, 6, false, "RGB16F"},
    {GL_RGBA16F, GL_RGBA, GL_FLOAT, 4, 8, false, "RGBA16F"},
    {GL_R32F, GL_RED, GL_FLOAT, 1, 4, false, "R32F"},
    {GL_RG32F, GL_RG, GL_FLOAT, 2, 8, false, "RG32F"},
    {GL_RGB32F, GL_RGB, GL_FLOAT, 3, 12, false, "RGB32F"},
    {GL_RGBA32F, GL_RGBA, GL_FLOAT, 4, 16, false, "RGBA32F"},
    {GL_R32I, GL_RED_INTEGER, GL_INT, 1, 4, true, "R32I"},
    {GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, 1, 4, true, "R32UI"},
    {GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT, 4, 16, true, "RGBA32UI"},
    {GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_FLOAT, 1, 4, false, "Depth24"},
    {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, 1, 4, false, "Depth32F"},
}};

GLint glFilter(Filter filter) { return filter == Filter::Nearest ? GL_NEAREST : GL_LINEAR; }

GLint glWrap(Wrap wrap) {
  switch (wrap) {
    case Wrap::Repeat: return GL_REPEAT;
    case Wrap::MirroredRepeat: return GL_MIRRORED_REPEAT;
    case Wrap::ClampToEdge: break;
  }
  return GL_CLAMP_TO_EDGE;
}

void applySampling(GLenum target, Sampling sampling, bool integer) {
  // Integer textures cannot be filtered: always nearest.
  GLint filter = integer ? GL_NEAREST : glFilter(sampling.filter);
  glTexParameteri(target, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(target, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(target, GL_TEXTURE_WRAP_S, glWrap(sampling.wrap));
  glTexParameteri(target, GL_TEXTURE_WRAP_T, glWrap(sampling.wrap));
  if (target == GL_TEXTURE_3D) glTexParameteri(target, GL_TEXTURE_WRAP_R, glWrap(sampling.wrap));
  glTexParameteri(target, GL_TEXTURE_BASE_LEVEL, 0);
  glTexParameteri(target, GL_TEXTURE_MAX_LEVEL, 0);
}

void checkChannels(int channels, const char* where) {
  if (channels < 1 || channels > 4) {
    throw RuntimeError(std::string(where) + ": " + std::to_string(channels) + " channels (expected 1 to 4)");
  }
}

void checkCount(std::size_t have, std::size_t want, const char* where) {
  if (have != want) {
    throw RuntimeError(std::string(where) + ": got " + std::to_string(have) + " floats, the texture needs " +
                       std::to_string(want));
  }
}

std::string dimsText(glm::ivec3 dims) {
  return std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" + std::to_string(dims.z);
}

std::size_t texelCount(glm::ivec3 dims) {
  return static_cast<std::size_t>(dims.x) * static_cast<std::size_t>(dims.y) * static_cast<std::size_t>(dims.z);
}

// Allocation can fail for lack of memory in any build: always check it.
void checkAllocation(const char* where, const std::string& what) {
  GLenum error = glGetError();
  if (error == GL_OUT_OF_MEMORY) throw RuntimeError(std::string(where) + ": out of GPU memory for " + what);
  if (error != GL_NO_ERROR) {
    throw RuntimeError(std::string(where) + ": " + glErrorName(error) + " allocating " + what);
  }
  checkErrors(where);
}

// Bytes a pixel of client data in `pixelFormat`/`pixelType` takes.
std::size_t clientPixelBytes(GLenum pixelFormat, GLenum pixelType) {
  std::size_t components = 1;
  switch (pixelFormat) {
    case GL_RG: case GL_RG_INTEGER: components = 2; break;
    case GL_RGB: case GL_RGB_INTEGER: case GL_BGR: components = 3; break;
    case GL_RGBA: case GL_RGBA_INTEGER: case GL_BGRA: components = 4; break;
    default: break;
  }
  switch (pixelType) {
    case GL_UNSIGNED_BYTE: case GL_BYTE: return components;
    case GL_UNSIGNED_SHORT: case GL_SHORT: case GL_HALF_FLOAT: return 2 * components;
    default: return 4 * components;
  }
}

void checkRawBytes(std::size_t bytes, std::size_t texels, GLenum pixelFormat, GLenum pixelType, const char* where) {
  std::size_t want = texels * clientPixelBytes(pixelFormat, pixelType);
  if (bytes != want) {
    throw RuntimeError(std::string(where) + ": got " + std::to_string(bytes) + " bytes, the texture needs " +
                       std::to_string(want));
  }
}

}  // namespace

const TextureFormatInfo& formatInfo(TextureFormat format) { return kFormats.at(static_cast<std::size_t>(format)); }

TextureFormat floatFormat(int channels, bool half) {
  checkChannels(channels, "floatFormat");
  static constexpr TextureFormat full[] = {TextureFormat::R32F, TextureFormat::RG32F, TextureFormat::RGB32F,
                                           TextureFormat::RGBA32F};
  static constexpr TextureFormat halfs[] = {TextureFormat::R16F, TextureFormat::RG16F, TextureFormat::RGB16F,
                                            TextureFormat::RGBA16F};
  return (half ? halfs : full)[channels - 1];
}

GLenum pixelFormatForChannels(int channels, bool integer) {
  checkChannels(channels, "pixelFormatForChannels");
  static constexpr GLenum plain[] = {GL_RED, GL_RG, GL_RGB, GL_RGBA};
  static constexpr GLenum ints[] = {GL_RED_INTEGER, GL_RG_INTEGER, GL_RGB_INTEGER, GL_RGBA_INTEGER};
  return (integer ? ints : plain)[channels - 1];
}

void checkTexture2DSize(glm::ivec2 size, const std::string& what) {
  const GlContext& context = detail::requireContext("a 2D texture");
  int limit = context.info().maxTextureSize;
  if (size.x < 1 || size.y < 1) {
    throw InputError(what, "", "size " + std::to_string(size.x) + "x" + std::to_string(size.y) + " is empty");
  }
  if (size.x > limit || size.y > limit) {
    throw InputError(what, "",
                     "size " + std::to_string(size.x) + "x" + std::to_string(size.y) +
                         " exceeds GL_MAX_TEXTURE_SIZE (" + std::to_string(limit) + ") of " + context.info().renderer);
  }
}

void checkTexture3DSize(glm::ivec3 dims, const std::string& what) {
  const GlContext& context = detail::requireContext("a 3D texture");
  int limit = context.info().max3DTextureSize;
  if (dims.x < 1 || dims.y < 1 || dims.z < 1) throw InputError(what, "", "size " + dimsText(dims) + " is empty");
  if (dims.x > limit || dims.y > limit || dims.z > limit) {
    throw InputError(what, "",
                     "size " + dimsText(dims) + " exceeds GL_MAX_3D_TEXTURE_SIZE (" + std::to_string(limit) +
                         ") of " + context.info().renderer);
  }
}

// ---- Texture2D ----

Texture2D::Texture2D(glm::ivec2 size, TextureFormat format, Sampling sampling) : size_(size), format_(format) {
  checkTexture2DSize(size, std::string("2D texture (") + formatInfo(format).name + ")");
  GLuint name = 0;
  glGenTextures(1, &name);
  handle_ = GlHandle<detail::TextureTraits>(name);
  const TextureFormatInfo& info = formatInfo(format);
  detail::ScopedBinding binding(GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, detail::bindTexture, name);
  applySampling(GL_TEXTURE_2D, sampling, info.integer);
  while (glGetError() != GL_NO_ERROR) {
  }
  glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(info.internalFormat), size.x, size.y, 0, info.pixelFormat,
               info.pixelType, nullptr);
  checkAllocation("Texture2D", std::to_string(size.x) + "x" + std::to_string(size.y) + " " + info.name);
}

Texture2D::Texture2D(glm::ivec2 size, TextureFormat format, std::span<const float> data, int channels,
                     Sampling sampling)
    : Texture2D(size, format, sampling) {
  upload(data, channels);
}

void Texture2D::upload(std::span<const float> data, int channels) {
  checkChannels(channels, "Texture2D::upload");
  checkCount(data.size(), static_cast<std::size_t>(size_.x) * static_cast<std::size_t>(size_.y) * channels,
             "Texture2D::upload");
  uploadRaw(data.data(), data.size_bytes(), pixelFormatForChannels(channels), GL_FLOAT);
}

void Texture2D::uploadRaw(const void* data, std::size_t bytes, GLenum pixelFormat, GLenum pixelType) {
  checkRawBytes(bytes, static_cast<std::size_t>(size_.x) * static_cast<std::size_t>(size_.y), pixelFormat, pixelType,
                "Texture2D::upload");
  detail::ScopedBinding binding(GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, detail::bindTexture, id());
  detail::ScopedPixelStore alignment(GL_UNPACK_ALIGNMENT, 1);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size_.x, size_.y, pixelFormat, pixelType, data);
  checkErrors("Texture2D::upload");
}

std::vector<float> Texture2D::download(int channels) const {
  checkChannels(channels, "Texture2D::download");
  std::vector<float> data(static_cast<std::size_t>(size_.x) * static_cast<std::size_t>(size_.y) * channels);
  detail::ScopedBinding binding(GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, detail::bindTexture, id());
  detail::ScopedPixelStore alignment(GL_PACK_ALIGNMENT, 1);
  glGetTexImage(GL_TEXTURE_2D, 0, pixelFormatForChannels(channels), GL_FLOAT, data.data());
  checkErrors("Texture2D::download");
  return data;
}

void Texture2D::setSampling(Sampling sampling) {
  detail::ScopedBinding binding(GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, detail::bindTexture, id());
  applySampling(GL_TEXTURE_2D, sampling, formatInfo(format_).integer);
  checkErrors("Texture2D::setSampling");
}

void Texture2D::bind(int unit) const {
  glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
  glBindTexture(GL_TEXTURE_2D, id());
  checkErrors("Texture2D::bind");
}

// ---- Texture3D ----

Texture3D::Texture3D(glm::ivec3 dims, TextureFormat format, Sampling sampling) : dims_(dims), format_(format) {
  const TextureFormatInfo& info = formatInfo(format);
  checkTexture3DSize(dims, std::string("3D texture (") + info.name + ")");
  GLuint name = 0;
  glGenTextures(1, &name);
  handle_ = GlHandle<detail::TextureTraits>(name);
  detail::ScopedBinding binding(GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D, detail::bindTexture, name);
  applySampling(GL_TEXTURE_3D, sampling, info.integer);
  while (glGetError() != GL_NO_ERROR) {
  }
  glTexImage3D(GL_TEXTURE_3D, 0, static_cast<GLint>(info.internalFormat), dims.x, dims.y, dims.z, 0, info.pixelFormat,
               info.pixelType, nullptr);
  checkAllocation("Texture3D", dimsText(dims) + " " + info.name);
}

Texture3D::Texture3D(glm::ivec3 dims, TextureFormat format, std::span<const float> data, int channels,
                     Sampling sampling)
    : Texture3D(dims, format, sampling) {
  upload(data, channels);
}

std::size_t Texture3D::bytes() const { return texelCount(dims_) * static_cast<std::size_t>(formatInfo(format_).bytesPerTexel); }

void Texture3D::upload(std::span<const float> data, int channels) {
  uploadRegion(glm::ivec3(0), dims_, data, channels);
}

void Texture3D::uploadRegion(glm::ivec3 offset, glm::ivec3 extent, std::span<const float> data, int channels) {
  checkChannels(channels, "Texture3D::upload");
  checkCount(data.size(), texelCount(extent) * static_cast<std::size_t>(channels), "Texture3D::upload");
  if (glm::any(glm::lessThan(offset, glm::ivec3(0))) || glm::any(glm::greaterThan(offset + extent, dims_))) {
    throw RuntimeError("Texture3D::uploadRegion: box at " + dimsText(offset) + " of " + dimsText(extent) +
                       " leaves the texture of " + dimsText(dims_));
  }
  detail::ScopedBinding binding(GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D, detail::bindTexture, id());
  detail::ScopedPixelStore alignment(GL_UNPACK_ALIGNMENT, 1);
  glTexSubImage3D(GL_TEXTURE_3D, 0, offset.x, offset.y, offset.z, extent.x, extent.y, extent.z,
                  pixelFormatForChannels(channels), GL_FLOAT, data.data());
  checkErrors("Texture3D::upload");
}

void Texture3D::uploadRaw(const void* data, std::size_t bytes, GLenum pixelFormat, GLenum pixelType) {
  checkRawBytes(bytes, texelCount(dims_), pixelFormat, pixelType, "Texture3D::uploadRaw");
  detail::ScopedBinding binding(GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D, detail::bindTexture, id());
  detail::ScopedPixelStore alignment(GL_UNPACK_ALIGNMENT, 1);
  glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, dims_.x, dims_.y, dims_.z, pixelFormat, pixelType, data);
  checkErrors("Texture3D::uploadRaw");
}

std::vector<float> Texture3D::download(int channels) const {
  checkChannels(channels, "Texture3D::download");
  std::vector<float> data(texelCount(dims_) * static_cast<std::size_t>(channels));
  detail::ScopedBinding binding(GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D, detail::bindTexture, id());
  detail::ScopedPixelStore alignment(GL_PACK_ALIGNMENT, 1);
  glGetTexImage(GL_TEXTURE_3D, 0, pixelFormatForChannels(channels), GL_FLOAT, data.data());
  checkErrors("Texture3D::download");
  return data;
}

void Texture3D::setSampling(Sampling sampling) {
  detail::ScopedBinding binding(GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D, detail::bindTexture, id());
  applySampling(GL_TEXTURE_3D, sampling, formatInfo(format_).integer);
  checkErrors("Texture3D::setSampling");
}

void Texture3D::bind(int unit) const {
  glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
  glBindTexture(GL_TEXTURE_3D, id());
  checkErrors("Texture3D::bind");
}

}  // namespace eik::gl
