// The live patch count on the GPU (see live_count.h).
#include "lightsim/live_count.h"

#include <array>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "gl/debug.h"
#include "gl/handle.h"

namespace eik::gpu {

LiveCount::LiveCount()
    : texture_({1, 1}, gl::TextureFormat::RGBA32F, gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge}),
      framebuffer_({1, 1}),
      pbo_(4 * sizeof(float), nullptr, GL_STREAM_READ) {
  framebuffer_.attach(0, texture_);
  framebuffer_.checkComplete();
  set(0);
}

void LiveCount::set(std::uint64_t count) {
  if (count > HistoPyramidLimits::kExactTotal) {
    throw std::logic_error("LiveCount::set: " + std::to_string(count) + " is over 2^24, which float cannot hold");
  }
  const std::array<float, 4> texel{static_cast<float>(count), 0.0f, 0.0f, 0.0f};
  texture_.upload(texel, 4);
}

void LiveCount::takeTotal(const HistoPyramid& pyramid) { pyramid.copyTopTo(texture_); }

void LiveCount::request() {
  if (pending_) throw std::logic_error("LiveCount::request: a read is already pending");
  gl::detail::ScopedBinding read(GL_READ_FRAMEBUFFER, GL_READ_FRAMEBUFFER_BINDING, gl::detail::bindFramebuffer,
                                 framebuffer_.id());
  gl::detail::ScopedBinding pack(GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING, gl::detail::bindBuffer,
                                 pbo_.id());
  gl::detail::ScopedPixelStore alignment(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, 1, 1, GL_RGBA, GL_FLOAT, nullptr);
  gl::checkErrors("LiveCount::request");
  pending_ = true;
}

std::uint64_t LiveCount::wait() {
  if (!pending_) throw std::logic_error("LiveCount::wait: no read is pending");
  pending_ = false;
  const std::vector<float> top = pbo_.download<float>(4);
  return hpTotalOfTop(top.data());
}

void LiveCount::bind(const gl::Program& program, int unit, const char* name) const {
  texture_.bind(unit);
  program.setSampler(name, unit);
}

}  // namespace eik::gpu
