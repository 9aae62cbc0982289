// The histogram pyramid of ALGORITHM.md step 6 (Ziegler, Tevs, Theobalt, Seidel 2006, with the RGBA
// node layout of Dyken et al. 2008): stream compaction and expansion of the patch list in OpenGL 3.3
// fragment shaders. (Its CPU reference, HistoPyramidCpu, is test-only: histo_pyramid_cpu.h.)
//
// Layout
//   * The base (level 0): one count per patch slot, an R32F texture of side 2^K — base(), which a
//     producer may render into, or any float texture of that size handed to build(counts).
//   * The pyramid: ONE RGBA32F texture with mip levels 0..K−1 (side 2^(K−1−m)); texel t of mip m is
//     node t of level m + 1 and holds the sums of its four children at level m, in child order
//     .x (0,0), .y (1,0), .z (0,1), .w (1,1). The top (mip K−1) is 1×1; its four components add up
//     to the total. Built with K full-screen draws, one per level, each over the live part of the
//     level; the traversal needs one fetch a level. (A 1×1 base gets K = 1: a 1×1 top.)
//   * Slots: list index k lives at texel hpSlotTexel(k), Morton / Z-order (x from the even bits of
//     k, y from the odd bits) — the same placement as lightsim/patch_textures.h's mortonTexel. The
//     descent in child order 0: (0,0), 1: (1,0), 2: (0,1), 3: (1,1) visits the base in exactly this
//     order, so the expanded list has the order of a plain prefix sum over the counts in index order
//     (what the CPU twin does). Output slot k of the new list is written at texel hpSlotTexel(k) of
//     the output texture, whose side may differ from the base's (Morton placement does not depend
//     on the side: any power-of-two side with side² ≥ total will do, e.g. hpBaseSizeFor(total)).
//     (A row-major placement would make the GPU order a Z-order permutation of the CPU twin's,
//     against ALGORITHM.md step 6.)
//
// Live slots: build(…, liveSlots) counts only slots < liveSlots; whatever the base (or the pyramid)
// holds at other texels is ignored, NaN included, so a producer may draw just hpLiveBox(liveSlots)
// and leave stale data from an earlier, longer list in the rest. Every pass draws only the live box
// of its level.
//
// Limits
//   * Counts are non-negative integers stored as floats. Sums are exact while every partial sum is
//     ≤ 2^24 = 16 777 216, hence the traversal is exact for total ≤ kExactTotal. A single slot may
//     hold any count up to that (lightsim uses 0, 1, 2 and 4); fractional or negative counts are not
//     supported. readTotal() is exact up to 2^24 and never less than min(true total, 2^24).
//   * Base side ≤ kMaxBaseSize = 4096 (2^24 slots; also ≤ GL_MAX_TEXTURE_SIZE, checked). The caller
//     must check readTotal() against the output list's capacity (grow it, up to 4096², or refuse)
//     before compacting; a total ≤ 4096² = 2^24 is also what keeps the traversal exact.
//   * Memory: side²·4 bytes (base) + side²·16/3 bytes (pyramid): 2048²: 37 MiB; 4096²: 149 MiB.
//
// GL contract for a pass that uses the traversal (shaders/lightsim/histo_pyramid.glsl):
//   * compile it with defines() ({"HP_LEVELS", K}) and #include "lightsim/histo_pyramid.glsl";
//   * declare `uniform sampler2D <name>;`, call bind(unit) and set the sampler to that unit;
//   * per output fragment: k = hpTexelSlot(ivec2(gl_FragCoord.xy)); discard k ≥ total (a uniform
//     from readTotal(), or hpTotal(<name>)); ivec2 s = hpFind(<name>, k, j); read patch texel s;
//   * draw only hpLiveBox(total) of the output (glViewport(0, 0, box.x, box.y) after binding the
//     output framebuffer) — slots beyond it are never needed.
// build() leaves every GL binding and capability as it found it (gl/handle.h conventions).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/vec2.hpp>

#include "gl/buffer.h"
#include "gl/framebuffer.h"
#include "gl/handle.h"
#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "gl/vertex_array.h"
#include "lightsim/morton.h"

