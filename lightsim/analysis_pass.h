// AnalysisPass: ALGORITHM.md step 5 (analysis, §6.2.4) for every live patch, and the per-patch work
// of steps 2–4 that the point passes after it only scatter: one full-screen fragment pass over the
// live box with five render targets (step_targets.h).
//
//   shader   common/fullscreen.vert + shaders/lightsim/analysis.frag (with lightsim/fate.glsl and
//            lightsim/atlas.glsl), compiled for one deposit mode (DEPOSIT_ACCUMULATE / DEPOSIT_MAX)
//            and the atlas layout (AtlasLayout::defines)
//   step     5: the fate and output count of each patch (0 dead: flux, exited, folded, depth; 1
//            keep; 2 or 4 split); 4: the voxel of the new midpoint and the value deposited there;
//            2 and 3: the flux absorbed and reflected in this step, for the ledger
//   in       list `current` (after the update pass) and `previous` (before it: m_old, Φ_old),
//            patches 0 .. n − 1 (n the LiveCount on the GPU; drawn over `slots` ≥ n); the volume, GridUniforms and of StepUniforms Δt, the kill
//            threshold, split length, depth limit and split rule
//   out      `targets`: counts (the pyramid's base), deposit A/B, ledger A/B; slots from n on
//            (to the live box of `slots`) get count 0 and no deposit
//
// The CPU twin of one patch is stepPatch (cpu_simulator.h), steps 4 and 5.
#pragma once

#include <cstddef>
#include <string>

#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/vertex_array.h"
#include "gl/volume_textures.h"
#include "lightsim/atlas.h"
#include "lightsim/grid_uniforms.h"
#include "lightsim/live_count.h"
#include "lightsim/patch_textures.h"
#include "lightsim/simulator.h"
#include "lightsim/step_targets.h"
#include "lightsim/step_uniforms.h"

namespace eik::gpu {

class AnalysisPass {
 public:
  // volumeDefines: as for UpdatePass. `track`: the deposit records of track-length deposits
  // (DEPOSIT_TRACK, track_deposit_pass.h) instead of the midpoint's; `receiver`: patches reaching
  // the receiver plane of StepUniforms are received (RECEIVER).
  AnalysisPass(const gl::ShaderLibrary& library, DepositMode mode, const AtlasLayout& atlas,
               const std::string& volumeDefines, bool track = false, bool receiver = false);
  void run(const PatchTextures& current, const PatchTextures& previous, const LiveCount& live, std::size_t slots,
           StepTargets& targets, const gl::VolumeTextures& volume, const GridUniforms& grid,
           const StepUniforms& step) const;

 private:
  gl::Program program_;
  gl::FullscreenTriangle triangle_;
};

}  // namespace eik::gpu
