// Buffer objects (see buffer.h).
#include "gl/buffer.h"

#include <string>

#include "core/error.h"
#include "gl/debug.h"

namespace eik::gl {

Buffer::Buffer(std::size_t bytes, const void* data, GLenum usage) : usage_(usage) {
  detail::requireContext("a buffer");
  GLuint name = 0;
  glGenBuffers(1, &name);
  handle_ = GlHandle<detail::BufferTraits>(name);
  resize(bytes, data);
}

void Buffer::resize(std::size_t bytes, const void* data) {
  detail::ScopedBinding binding(GL_COPY_WRITE_BUFFER, GL_COPY_WRITE_BUFFER, detail::bindBuffer, id());
  while (glGetError() != GL_NO_ERROR) {
  }
  glBufferData(GL_COPY_WRITE_BUFFER, static_cast<GLsizeiptr>(bytes), data, usage_);
  GLenum error = glGetError();
  if (error == GL_OUT_OF_MEMORY) {
    throw RuntimeError("Buffer: out of GPU memory for " + std::to_string(bytes) + " bytes");
  }
  if (error != GL_NO_ERROR) throw RuntimeError("Buffer: " + glErrorName(error) + " allocating " + std::to_string(bytes) + " bytes");
  size_ = bytes;
}

void Buffer::upload(std::size_t offset, std::size_t bytes, const void* data) {
  if (offset + bytes > size_) {
    throw RuntimeError("Buffer::upload: bytes [" + std::to_string(offset) + ", " + std::to_string(offset + bytes) +
                       ") past the end of a buffer of " + std::to_string(size_));
  }
  detail::ScopedBinding binding(GL_COPY_WRITE_BUFFER, GL_COPY_WRITE_BUFFER, detail::bindBuffer, id());
  glBufferSubData(GL_COPY_WRITE_BUFFER, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
  checkErrors("Buffer::upload");
}

void Buffer::downloadBytes(std::size_t offset, std::size_t bytes, void* out) const {
  if (offset + bytes > size_) {
    throw RuntimeError("Buffer::download: bytes [" + std::to_string(offset) + ", " + std::to_string(offset + bytes) +
                       ") past the end of a buffer of " + std::to_string(size_));
  }
  detail::ScopedBinding binding(GL_COPY_READ_BUFFER, GL_COPY_READ_BUFFER, detail::bindBuffer, id());
  glGetBufferSubData(GL_COPY_READ_BUFFER, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), out);
  checkErrors("Buffer::download");
}

void Buffer::bind(GLenum target) const {
  glBindBuffer(target, id());
  checkErrors("Buffer::bind");
}

void Buffer::bindBase(GLenum target, GLuint index) const {
  glBindBufferBase(target, index, id());
  checkErrors("Buffer::bindBase");
}

}  // namespace eik::gl
