// GlHandle: the move-only owner of one OpenGL object name, the base of every RAII type in gl/.
//
// Conventions for all of gl/ (no GL state leaks between passes, docs/architecture.md):
//  * An object remembers the context it was made in (GlContext::serial) and deletes its name in
//    its destructor only while that context is current; destroy objects before their context.
//  * Methods named bind() / use() change GL bindings on purpose: they set up the next draw.
//  * Every other method (constructors, upload, download, attach, uniform setters, reads) saves the
//    bindings it has to touch and restores them before returning (ScopedBinding below).
//  * Pixel transfers set GL_(UN)PACK_ALIGNMENT to 1 for the call and restore it; nothing in gl/
//    leaves a buffer bound to GL_PIXEL_PACK_BUFFER / GL_PIXEL_UNPACK_BUFFER.
#pragma once

#include <utility>

#include "gl/context.h"
#include "gl/gl.h"

namespace eik::gl {

// Traits: `static void destroy(GLuint name);`
template <class Traits>
class GlHandle {
 public:
  GlHandle() = default;
  explicit GlHandle(GLuint name) : name_(name), context_(GlContext::currentSerial()) {}
  ~GlHandle() { reset(); }
  GlHandle(GlHandle&& other) noexcept
      : name_(std::exchange(other.name_, 0)), context_(std::exchange(other.context_, 0)) {}
  GlHandle& operator=(GlHandle&& other) noexcept {
    if (this != &other) {
      reset();
      name_ = std::exchange(other.name_, 0);
      context_ = std::exchange(other.context_, 0);
    }
    return *this;
  }
  GlHandle(const GlHandle&) = delete;
  GlHandle& operator=(const GlHandle&) = delete;

  GLuint get() const { return name_; }
  explicit operator bool() const { return name_ != 0; }

  void reset() {
    if (name_ != 0 && context_ == GlContext::currentSerial()) Traits::destroy(name_);
    name_ = 0;
    context_ = 0;
  }

 private:
  GLuint name_ = 0;
  unsigned long long context_ = 0;
};

namespace detail {

// Saves the object bound to a binding point (queried with `query`) and rebinds it on exit.
// `bindFn(target, name)` is the matching glBind* call.
class ScopedBinding {
 public:
  using BindFunction = void (*)(GLenum target, GLuint name);
  ScopedBinding(GLenum target, GLenum query, BindFunction bind) : target_(target), bind_(bind) {
    GLint previous = 0;
    glGetIntegerv(query, &previous);
    previous_ = static_cast<GLuint>(previous);
  }
  ScopedBinding(GLenum target, GLenum query, BindFunction bind, GLuint name) : ScopedBinding(target, query, bind) {
    bind_(target_, name);
  }
  ~ScopedBinding() { bind_(target_, previous_); }
  ScopedBinding(const ScopedBinding&) = delete;
  ScopedBinding& operator=(const ScopedBinding&) = delete;

 private:
  GLenum target_;
  GLuint previous_ = 0;
  BindFunction bind_;
};

// Sets a glPixelStorei parameter for a scope.
class ScopedPixelStore {
 public:
  ScopedPixelStore(GLenum parameter, GLint value) : parameter_(parameter) {
    glGetIntegerv(parameter, &previous_);
    glPixelStorei(parameter, value);
  }
  ~ScopedPixelStore() { glPixelStorei(parameter_, previous_); }
  ScopedPixelStore(const ScopedPixelStore&) = delete;
  ScopedPixelStore& operator=(const ScopedPixelStore&) = delete;

 private:
  GLenum parameter_;
  GLint previous_ = 0;
};

// Plain functions with the glBind* signature (the gl* names are macros over loaded pointers).
void bindTexture(GLenum target, GLuint name);
void bindBuffer(GLenum target, GLuint name);
void bindFramebuffer(GLenum target, GLuint name);
void bindVertexArray(GLenum /*unused*/, GLuint name);
void useProgram(GLenum /*unused*/, GLuint name);

// The current context, or a RuntimeError naming `what` needed one.
GlContext& requireContext(const char* what);

}  // namespace detail
}  // namespace eik::gl
