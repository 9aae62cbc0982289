// Buffer objects (RAII): vertex, index, uniform, transform-feedback and pixel buffers alike.
// Uploads and downloads go through GL_COPY_WRITE_BUFFER / GL_COPY_READ_BUFFER (queried by those
// names: the *_BINDING aliases are GL 4.2), so they disturb
// neither GL_ARRAY_BUFFER nor a vertex array's element buffer.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "gl/handle.h"

namespace eik::gl {

namespace detail {
struct BufferTraits {
  static void destroy(GLuint name) { glDeleteBuffers(1, &name); }
};
}  // namespace detail

class Buffer {
 public:
  Buffer() = default;
  // `bytes` of storage, filled from `data` when it is not null. usage: GL_STATIC_DRAW, GL_DYNAMIC_COPY, ...
  explicit Buffer(std::size_t bytes, const void* data = nullptr, GLenum usage = GL_STATIC_DRAW);
  template <class T>
  explicit Buffer(std::span<const T> data, GLenum usage = GL_STATIC_DRAW)
      : Buffer(data.size_bytes(), data.data(), usage) {}

  // Replaces bytes [offset, offset + bytes).
  void upload(std::size_t offset, std::size_t bytes, const void* data);
  template <class T>
  void upload(std::span<const T> data, std::size_t offset = 0) {
    upload(offset, data.size_bytes(), data.data());
  }
  // Reallocates to `bytes` (contents from `data` or undefined).
  void resize(std::size_t bytes, const void* data = nullptr);
  // Reads bytes [offset, offset + count·sizeof(T)) back.
  template <class T>
  std::vector<T> download(std::size_t count, std::size_t offset = 0) const {
    std::vector<T> data(count);
    downloadBytes(offset, count * sizeof(T), data.data());
    return data;
  }
  void downloadBytes(std::size_t offset, std::size_t bytes, void* out) const;

  void bind(GLenum target) const;                       // glBindBuffer
  void bindBase(GLenum target, GLuint index) const;     // uniform / transform feedback binding points

  GLuint id() const { return handle_.get(); }
  explicit operator bool() const { return bool(handle_); }
  std::size_t size() const { return size_; }

 private:
  GlHandle<detail::BufferTraits> handle_;
  std::size_t size_ = 0;
  GLenum usage_ = GL_STATIC_DRAW;
};

}  // namespace eik::gl
