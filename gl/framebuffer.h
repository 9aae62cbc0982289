// Framebuffer objects (RAII) with several colour attachments (MRT), a completeness check with a
// readable status, and readback of an attachment (or of a window's default framebuffer) into
// floats. Pixel rows come back bottom row first (GL order); flipRows() turns them top-down.
#pragma once

#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "gl/handle.h"
#include "gl/texture.h"

namespace eik::gl {

namespace detail {
struct FramebufferTraits {
  static void destroy(GLuint name) { glDeleteFramebuffers(1, &name); }
};
struct RenderbufferTraits {
  static void destroy(GLuint name) { glDeleteRenderbuffers(1, &name); }
};
}  // namespace detail

class Framebuffer {
 public:
  Framebuffer() = default;
  // A framebuffer of `size` with its own colour textures, attachment i in colorFormats[i]
  // (nearest filtering, so a later pass can texelFetch or sample it exactly), and a 24-bit depth
  // buffer when `depth`. Checked for completeness.
  Framebuffer(glm::ivec2 size, std::vector<TextureFormat> colorFormats, bool depth = false);
  // An empty framebuffer of `size` to attach textures made elsewhere (then call checkComplete()).
  explicit Framebuffer(glm::ivec2 size);

  // Attaches a 2D texture (or one z layer of a 3D texture) as colour attachment `index`. The
  // framebuffer does not own it: keep it alive while the framebuffer is used.
  void attach(int index, const Texture2D& texture, int level = 0);
  void attachLayer(int index, const Texture3D& texture, int layer, int level = 0);
  // Throws RuntimeError("framebuffer 64x64 (RGBA32F, RGB32F) is incomplete:
  // GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT") when GL cannot render into it.
  void checkComplete() const;

  // Binds it for drawing into every attachment (glDrawBuffers) and sets the viewport to its size.
  void bind() const;
  // Binds the window's default framebuffer (back buffer) with a viewport of `size`.
  static void bindDefault(glm::ivec2 size);

  // Clears attachment `index` to `value` (float formats), restoring the bindings.
  void clear(int index, glm::vec4 value);
  // Attachment `index` as RGBA floats, size.x·size.y·4 values, bottom row first.
  std::vector<float> readRGBA(int index = 0) const;
  // Or `channels` (1–4) floats a pixel.
  std::vector<float> read(int index, int channels) const;

  // The texture made by the first constructor for attachment `index` (RuntimeError for attached ones).
  const Texture2D& color(int index) const;
  int colorCount() const { return static_cast<int>(attachmentNames_.size()); }
  glm::ivec2 size() const { return size_; }
  GLuint id() const { return handle_.get(); }
  explicit operator bool() const { return bool(handle_); }

 private:
  void create();
  void setDrawBuffers() const;
  std::string describe() const;

  GlHandle<detail::FramebufferTraits> handle_;
  GlHandle<detail::RenderbufferTraits> depth_;
  glm::ivec2 size_{0};
  std::vector<Texture2D> owned_;              // owned colour textures (first constructor)
  std::vector<std::string> attachmentNames_;  // format of each attachment, "" where none
};

// The default framebuffer of the current (window) context: GL_BACK before swapBuffers(), as RGBA
// floats, bottom row first.
std::vector<float> readDefaultFramebufferRGBA(glm::ivec2 size, GLenum buffer = GL_BACK);

// Reverses the row order of an image of `width` pixels of `channels` floats (bottom-up ⇄ top-down).
void flipRows(std::vector<float>& pixels, int width, int channels);

// GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT etc. as text.
std::string framebufferStatusName(GLenum status);

}  // namespace eik::gl
