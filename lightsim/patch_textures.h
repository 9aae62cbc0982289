// The GPU patch list (ALGORITHM.md "Patch state"): eight RGBA32F textures of one square,
// power-of-two size, attached together to one framebuffer so a pass writes a whole patch with
// multiple render targets (GL 3.3 guarantees 8 draw buffers):
//
//   attachment  texture  texel
//   0..3        P0..P3   (x_c, w_c.x)                 corner c position and w.x
//   4           W01      (w₀.y, w₀.z, w₁.y, w₁.z)
//   5           W23      (w₂.y, w₂.z, w₃.y, w₃.z)
//   6           FLUX     (Φ.rgb, A₀)
//   7           META     (depth, n_in, cos_in, T_fresnel of the last step)
//                        with sharp interfaces (PatchLayout::Sharp, SHARP_INTERFACES in GLSL):
//                        (depth + 64·(reflections + 256·bounce), Σ (medium_c + 1)·8^c + 4096·crossed
//                         + 65536·reflected, reflect_pending, T_fresnel + 2·event) — all integers
//                         exact in float
//
// Patch k lives at texel mortonTexel(k) (x from the even bits of k, y from the odd ones). That is
// the order in which a histogram pyramid is descended with the child order (0,0), (1,0), (0,1),
// (1,1) (ALGORITHM.md step 6), so the compacted list has exactly the order of the CPU twin's
// prefix sum. The first `count` patches then lie inside the rectangle mortonBox(count), which the
// full-screen passes use as their viewport.
//
// The simulator ping-pongs between two PatchTextures; a list never needs copying when it grows,
// because compaction writes the whole new list (see GpuSimulator).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "gl/framebuffer.h"
#include "gl/program.h"
#include "lightsim/morton.h"
#include "lightsim/wavefront.h"

namespace eik {

// mortonTexel, mortonIndex, mortonBox: lightsim/morton.h.
// Sets the viewport to mortonBox(count) (after the target's bind() set it to the whole list): the
// full-screen passes over a list draw only the live patches' box.
void viewportLiveBox(std::size_t count);
// The smallest power-of-two side whose square holds `count` patches (at least `minimum`).
int patchSideFor(std::size_t count, int minimum = 1);

// One patch as its eight texels (the layout above), and back (float ↔ double). The META texel
// holds the boundary-layer state (Smooth) or the sharp-interface state (Sharp).
using PatchTexels = std::array<glm::vec4, 8>;
enum class PatchLayout { Smooth, Sharp };
PatchTexels packPatch(const Patch& patch, PatchLayout layout = PatchLayout::Smooth);
Patch unpackPatch(const PatchTexels& texels, PatchLayout layout = PatchLayout::Smooth);

class PatchTextures {
 public:
  static constexpr int kAttachments = 8;
  enum Slot { kP0 = 0, kP1, kP2, kP3, kW01, kW23, kFlux, kMeta };
  // GLSL sampler names of the slots, as declared by shaders/lightsim/patch.glsl for the list read
  // as `prefix` ("uPatch" → uPatch[0] .. uPatch[7]).
  static std::string samplerName(const std::string& prefix, int slot);

  PatchTextures() = default;
  // A list of side × side patches (side a power of two, ≤ GL_MAX_TEXTURE_SIZE); contents undefined.
  explicit PatchTextures(int side);

  int side() const { return side_; }
  std::size_t capacity() const { return static_cast<std::size_t>(side_) * static_cast<std::size_t>(side_); }
  std::size_t bytes() const { return capacity() * kAttachments * 16; }
  explicit operator bool() const { return side_ > 0; }

  // The render target: all eight textures as colour attachments 0..7.
  gl::Framebuffer& framebuffer() { return framebuffer_; }
  const gl::Framebuffer& framebuffer() const { return framebuffer_; }
  const gl::Texture2D& texture(int slot) const { return textures_[static_cast<std::size_t>(slot)]; }

  // Binds the eight textures to units firstUnit .. firstUnit + 7 and points the sampler array
  // `prefix`[0..7] of `program` at them. Returns the next free unit.
  int bind(const gl::Program& program, const std::string& prefix, int firstUnit) const;

  // Writes patches 0 .. patches.size() − 1 (the rest of the list becomes zero).
  void upload(std::span<const PatchTexels> patches);
  // Reads patches 0 .. count − 1 back (tests, debugging).
  std::vector<PatchTexels> download(std::size_t count) const;

 private:
  int side_ = 0;
  std::array<gl::Texture2D, kAttachments> textures_;  // owned; attached to framebuffer_
  gl::Framebuffer framebuffer_;
};

}  // namespace eik
