// Framebuffer objects and pixel readback (see framebuffer.h).
#include "gl/framebuffer.h"

#include <algorithm>
#include <string>

#include "core/error.h"
#include "gl/debug.h"

namespace eik::gl {

std::string framebufferStatusName(GLenum status) {
  switch (status) {
    case GL_FRAMEBUFFER_COMPLETE: return "GL_FRAMEBUFFER_COMPLETE";
    case GL_FRAMEBUFFER_UNDEFINED: return "GL_FRAMEBUFFER_UNDEFINED";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT (nothing attached)";
    case GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER: return "GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER";
    case GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER: return "GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER";
    case GL_FRAMEBUFFER_UNSUPPORTED: return "GL_FRAMEBUFFER_UNSUPPORTED (this format combination cannot be rendered to)";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE: return "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
    case GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS: return "GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS";
    default: return "framebuffer status " + std::to_string(status);
  }
}

Framebuffer::Framebuffer(glm::ivec2 size) : size_(size) { create(); }

Framebuffer::Framebuffer(glm::ivec2 size, std::vector<TextureFormat> colorFormats, bool depth) : size_(size) {
  create();
  const int limit = GlContext::current()->info().maxColorAttachments;
  if (static_cast<int>(colorFormats.size()) > limit) {
    throw RuntimeError("Framebuffer: " + std::to_string(colorFormats.size()) +
                       " colour attachments, this OpenGL allows " + std::to_string(limit));
  }
  owned_.reserve(colorFormats.size());
  for (std::size_t i = 0; i < colorFormats.size(); ++i) {
    owned_.emplace_back(size, colorFormats[i], Sampling{Filter::Nearest, Wrap::ClampToEdge});
    attach(static_cast<int>(i), owned_.back());
  }
  if (depth) {
    GLuint name = 0;
    glGenRenderbuffers(1, &name);
    depth_ = GlHandle<detail::RenderbufferTraits>(name);
    GLint previous = 0;
    glGetIntegerv(GL_RENDERBUFFER_BINDING, &previous);
    glBindRenderbuffer(GL_RENDERBUFFER, name);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, size.x, size.y);
    glBindRenderbuffer(GL_RENDERBUFFER, static_cast<GLuint>(previous));
    detail::ScopedBinding binding(GL_FRAMEBUFFER, GL_FRAMEBUFFER_BINDING, detail::bindFramebuffer, id());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, name);
    checkErrors("Framebuffer (depth)");
  }
  checkComplete();
}

void Framebuffer::create() {
  checkTexture2DSize(size_, "framebuffer");
  GLuint name = 0;
  glGenFramebuffers(1, &name);
  handle_ = GlHandle<detail::FramebufferTraits>(name);
}

void Framebuffer::attach(int index, const Texture2D& texture, int level) {
  if (texture.size() != size_) {
    throw RuntimeError("Framebuffer::attach: texture of " + std::to_string(texture.size().x) + "x" +
                       std::to_string(texture.size().y) + " on a framebuffer of " + std::to_string(size_.x) + "x" +
                       std::to_string(size_.y));
  }
  detail::ScopedBinding binding(GL_FRAMEBUFFER, GL_FRAMEBUFFER_BINDING, detail::bindFramebuffer, id());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index), GL_TEXTURE_2D,
                         texture.id(), level);
  if (static_cast<int>(attachmentNames_.size()) <= index) attachmentNames_.resize(static_cast<std::size_t>(index) + 1);
  attachmentNames_[static_cast<std::size_t>(index)] = formatInfo(texture.format()).name;
  checkErrors("Framebuffer::attach");
}

void Framebuffer::attachLayer(int index, const Texture3D& texture, int layer, int level) {
  if (glm::ivec2(texture.dims()) != size_) {
    throw RuntimeError("Framebuffer::attachLayer: 3D texture layers of " + std::to_string(texture.dims().x) + "x" +
                       std::to_string(texture.dims().y) + " on a framebuffer of " + std::to_string(size_.x) + "x" +
                       std::to_string(size_.y));
  }
  detail::ScopedBinding binding(GL_FRAMEBUFFER, GL_FRAMEBUFFER_BINDING, detail::bindFramebuffer, id());
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index), texture.id(), level,
                            layer);
  if (static_cast<int>(attachmentNames_.size()) <= index) attachmentNames_.resize(static_cast<std::size_t>(index) + 1);
  attachmentNames_[static_cast<std::size_t>(index)] = std::string(formatInfo(texture.format()).name) + " layer " +
                                                      std::to_string(layer);
  checkErrors("Framebuffer::attachLayer");
}