namespace eik {

// ---------------------------------------------------------------------------------------------
// Slots (Morton order), shared by the GPU pyramid and the CPU reference (histo_pyramid_cpu.h).

struct HistoPyramidLimits {
  static constexpr int kMaxBaseSize = 4096;
  static constexpr std::uint64_t kExactTotal = std::uint64_t{1} << 24;  // float-exact integer sums
  static constexpr std::size_t kAllSlots = std::numeric_limits<std::size_t>::max();
};

// Slot (list index) → texel and back (Morton, lightsim/morton.h; valid at every level of the
// pyramid), and the rectangle holding the first `count` slots.
inline glm::ivec2 hpSlotTexel(std::uint32_t slot) { return mortonTexel(slot); }
inline std::uint32_t hpTexelSlot(glm::ivec2 texel) { return mortonIndex(texel); }
inline glm::ivec2 hpLiveBox(std::uint64_t count) { return mortonBox(count); }
// The smallest power-of-two side whose square holds `capacity` slots (at least 1).
int hpBaseSizeFor(std::uint64_t capacity);
// log2 of a base side that is a power of two in [1, kMaxBaseSize]; InputError otherwise.
int hpCheckedLevels(int baseSize);
// The total a top texel (or a copy of it) holds: the sum of its four components; RuntimeError
// when one is not a non-negative finite number.
std::uint64_t hpTotalOfTop(const float top[4]);

// ---------------------------------------------------------------------------------------------
// GPU pyramid (needs a current GL context for its whole life; destroy it before the context).

class HistoPyramid {
 public:
  // A pyramid over a base of baseSize × baseSize slots (a power of two, 1..kMaxBaseSize and ≤
  // GL_MAX_TEXTURE_SIZE; InputError otherwise). Compiles its two small programs from `library`.
  explicit HistoPyramid(int baseSize, const gl::ShaderLibrary& library = gl::ShaderLibrary());
  HistoPyramid(HistoPyramid&&) noexcept = default;
  HistoPyramid& operator=(HistoPyramid&&) noexcept = default;

  int baseSize() const { return base_; }
  int levels() const { return levels_; }  // K = log2(baseSize) (1 for a 1×1 base) = HP_LEVELS
  std::uint64_t capacity() const { return std::uint64_t(base_) * std::uint64_t(base_); }

  // An R32F base of baseSize², owned by the pyramid: a producer (the analysis pass) may render its
  // counts straight into it as a colour attachment of its own framebuffer (gl::Framebuffer::attach),
  // then call build(liveSlots).
  const gl::Texture2D& base() const { return baseTexture_; }

  // Builds the pyramid from base(). Only slots < liveSlots count.
  void build(std::size_t liveSlots = HistoPyramidLimits::kAllSlots);
  // Builds it from the .r channel of `counts` instead (baseSize², any float format, read with
  // texelFetch: its filter does not matter). Only slots < liveSlots count.
  void build(const gl::Texture2D& counts, std::size_t liveSlots = HistoPyramidLimits::kAllSlots);

  // The total (the top texel's four components) read back with glReadPixels of 1 texel: waits for
  // the build.
  std::uint64_t readTotal() const;
  // The same in two halves: requestTotal() queues the 1-texel read into a pixel-pack buffer (no
  // wait); waitTotal() returns it, waiting only if the GPU is not done yet, so the CPU can queue
  // more work in between.
  void requestTotal();
  std::uint64_t waitTotal();
  // Copies the top texel into texel (0, 0) of `target` (an RGBA32F texture; a GPU copy, no wait):
  // how the simulator keeps the count on the GPU (live_count.h).
  void copyTopTo(const gl::Texture2D& target) const;

  // Binds the pyramid texture (all its mip levels) to unit `unit` for hpFind/hpTotal (leaves that
  // unit active). Its filter is GL_NEAREST_MIPMAP_NEAREST; read it with texelFetch only.
  void bind(int unit) const;
  GLuint textureId() const { return pyramid_.id(); }
  // {"HP_LEVELS", K}: the defines a pass including lightsim/histo_pyramid.glsl needs.
  gl::ShaderDefines defines() const;

  // The pyramid read back (tests, debugging): mip m as (side >> (m+1))² RGBA texels, texel order.
  std::vector<std::vector<float>> downloadLevels() const;

 private:
  int mipSide(int m) const;
  void reduceLevels(GLuint counts, std::size_t liveSlots);

  int base_ = 0;
  int levels_ = 0;
  gl::Texture2D baseTexture_;  // R32F counts, for producers
  gl::Texture2D pyramid_;      // RGBA32F, mips 0..K−1 (its mip 0 is (side/2)²)
  std::vector<gl::GlHandle<gl::detail::FramebufferTraits>> framebuffers_;  // one per mip, that mip attached
  gl::Program first_;   // level 1 from the counts
  gl::Program reduce_;  // level m + 1 from mip m − 1
  gl::FullscreenTriangle triangle_;
  gl::Buffer pbo_;  // pixel-pack buffer of requestTotal() (made on first use)
  bool pending_ = false;
};

}  // namespace eik
