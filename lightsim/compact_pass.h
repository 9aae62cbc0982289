// CompactPass: ALGORITHM.md step 6, compaction and expansion (Ziegler et al. 2006; §6.2.4): one
// fragment per slot k of the new list, over its live box; the histogram pyramid over the analysis
// counts (histo_pyramid.h) gives the source patch s and sub-index j of slot k.
//
//   shader   common/fullscreen.vert + shaders/lightsim/compact.frag (with
//            lightsim/histo_pyramid.glsl), compiled for the pyramid's levels (HistoPyramid::defines)
//   step     6: count 1 copies the patch; a split writes child j of its 2×2 or 1×2 split (bilinear
//            corners and w, w renormalised to n, flux shared by area, depth + 1 or + ½)
//   in       list `in` (the updated list the analysis saw), `targets` (its built pyramid, and
//            ledger A for the fate of each source), the volume (n at the new corners), GridUniforms
//   out      list `out`: patches 0 .. total − 1, total = the pyramid's total (hpTotal, read on
//            the GPU); `slots` (≥ total, ≤ out's capacity) sizes the draw: the total itself when it
//            was read back, or a bound on it (4 × the list the analysis saw) when it was not
//
// The CPU twin is the prefix sum over the counts and splitPatch in CpuSimulator::run (the same
// order: the pyramid's Morton order is the prefix sum's index order).
#pragma once

#include <cstddef>
#include <string>

#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/vertex_array.h"
#include "gl/volume_textures.h"
#include "lightsim/grid_uniforms.h"
#include "lightsim/patch_textures.h"
#include "lightsim/step_targets.h"

namespace eik::gpu {

class CompactPass {
 public:
  // pyramidDefines: HistoPyramid::defines() of the pyramids it will read (their levels).
  CompactPass(const gl::ShaderLibrary& library, const gl::ShaderDefines& pyramidDefines,
              const std::string& volumeDefines);
  // dt: an ordinary step's time, Δt or a straight step's (StepUniforms::stepDt), reflectedDt a
  // reflected wavefront's (StepUniforms::reflectedStepDt; 0: dt): with sharp interfaces the reach
  // of a followed reflection, 4·dt + 2h (sharp.glsl reflectedPatch).
  void run(const PatchTextures& in, const StepTargets& targets, PatchTextures& out, std::size_t slots,
           const gl::VolumeTextures& volume, const GridUniforms& grid, float dt = 0.0f,
           float reflectedDt = 0.0f) const;

 private:
  gl::Program program_;
  gl::FullscreenTriangle triangle_;
};

}  // namespace eik::gpu