std::string Framebuffer::describe() const {
  std::string text = "framebuffer " + std::to_string(size_.x) + "x" + std::to_string(size_.y) + " (";
  for (std::size_t i = 0; i < attachmentNames_.size(); ++i) {
    text += (i ? ", " : "") + (attachmentNames_[i].empty() ? std::string("none") : attachmentNames_[i]);
  }
  return text + (depth_ ? ", depth)" : ")");
}

void Framebuffer::checkComplete() const {
  detail::ScopedBinding binding(GL_FRAMEBUFFER, GL_FRAMEBUFFER_BINDING, detail::bindFramebuffer, id());
  setDrawBuffers();
  GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw RuntimeError(describe() + " is incomplete: " + framebufferStatusName(status));
  }
  checkErrors("Framebuffer::checkComplete");
}

void Framebuffer::setDrawBuffers() const {
  std::vector<GLenum> buffers(attachmentNames_.size(), GL_NONE);
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    if (!attachmentNames_[i].empty()) buffers[i] = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i);
  }
  if (buffers.empty()) {
    GLenum none = GL_NONE;
    glDrawBuffers(1, &none);
  } else {
    glDrawBuffers(static_cast<GLsizei>(buffers.size()), buffers.data());
  }
}

void Framebuffer::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, id());
  setDrawBuffers();
  glViewport(0, 0, size_.x, size_.y);
  checkErrors("Framebuffer::bind");
}

void Framebuffer::bindDefault(glm::ivec2 size) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, size.x, size.y);
  checkErrors("Framebuffer::bindDefault");
}

void Framebuffer::clear(int index, glm::vec4 value) {
  detail::ScopedBinding binding(GL_DRAW_FRAMEBUFFER, GL_DRAW_FRAMEBUFFER_BINDING, detail::bindFramebuffer, id());
  setDrawBuffers();
  glClearBufferfv(GL_COLOR, index, &value.x);
  checkErrors("Framebuffer::clear");
}

const Texture2D& Framebuffer::color(int index) const {
  if (index < 0 || index >= static_cast<int>(owned_.size())) {
    throw RuntimeError("Framebuffer::color: no owned colour texture " + std::to_string(index));
  }
  return owned_[static_cast<std::size_t>(index)];
}

std::vector<float> Framebuffer::readRGBA(int index) const { return read(index, 4); }

std::vector<float> Framebuffer::read(int index, int channels) const {
  if (index < 0 || index >= colorCount() || attachmentNames_[static_cast<std::size_t>(index)].empty()) {
    throw RuntimeError("Framebuffer::read: " + describe() + " has no colour attachment " + std::to_string(index));
  }
  std::vector<float> pixels(static_cast<std::size_t>(size_.x) * static_cast<std::size_t>(size_.y) *
                            static_cast<std::size_t>(channels));
  detail::ScopedBinding binding(GL_READ_FRAMEBUFFER, GL_READ_FRAMEBUFFER_BINDING, detail::bindFramebuffer, id());
  detail::ScopedPixelStore alignment(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index));
  glReadPixels(0, 0, size_.x, size_.y, pixelFormatForChannels(channels), GL_FLOAT, pixels.data());
  checkErrors("Framebuffer::read");
  return pixels;
}

std::vector<float> readDefaultFramebufferRGBA(glm::ivec2 size, GLenum buffer) {
  std::vector<float> pixels(static_cast<std::size_t>(size.x) * static_cast<std::size_t>(size.y) * 4);
  detail::ScopedBinding binding(GL_READ_FRAMEBUFFER, GL_READ_FRAMEBUFFER_BINDING, detail::bindFramebuffer, 0);
  detail::ScopedPixelStore alignment(GL_PACK_ALIGNMENT, 1);
  GLint previousReadBuffer = GL_BACK;
  glGetIntegerv(GL_READ_BUFFER, &previousReadBuffer);
  glReadBuffer(buffer);
  glReadPixels(0, 0, size.x, size.y, GL_RGBA, GL_FLOAT, pixels.data());
  glReadBuffer(static_cast<GLenum>(previousReadBuffer));
  checkErrors("readDefaultFramebufferRGBA");
  return pixels;
}

void flipRows(std::vector<float>& pixels, int width, int channels) {
  const std::size_t row = static_cast<std::size_t>(width) * static_cast<std::size_t>(channels);
  if (row == 0) return;
  const std::size_t rows = pixels.size() / row;
  for (std::size_t top = 0, bottom = rows - 1; top < bottom; ++top, --bottom) {
    std::swap_ranges(pixels.begin() + static_cast<std::ptrdiff_t>(top * row),
                     pixels.begin() + static_cast<std::ptrdiff_t>((top + 1) * row),
                     pixels.begin() + static_cast<std::ptrdiff_t>(bottom * row));
  }
}

}  // namespace eik::gl
