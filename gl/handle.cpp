// Binding helpers shared by the RAII types of gl/ (see handle.h for the conventions).
#include "gl/handle.h"

#include <string>

#include "core/error.h"

namespace eik::gl::detail {

void bindTexture(GLenum target, GLuint name) { glBindTexture(target, name); }
void bindBuffer(GLenum target, GLuint name) { glBindBuffer(target, name); }
void bindFramebuffer(GLenum target, GLuint name) { glBindFramebuffer(target, name); }
void bindVertexArray(GLenum, GLuint name) { glBindVertexArray(name); }
void useProgram(GLenum, GLuint name) { glUseProgram(name); }

GlContext& requireContext(const char* what) {
  GlContext* context = GlContext::current();
  if (!context) throw RuntimeError(std::string(what) + " needs a current OpenGL context (create a gl::GlContext first)");
  return *context;
}

}  // namespace eik::gl::detail
