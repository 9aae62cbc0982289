// The histogram pyramid: slots, GPU build and total readback (see histo_pyramid.h).
#include "lightsim/histo_pyramid.h"

#include <bit>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "gl/debug.h"
#include "gl/scoped_state.h"

namespace eik {
namespace {

constexpr const char* kWhat = "HistoPyramid";

// Slots of level `level` that hold any of the first `live` base slots: ⌈live / 4^level⌉.
std::uint64_t liveNodes(std::uint64_t live, int level) {
  const int shift = 2 * level;
  return (live + (std::uint64_t{1} << shift) - 1) >> shift;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Slots.

int hpCheckedLevels(int baseSize) {
  if (baseSize < 1 || baseSize > HistoPyramidLimits::kMaxBaseSize || !std::has_single_bit(unsigned(baseSize))) {
    throw InputError(kWhat, "base size",
                     std::to_string(baseSize) + " is not a power of two in [1, " +
                         std::to_string(HistoPyramidLimits::kMaxBaseSize) + "]");
  }
  return std::countr_zero(unsigned(baseSize));
}

int hpBaseSizeFor(std::uint64_t capacity) {
  int side = 1;
  while (std::uint64_t(side) * std::uint64_t(side) < capacity) side *= 2;
  return side;
}

// ---------------------------------------------------------------------------------------------
// GPU pyramid.

HistoPyramid::HistoPyramid(int baseSize, const gl::ShaderLibrary& library)
    : base_(baseSize),
      levels_(std::max(hpCheckedLevels(baseSize), 1)),
      baseTexture_({baseSize, baseSize}, gl::TextureFormat::R32F,
                   gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge}),
      pyramid_(glm::ivec2(std::max(baseSize / 2, 1)), gl::TextureFormat::RGBA32F,
               gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge}),
      first_(library.program("common/fullscreen.vert", "lightsim/histo_pyramid_reduce.frag",
                             {{"HP_FIRST", "1"}, {"HP_BASE_SIZE", std::to_string(baseSize)}})),
      reduce_(library.program("common/fullscreen.vert", "lightsim/histo_pyramid_reduce.frag")) {
  {
    gl::detail::ScopedBinding binding(GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, gl::detail::bindTexture, pyramid_.id());
    while (glGetError() != GL_NO_ERROR) {
    }
    for (int m = 1; m < levels_; ++m) {
      glTexImage2D(GL_TEXTURE_2D, m, GL_RGBA32F, mipSide(m), mipSide(m), 0, GL_RGBA, GL_FLOAT, nullptr);
    }
    if (glGetError() == GL_OUT_OF_MEMORY) {
      throw RuntimeError("HistoPyramid: out of GPU memory for the levels of a " + std::to_string(base_) + "² pyramid");
    }
    // A mipmap filter, so that every level is part of the texture (with a non-mipmap min filter an
    // implementation may expose only the base level to texelFetch).
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, levels_ - 1);
    gl::checkErrorsAlways("HistoPyramid: allocating the levels");
  }
  gl::detail::ScopedBinding binding(GL_FRAMEBUFFER, GL_FRAMEBUFFER_BINDING, gl::detail::bindFramebuffer);
  for (int m = 0; m < levels_; ++m) {
    GLuint name = 0;
    glGenFramebuffers(1, &name);
    framebuffers_.emplace_back(name);
    glBindFramebuffer(GL_FRAMEBUFFER, name);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, pyramid_.id(), m);
    const GLenum buffer = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &buffer);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      throw RuntimeError("HistoPyramid: level " + std::to_string(m + 1) + " (RGBA32F) cannot be rendered to: " +
                         gl::framebufferStatusName(status));
    }
  }
  first_.setSampler("uHpSource", 0);
  reduce_.setSampler("uHpSource", 0);
  gl::checkErrorsAlways("HistoPyramid");
}

int HistoPyramid::mipSide(int m) const { return std::max(1, std::max(base_ / 2, 1) >> m); }

void HistoPyramid::build(std::size_t liveSlots) { reduceLevels(baseTexture_.id(), liveSlots); }

void HistoPyramid::build(const gl::Texture2D& counts, std::size_t liveSlots) {
  if (counts.size() != glm::ivec2(base_)) {
    throw RuntimeError("HistoPyramid::build: counts of " + std::to_string(counts.size().x) + "x" +
                       std::to_string(counts.size().y) + " for a base of " + std::to_string(base_) + "²");
  }
  reduceLevels(counts.id(), liveSlots);
}

