// UpdatePass: ALGORITHM.md steps 1–3 for every live patch, one full-screen fragment pass over the
// list's live box (viewportLiveBox) writing all eight patch textures at once (MRT).
//
//   shader   common/fullscreen.vert + shaders/lightsim/update.frag (with lightsim/fresnel.glsl),
//            compiled for one integrator: INTEGRATOR_EULER (Eq. 6.1/6.2), _RK2 or _RK4
//   step     1 update (§6.2.2): per corner x ← x + Δt·w/n², w ← w + Δt·∇n/n (or RK2/RK4), then
//            |w| = n(x_new); 2 absorption Φ ← Φ·exp(−σa(m_old)·Δs_m); 3 Fresnel boundary
//            tracking (enter a layer at g > g_on, leave it at g < g_off keeping 1 − R); a patch
//            in quiet space may instead cross it in one straight step (free flight)
//   in       list `in` (patches 0 .. n − 1, n the LiveCount on the GPU; the pass is drawn over
//            `slots` ≥ n and skips the rest), the volume's n, ∇n, σa, GridUniforms, and of
//            StepUniforms Δt, g_on, g_off (and the straight step, the flight cap, the split
//            length and depth limit); the quiet maps of free flight and straight steps (UpdateMaps)
//   out      list `out` (the same patches, stepped; slots from n on are left alone)
//
// The CPU twin of one patch is stepPatch (cpu_simulator.h), steps 1–3, with advanceCorner.
#pragma once

#include <cstddef>
#include <string>

#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/vertex_array.h"
#include "gl/volume_textures.h"
#include "lightsim/grid_uniforms.h"
#include "lightsim/live_count.h"
#include "lightsim/patch_textures.h"
#include "lightsim/quiet_texture.h"
#include "lightsim/simulator.h"
#include "lightsim/step_uniforms.h"

namespace eik::gpu {

// The quiet maps an update reads (shaders/lightsim/flight.glsl). `quiet` set: free flight
// (FREE_FLIGHT) across quiet space where σa = 0; `absorbers` set: straight steps (StepUniforms::
// stepDt > dt) only where no voxel within their reach absorbs (ABSORBER_MAP). The pass is compiled
// for the maps it was made with, and run() must get the same ones.
struct UpdateMaps {
  const QuietTexture* quiet = nullptr;
  const QuietTexture* absorbers = nullptr;
};

class UpdatePass {
 public:
  // volumeDefines: the volume layout's GLSL defines (gl::VolumeLayout::glslDefines, plus
  // EXACT_TRILINEAR when the shader samples the fields itself). freeFlight / absorberMap: compiled
  // to read those maps (UpdateMaps).
  UpdatePass(const gl::ShaderLibrary& library, Integrator integrator, const std::string& volumeDefines,
             bool freeFlight = false, bool absorberMap = false);
  void run(const PatchTextures& in, PatchTextures& out, const LiveCount& live, std::size_t slots,
           const gl::VolumeTextures& volume, const GridUniforms& grid, const StepUniforms& step,
           const UpdateMaps& maps = {}) const;

 private:
  gl::Program program_;
  gl::FullscreenTriangle triangle_;
  bool freeFlight_ = false, absorberMap_ = false;
};

}  // namespace eik::gpu
