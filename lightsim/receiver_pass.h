// ReceiverPass: the GPU twin of the receiver-map deposits (ALGORITHM.md "Receivers";
// lightsim/receiver.h): a patch that reaches the receiver plane spreads its flux Φ uniformly over
// its footprint — the quadrilateral where its corner rays (x_c along w_c) meet the plane — split
// into the triangles (0, 1, 2) and (0, 2, 3), each taking Φ·|its area|/(|area 1| + |area 2|), each
// clipped exactly against every texel of the map (patchFootprint, depositFootprint and
// triangleSquareOverlap on the CPU).
//
//   shader   shaders/lightsim/receiver.vert + receiver.frag
//   draw     GL_TRIANGLES without vertex buffers, 12 vertices a patch (gl_VertexID / 12 = patch
//            index): for each footprint triangle one quad over its bounding box, grown outwards to
//            whole texels (conservative), in the map's texel coordinates; culled (degenerate
//            positions) when the patch was not received, a corner ray runs parallel to the plane,
//            the triangle has no flux or lies off the map, or a footprint corner is not finite or
//            ≥ 1e15 texels away (a negligible share of its flux would land on the map). A
//            degenerate triangle (no area) gives its whole share to the texel of its centroid, as
//            depositConvex does (so a patch focused onto the plane is not lost).
//   fragment the exact area of triangle ∩ texel (Sutherland–Hodgman against the texel's four
//            edges, shoelace area), out = share·overlap/|triangle area|, summed by additive
//            blending (gl::ScopedBlendAdd) into the map's RGBA32F target; flux off the map is
//            dropped (viewport = the map), as on the CPU
//   in       `after`: the patches (P0..P3 = (x_c, w_c.x), W01/W23 = w_c.yz, patch.glsl) in
//            grid-local coordinates (world − origin); `receiveInfo` (RGBA32F, the list's size,
//            patch k at mortonTexel(k)): rgb = the flux Φ the patch brings to the plane, a > 0 when
//            it was received (else it deposits nothing). The patches' own FLUX is not read.
//   out      `target`: flux per texel (W, RGB; alpha unused, 0) added to what is there
//
// Precision: everything on the GPU is float. Footprint corners are computed relative to the map's
// corner (a point of the plane, so the same footprint as patchFootprint's relative to map.point,
// without the cancellation of uv − origin), and the clipping relative to each texel's corner, so
// a texel's flux is as exact as float coordinates of the size of the map (in texels) allow
// (receiver_pass_test.cpp: ~1e-7 of a patch's flux per texel against the CPU). A triangle whose
// height is below 1e-5 of its longest edge (float cannot resolve its area) counts as degenerate.
// Each texel sums its patches in float (additive blending); CpuSimulator sums in double.
//
// GL state: run() binds the target's framebuffer (viewport = the map), the list's eight textures
// to units 0..7 and receiveInfo to unit 8 (left bound, like the other passes), turns blending on
// (GL_ONE, GL_ONE) and face culling, depth and scissor tests off for its draw only (restored), and
// leaves no program, vertex array or framebuffer bound (gl::ScopedPassBindings).
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "core/receiver_map.h"
#include "gl/framebuffer.h"
#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "gl/vertex_array.h"
#include "lightsim/patch_textures.h"

namespace eik::gpu {

// The receiver map's render target: one RGBA32F texture of map.texels (texel (i, j) = pixel
// (i, j), so u runs along x and v along y) holding the flux per texel, and its framebuffer.
class ReceiverTarget {
 public:
  ReceiverTarget() = default;
  // InputError naming "receiver" when texels is empty or exceeds GL_MAX_TEXTURE_SIZE. Cleared.
  explicit ReceiverTarget(glm::ivec2 texels);

  glm::ivec2 texels() const { return texels_; }
  std::size_t texelCount() const { return static_cast<std::size_t>(texels_.x) * static_cast<std::size_t>(texels_.y); }
  std::size_t bytes() const { return texelCount() * 16; }
  gl::Framebuffer& framebuffer() { return framebuffer_; }
  const gl::Texture2D& texture() const { return texture_; }
  explicit operator bool() const { return bool(texture_); }

  // Zero flux.
  void clear();
  // The flux per texel (W, RGB), u fastest, like the CPU's per-texel sums (depositFootprint).
  std::vector<glm::dvec3> readFlux() const;
  // Writes the irradiance = flux / pitch² into map.irradiance (RGB floats, u fastest), as the end
  // of CpuSimulator::run does. RuntimeError when map.texels is not this target's size.
  // `extra_flux` (W per texel, or empty): added to each texel's flux first (directMapLight).
  void fill(ReceiverMap& map, const std::vector<glm::dvec3>& extra_flux = {}) const;

 private:
  glm::ivec2 texels_{0};
  gl::Texture2D texture_;
  gl::Framebuffer framebuffer_;
};

class ReceiverPass {
 public:
  explicit ReceiverPass(const gl::ShaderLibrary& library);
  // Deposits the footprints of patches 0 .. count − 1 of `after` that `receiveInfo` marks as
  // received into `target` (additive). map: the plane and its texels (its irradiance is not read);
  // origin: the grid's origin, which `after`'s coordinates are relative to. RuntimeError when
  // target's size is not map.texels, count exceeds the list (or 12·count a GLsizei), or
  // receiveInfo does not cover mortonBox(count).
  void run(const PatchTextures& after, const gl::Texture2D& receiveInfo, std::size_t count, ReceiverTarget& target,
           const ReceiverMap& map, const glm::dvec3& origin) const;

 private:
  gl::Program program_;
  gl::VertexArray vao_;
};

}  // namespace eik::gpu