void HistoPyramid::reduceLevels(GLuint counts, std::size_t liveSlots) {
  const std::uint64_t live = std::min<std::uint64_t>(liveSlots, capacity());
  pending_ = false;
  gl::ScopedPassState state;
  for (int m = 0; m < levels_; ++m) {
    const gl::Program& program = m == 0 ? first_ : reduce_;
    if (m == 0) {
      glBindTexture(GL_TEXTURE_2D, counts);
    } else {
      if (m == 1) glBindTexture(GL_TEXTURE_2D, pyramid_.id());
      // Sample mip m − 1 only: the mip written is outside [base, max], so no feedback loop.
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, m - 1);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, m - 1);
    }
    if (m <= 1) program.use();
    glUniform1i(program.uniformLocation("uHpSourceLive"), static_cast<GLint>(liveNodes(live, m)));
    // At least node (0, 0) of every level, so the top is written even for an empty list.
    const glm::ivec2 box = hpLiveBox(std::max<std::uint64_t>(liveNodes(live, m + 1), 1));
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffers_[static_cast<std::size_t>(m)].get());
    glViewport(0, 0, box.x, box.y);
    triangle_.draw();
  }
  if (levels_ > 1) {
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, levels_ - 1);
  }
  gl::checkErrors("HistoPyramid::build");
}

std::uint64_t hpTotalOfTop(const float top[4]) {
  std::uint64_t total = 0;
  for (int i = 0; i < 4; ++i) {
    if (!(top[i] >= 0.0f) || !std::isfinite(top[i])) {
      throw RuntimeError("HistoPyramid: the top of the pyramid reads back as " + std::to_string(top[i]) +
                         " (counts must be non-negative integers)");
    }
    total += static_cast<std::uint64_t>(top[i]);
  }
  return total;
}

std::uint64_t HistoPyramid::readTotal() const {
  gl::detail::ScopedBinding read(GL_READ_FRAMEBUFFER, GL_READ_FRAMEBUFFER_BINDING, gl::detail::bindFramebuffer,
                                 framebuffers_.back().get());
  gl::detail::ScopedBinding pack(GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING, gl::detail::bindBuffer, 0);
  gl::detail::ScopedPixelStore alignment(GL_PACK_ALIGNMENT, 1);
  float top[4] = {-1.0f, -1.0f, -1.0f, -1.0f};
  glReadPixels(0, 0, 1, 1, GL_RGBA, GL_FLOAT, top);
  gl::checkErrors("HistoPyramid::readTotal");
  return hpTotalOfTop(top);
}

void HistoPyramid::requestTotal() {
  if (!pbo_) pbo_ = gl::Buffer(4 * sizeof(float), nullptr, GL_STREAM_READ);
  gl::detail::ScopedBinding read(GL_READ_FRAMEBUFFER, GL_READ_FRAMEBUFFER_BINDING, gl::detail::bindFramebuffer,
                                 framebuffers_.back().get());
  gl::detail::ScopedBinding pack(GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING, gl::detail::bindBuffer,
                                 pbo_.id());
  gl::detail::ScopedPixelStore alignment(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, 1, 1, GL_RGBA, GL_FLOAT, nullptr);
  gl::checkErrors("HistoPyramid::requestTotal");
  pending_ = true;
}

std::uint64_t HistoPyramid::waitTotal() {
  if (!pending_) requestTotal();
  pending_ = false;
  const std::vector<float> top = pbo_.download<float>(4);
  return hpTotalOfTop(top.data());
}

void HistoPyramid::copyTopTo(const gl::Texture2D& target) const {
  if (target.format() != gl::TextureFormat::RGBA32F) {
    throw std::logic_error("HistoPyramid::copyTopTo: the target must be RGBA32F");
  }
  gl::detail::ScopedBinding read(GL_READ_FRAMEBUFFER, GL_READ_FRAMEBUFFER_BINDING, gl::detail::bindFramebuffer,
                                 framebuffers_.back().get());
  gl::detail::ScopedBinding binding(GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, gl::detail::bindTexture, target.id());
  glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, 1, 1);
  gl::checkErrors("HistoPyramid::copyTopTo");
}

void HistoPyramid::bind(int unit) const { pyramid_.bind(unit); }

gl::ShaderDefines HistoPyramid::defines() const { return {{"HP_LEVELS", std::to_string(levels_)}}; }

std::vector<std::vector<float>> HistoPyramid::downloadLevels() const {
  std::vector<std::vector<float>> out;
  gl::detail::ScopedBinding binding(GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, gl::detail::bindTexture, pyramid_.id());
  gl::detail::ScopedBinding pack(GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING, gl::detail::bindBuffer, 0);
  gl::detail::ScopedPixelStore alignment(GL_PACK_ALIGNMENT, 1);
  for (int m = 0; m < levels_; ++m) {
    const auto side = static_cast<std::size_t>(mipSide(m));
    out.emplace_back(side * side * 4);
    glGetTexImage(GL_TEXTURE_2D, m, GL_RGBA, GL_FLOAT, out.back().data());
  }
  gl::checkErrors("HistoPyramid::downloadLevels");
  return out;
}

}  // namespace eik
