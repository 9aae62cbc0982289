// Vertex array objects and the full-screen triangle (see vertex_array.h).
#include "gl/vertex_array.h"

#include "gl/debug.h"

namespace eik::gl {

VertexArray VertexArray::create() {
  detail::requireContext("a vertex array");
  GLuint name = 0;
  glGenVertexArrays(1, &name);
  VertexArray vao;
  vao.handle_ = GlHandle<detail::VertexArrayTraits>(name);
  checkErrors("VertexArray::create");
  return vao;
}

void VertexArray::attribute(GLuint index, const Buffer& buffer, int components, GLenum type, std::size_t stride,
                            std::size_t offset, bool normalized) {
  detail::ScopedBinding vao(0, GL_VERTEX_ARRAY_BINDING, detail::bindVertexArray, id());
  detail::ScopedBinding array(GL_ARRAY_BUFFER, GL_ARRAY_BUFFER_BINDING, detail::bindBuffer, buffer.id());
  glEnableVertexAttribArray(index);
  glVertexAttribPointer(index, components, type, normalized ? GL_TRUE : GL_FALSE, static_cast<GLsizei>(stride),
                        reinterpret_cast<const void*>(offset));
  checkErrors("VertexArray::attribute");
}

void VertexArray::integerAttribute(GLuint index, const Buffer& buffer, int components, GLenum type,
                                   std::size_t stride, std::size_t offset) {
  detail::ScopedBinding vao(0, GL_VERTEX_ARRAY_BINDING, detail::bindVertexArray, id());
  detail::ScopedBinding array(GL_ARRAY_BUFFER, GL_ARRAY_BUFFER_BINDING, detail::bindBuffer, buffer.id());
  glEnableVertexAttribArray(index);
  glVertexAttribIPointer(index, components, type, static_cast<GLsizei>(stride),
                         reinterpret_cast<const void*>(offset));
  checkErrors("VertexArray::integerAttribute");
}

void VertexArray::divisor(GLuint index, GLuint divisor) {
  detail::ScopedBinding vao(0, GL_VERTEX_ARRAY_BINDING, detail::bindVertexArray, id());
  glVertexAttribDivisor(index, divisor);
  checkErrors("VertexArray::divisor");
}

void VertexArray::elementBuffer(const Buffer& buffer) {
  // The element buffer binding is VAO state: bind it inside the VAO, then restore the VAO.
  detail::ScopedBinding vao(0, GL_VERTEX_ARRAY_BINDING, detail::bindVertexArray, id());
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffer.id());
  checkErrors("VertexArray::elementBuffer");
}

void VertexArray::bind() const {
  glBindVertexArray(id());
  checkErrors("VertexArray::bind");
}

FullscreenTriangle::FullscreenTriangle() : vao_(VertexArray::create()) {}

void FullscreenTriangle::draw() const {
  vao_.bind();
  glDrawArrays(GL_TRIANGLES, 0, 3);
  checkErrors("FullscreenTriangle::draw");
}

}  // namespace eik::gl
