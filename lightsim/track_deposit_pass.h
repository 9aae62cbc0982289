// TrackDepositPass: ALGORITHM.md step 4 with the track-length kernel ("Track deposits",
// DepositKernel::Track), the GPU twin of the CPU's applyTrackDeposits (cpu_simulator.cpp) and
// forEachTrackWeight / trackLattice (track_deposit.h). Each patch-step deposits its flux times the
// length of its sub-paths over the voxel volume, spread over the voxels with the trilinear hats
// K_v integrated exactly along each sub-path.
//
//   shader   shaders/lightsim/track_deposit.vert + track_deposit.frag, compiled for the atlas
//            layout (AtlasLayout::defines)
//   draw     fragment-parallel scatter: one GL_POINTS vertex per (patch, z-slice), count·S vertices
//            with S = maxExtentVoxels + 2. The vertex shader finds the voxel box of the hats the
//            swept patch touches (centres within one voxel of the corners' bounding box, clamped to
//            the grid), culls the slices outside it and covers, in that slice's atlas tile, the x/y
//            extent of the swept hull cut by the slab of z that reaches the slice's hats (the 28
//            corner pairs' crossings with its planes) with one square point (gl_PointSize): a
//            slanted flight covers a few voxels of its box in each slice (BENCHMARKS.md "On a real
//            GPU": the pass 1.7× faster on an H200). Each fragment is one voxel v: it sums,
//            over the patch's n_u × n_v sub-paths, ∫ K_v ds exactly (the path cut at the hat's kinks,
//            each piece by 2-point Gauss–Legendre, exact for the cubic), and additive blending sums
//            the patches.
//   step     4, accumulate only: for every sub-path (u, v) = ((i_u + ½)/n_u, (i_v + ½)/n_v) from the
//            bilinear point of the corners before to that of the corners after (clipped at the
//            receiver plane when asked), with Φ_sub = track_flux/(n_u·n_v), L its length, d̂ its
//            direction and w_v = ∫ K_v ds / L:
//              target 0 += (Φ_sub · L/V_voxel · w_v, 0)
//              target 1 += (lum(Φ_sub) · L · d̂ · w_v, 1)     (.w: 1 per patch that reached v)
//            Lattice n = trackLattice(longer edge / h) per direction (u: x₀x₁ and x₃x₂, v: x₁x₂ and
//            x₀x₃, before and after), as subPathLattice in cpu_simulator.cpp, but with an allowance
//            of 1e-4 half-voxels (the CPU's 1e-9 in double) so that float corners of an edge of
//            exactly k/2 voxels get the CPU's k sub-paths (track_deposit.vert trackLattice).
//   in       `before`, `after`: the corner positions P0..P3 of patches 0 .. count − 1 (patch k at
//            mortonTexel(k)) in the grid's local frame; `trackInfo` (RGBA32F, same layout): rgb =
//            track_flux (W), a = flag: a < 0 no deposit; a ≥ 0 deposit; a ≥ 1 also clip the
//            sub-paths at the receiver plane (when TrackDepositUniforms::receiverEnabled)
//   out      `atlas` (accumulate mode): its two RGBA32F targets, added to
//
// GL state: the pass binds the atlas framebuffer (viewport = atlas), its program and VAO, texture
// units 0..16 (before: 0..7, after: 8..15, trackInfo: 16), and, for its draw only, additive
// blending and GL_PROGRAM_POINT_SIZE (both restored). Program, VAO and framebuffer are unbound on
// exit (gl::ScopedPassBindings); the texture units keep their bindings.
#pragma once

#include <cstddef>

#include <glm/vec3.hpp>

#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "gl/vertex_array.h"
#include "lightsim/atlas.h"
#include "lightsim/grid_uniforms.h"
#include "lightsim/patch_textures.h"

namespace eik::gpu {

struct TrackDepositUniforms {
  // The grid in the corners' frame: boundsMin, boundsMax and dims place the voxels, voxelEdge is h of
  // the sub-path lattice (the smallest voxel edge, as VolumeSampler::h), voxelVolume is V_voxel.
  // invExtent is not used.
  GridUniforms grid;
  // The receiver plane (ALGORITHM.md "Receivers"): the sub-paths of patches flagged a ≥ 1 are
  // clipped to the side the normal points to, as applyTrackDeposits does.
  bool receiverEnabled = false;
  glm::vec3 receiverPoint{0.0f};
  glm::vec3 receiverNormal{0.0f, 1.0f, 0.0f};  // unit
  // A bound, in voxels of each axis, on the extent along any axis of a patch-step's 8 corners
  // (before and after): its hats then span at most maxExtentVoxels + 2 voxels an axis, which is the
  // number of z-slices drawn per patch and the largest point size. A patch-step beyond the bound
  // loses the voxels past maxExtentVoxels + 2 from the low corner of its box along that axis.
  int maxExtentVoxels = 8;
  // Patch-steps whose irradiance (track flux, max channel, over the smaller of the two corner
  // quadrilaterals' areas) is under this take the 1-voxel lattice (track_deposit.h trackSpacing;
  // StepContext::dim_irradiance). 0: every patch-step takes the ½-voxel lattice.
  float dimIrradiance = 0.0f;
};

class TrackDepositPass {
 public:
  // Compiles the program for `layout` and reads the context's point size range.
  TrackDepositPass(const gl::ShaderLibrary& library, const AtlasLayout& layout);

  // The largest maxExtentVoxels this context can draw (the point size range's maximum − 2).
  int maxExtentVoxels() const { return maxExtent_; }

  // Adds the track deposits of patch-steps 0 .. count − 1 to `atlas` (accumulate mode, the layout
  // given to the constructor). RuntimeError when the atlas is in max mode or of another layout,
  // or when uniforms.maxExtentVoxels is < 0 or > maxExtentVoxels().
  void run(const PatchTextures& before, const PatchTextures& after, const gl::Texture2D& trackInfo, std::size_t count,
           AtlasTargets& atlas, const TrackDepositUniforms& uniforms) const;

 private:
  gl::Program program_;
  gl::VertexArray vao_;
  AtlasLayout layout_;
  int maxExtent_ = 0;
};

}  // namespace eik::gpu
