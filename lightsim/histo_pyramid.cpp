// The histogram pyramid: GPU build and total readback, CPU reference (see histo_pyramid.h).
#include "lightsim/histo_pyramid.h"

#include <bit>
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "gl/debug.h"

namespace eik {
namespace {

constexpr const char* kWhat = "HistoPyramid";

std::uint32_t part1By1(std::uint32_t v) {
  v &= 0x0000ffffu;
  v = (v | (v << 8)) & 0x00ff00ffu;
  v = (v | (v << 4)) & 0x0f0f0f0fu;
  v = (v | (v << 2)) & 0x33333333u;
  v = (v | (v << 1)) & 0x55555555u;
  return v;
}

std::uint32_t compact1By1(std::uint32_t v) {
  v &= 0x55555555u;
  v = (v | (v >> 1)) & 0x33333333u;
  v = (v | (v >> 2)) & 0x0f0f0f0fu;
  v = (v | (v >> 4)) & 0x00ff00ffu;
  v = (v | (v >> 8)) & 0x0000ffffu;
  return v;
}

// log2 of a power-of-two base side in [1, kMaxBaseSize]; InputError otherwise.
int checkedLevels(int baseSize) {
  if (baseSize < 1 || baseSize > HistoPyramidLimits::kMaxBaseSize || !std::has_single_bit(unsigned(baseSize))) {
    throw InputError(kWhat, "base size",
                     std::to_string(baseSize) + " is not a power of two in [1, " +
                         std::to_string(HistoPyramidLimits::kMaxBaseSize) + "]");
  }
  return std::countr_zero(unsigned(baseSize));
}

// Slots of level `level` that hold any of the first `live` base slots: ⌈live / 4^level⌉.
std::uint64_t liveNodes(std::uint64_t live, int level) {
  const int shift = 2 * level;
  return (live + (std::uint64_t{1} << shift) - 1) >> shift;
}

std::size_t texelIndex(glm::ivec2 t, int side) {
  return static_cast<std::size_t>(t.y) * static_cast<std::size_t>(side) + static_cast<std::size_t>(t.x);
}

// Saves and restores a glEnable/glDisable capability, disabling it for the scope.
class ScopedDisable {
 public:
  explicit ScopedDisable(GLenum cap) : cap_(cap), was_(glIsEnabled(cap) == GL_TRUE) {
    if (was_) glDisable(cap_);
  }
  ~ScopedDisable() {
    if (was_) glEnable(cap_);
  }
  ScopedDisable(const ScopedDisable&) = delete;
  ScopedDisable& operator=(const ScopedDisable&) = delete;

 private:
  GLenum cap_;
  bool was_;
};

// Everything a build pass touches, restored on exit (gl/handle.h conventions): framebuffer,
// program, vertex array, viewport, texture unit 0 and the active unit, and the per-fragment tests
// and blending a caller may have left on (the deposit pass blends).
class PassState {
 public:
  PassState()
      : framebuffer_(GL_FRAMEBUFFER, GL_FRAMEBUFFER_BINDING, gl::detail::bindFramebuffer),
        program_(0, GL_CURRENT_PROGRAM, gl::detail::useProgram),
        vertexArray_(0, GL_VERTEX_ARRAY_BINDING, gl::detail::bindVertexArray),
        blend_(GL_BLEND),
        depth_(GL_DEPTH_TEST),
        scissor_(GL_SCISSOR_TEST),
        stencil_(GL_STENCIL_TEST),
        cull_(GL_CULL_FACE) {
    glGetIntegerv(GL_VIEWPORT, viewport_);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &activeTexture_);
    glActiveTexture(GL_TEXTURE0);
    texture_.emplace(GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, gl::detail::bindTexture);
  }
  ~PassState() {
    texture_.reset();
    glActiveTexture(static_cast<GLenum>(activeTexture_));
    glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
  }
  PassState(const PassState&) = delete;
  PassState& operator=(const PassState&) = delete;

