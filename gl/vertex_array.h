// Vertex array objects (RAII), and the empty one a full-screen triangle needs: core profile
// requires a bound VAO for every draw, even one whose vertex shader makes its positions from
// gl_VertexID (shaders/common/fullscreen.vert).
#pragma once

#include <cstddef>

#include "gl/buffer.h"
#include "gl/handle.h"

namespace eik::gl {

namespace detail {
struct VertexArrayTraits {
  static void destroy(GLuint name) { glDeleteVertexArrays(1, &name); }
};
}  // namespace detail

class VertexArray {
 public:
  // Creates the VAO (needs a current context).
  static VertexArray create();
  VertexArray() = default;

  // Float attribute `index` read from `buffer` (components 1–4 of `type`, normalised for integer
  // types when asked). Restores the VAO and GL_ARRAY_BUFFER bindings.
  void attribute(GLuint index, const Buffer& buffer, int components, GLenum type = GL_FLOAT, std::size_t stride = 0,
                 std::size_t offset = 0, bool normalized = false);
  // Integer attribute (glVertexAttribIPointer).
  void integerAttribute(GLuint index, const Buffer& buffer, int components, GLenum type = GL_INT,
                        std::size_t stride = 0, std::size_t offset = 0);
  void divisor(GLuint index, GLuint divisor);
  void elementBuffer(const Buffer& buffer);

  void bind() const;

  GLuint id() const { return handle_.get(); }
  explicit operator bool() const { return bool(handle_); }

 private:
  GlHandle<detail::VertexArrayTraits> handle_;
};

// A triangle that covers the viewport: draw() binds its empty VAO and issues 3 vertices.
// Pair it with shaders/common/fullscreen.vert (out vec2 vUv in [0,1]²).
class FullscreenTriangle {
 public:
  FullscreenTriangle();  // needs a current context
  void draw() const;

 private:
  VertexArray vao_;
};

}  // namespace eik::gl