 private:
  gl::detail::ScopedBinding framebuffer_;
  gl::detail::ScopedBinding program_;
  gl::detail::ScopedBinding vertexArray_;
  ScopedDisable blend_, depth_, scissor_, stencil_, cull_;
  std::optional<gl::detail::ScopedBinding> texture_;
  GLint viewport_[4] = {0, 0, 0, 0};
  GLint activeTexture_ = GL_TEXTURE0;
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Slots.

glm::ivec2 hpSlotTexel(std::uint32_t slot) {
  return {static_cast<int>(compact1By1(slot)), static_cast<int>(compact1By1(slot >> 1))};
}

std::uint32_t hpTexelSlot(glm::ivec2 texel) {
  return part1By1(static_cast<std::uint32_t>(texel.x)) | (part1By1(static_cast<std::uint32_t>(texel.y)) << 1);
}

glm::ivec2 hpLiveBox(std::uint64_t count) {
  if (count == 0) return {0, 0};
  if (count > (std::uint64_t{1} << 32)) throw std::out_of_range("hpLiveBox: more than 2^32 slots");
  const int bits = static_cast<int>(std::bit_width(count - 1));
  return {1 << ((bits + 1) / 2), 1 << (bits / 2)};
}

int hpBaseSizeFor(std::uint64_t capacity) {
  int side = 1;
  while (std::uint64_t(side) * std::uint64_t(side) < capacity) side *= 2;
  return side;
}

// ---------------------------------------------------------------------------------------------
// CPU reference.

HistoPyramidCpu::HistoPyramidCpu(int baseSize, std::span<const float> counts, std::size_t liveSlots)
    : base_(baseSize), levels_(checkedLevels(baseSize)) {
  const std::size_t n = static_cast<std::size_t>(baseSize) * static_cast<std::size_t>(baseSize);
  if (counts.size() != n) {
    throw InputError(kWhat, "counts", std::to_string(counts.size()) + " values for a base of " + std::to_string(n));
  }
  level_.resize(static_cast<std::size_t>(levels_) + 1);
  level_[0].assign(n, 0);
  const std::size_t live = std::min(liveSlots, n);
  for (std::size_t slot = 0; slot < live; ++slot) {
    const std::size_t i = texelIndex(hpSlotTexel(static_cast<std::uint32_t>(slot)), base_);
    const float c = counts[i];
    if (!std::isfinite(c) || c < 0.0f || c != std::floor(c)) {
      throw InputError(kWhat, "counts", "slot " + std::to_string(slot) + " holds " + std::to_string(c) +
                                            " (counts are non-negative integers)");
    }
    level_[0][i] = static_cast<std::uint64_t>(c);
  }
  for (int l = 1; l <= levels_; ++l) {
    const int side = base_ >> l, below = base_ >> (l - 1);
    std::vector<std::uint64_t>& out = level_[static_cast<std::size_t>(l)];
    const std::vector<std::uint64_t>& in = level_[static_cast<std::size_t>(l - 1)];
    out.assign(static_cast<std::size_t>(side) * static_cast<std::size_t>(side), 0);
    for (int y = 0; y < side; ++y) {
      for (int x = 0; x < side; ++x) {
        const std::size_t c = texelIndex({2 * x, 2 * y}, below);
        out[texelIndex({x, y}, side)] = in[c] + in[c + 1] + in[c + static_cast<std::size_t>(below)] +
                                        in[c + static_cast<std::size_t>(below) + 1];
      }
    }
  }
}

std::uint64_t HistoPyramidCpu::at(int level, glm::ivec2 t) const {
  return level_.at(static_cast<std::size_t>(level)).at(texelIndex(t, base_ >> level));
}

HistoPyramidEntry HistoPyramidCpu::find(std::uint64_t k) const {
  if (k >= total()) throw std::out_of_range("HistoPyramidCpu::find: slot beyond the total");
  glm::ivec2 node{0};
  for (int l = levels_ - 1; l >= 0; --l) {
    node *= 2;
    static constexpr glm::ivec2 kChild[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    int child = 0;
    for (; child < 3; ++child) {
      const std::uint64_t c = at(l, node + kChild[child]);
      if (k < c) break;
      k -= c;
    }
    node += kChild[child];
  }
  return {hpTexelSlot(node), node, static_cast<std::uint32_t>(k)};
}

std::vector<HistoPyramidEntry> HistoPyramidCpu::expand() const {
  std::vector<HistoPyramidEntry> out;
  out.reserve(static_cast<std::size_t>(total()));
  for (std::uint64_t k = 0; k < total(); ++k) out.push_back(find(k));
  return out;
}

std::vector<HistoPyramidEntry> hpExpandByPrefixSum(std::span<const std::uint32_t> countsBySlot) {
  std::vector<HistoPyramidEntry> out;
  for (std::size_t s = 0; s < countsBySlot.size(); ++s) {
    const auto slot = static_cast<std::uint32_t>(s);
    for (std::uint32_t j = 0; j < countsBySlot[s]; ++j) out.push_back({slot, hpSlotTexel(slot), j});
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// GPU pyramid.

HistoPyramid::HistoPyramid(int baseSize, const gl::ShaderLibrary& library)
    : base_(baseSize),
      levels_(std::max(checkedLevels(baseSize), 1)),
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
  PassState state;
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

namespace {
std::uint64_t totalFromTop(const float top[4]) {
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
}  // namespace

std::uint64_t HistoPyramid::readTotal() const {
  gl::detail::ScopedBinding read(GL_READ_FRAMEBUFFER, GL_READ_FRAMEBUFFER_BINDING, gl::detail::bindFramebuffer,
                                 framebuffers_.back().get());
  gl::detail::ScopedBinding pack(GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING, gl::detail::bindBuffer, 0);
  gl::detail::ScopedPixelStore alignment(GL_PACK_ALIGNMENT, 1);
  float top[4] = {-1.0f, -1.0f, -1.0f, -1.0f};
  glReadPixels(0, 0, 1, 1, GL_RGBA, GL_FLOAT, top);
  gl::checkErrors("HistoPyramid::readTotal");
  return totalFromTop(top);
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
  return totalFromTop(top.data());
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
