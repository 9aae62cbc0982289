// StepTargets: what the analysis pass (analysis_pass.h) writes per patch, in the patch list layout
// (patch k at mortonTexel(k), patch_textures.h), and what the passes after it read:
//
//   attachment  target            texel                                       read by
//   0           pyramid.base()    count 0, 1, 2 or 4 (R32F)                   HistoPyramid::build
//   1           depositA          (deposit value, atlas x; x < 0: none)       DepositPass
//   2           depositB          (deposit direction, atlas y)                DepositPass
//   3           ledgerA           (flux absorbed, fate code)                  LedgerPass, CompactPass
//   4           ledgerB           (flux reflected, left a boundary layer)     LedgerPass
//
// (shaders/lightsim/analysis.frag; fate codes: shaders/lightsim/fate_codes.glsl.) The pyramid over
// the counts is ALGORITHM.md step 6's histogram pyramid (histo_pyramid.h).
#pragma once

#include <cstddef>

#include "gl/framebuffer.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "lightsim/histo_pyramid.h"

namespace eik::gpu {

// Fate codes read back on the CPU (ledgerA's w & 15), as shaders/lightsim/fate_codes.glsl defines them.
constexpr int kFateExited = 5;    // FATE_EXITED
constexpr int kFateReceived = 9;  // FATE_RECEIVED

struct StepTargets {
  HistoPyramid pyramid;
  gl::Texture2D depositA, depositB, ledgerA, ledgerB;  // RGBA32F
  gl::Framebuffer framebuffer;                         // base, deposit A, B, ledger A, B

  // Targets for a list of side × side patches.
  StepTargets(int side, const gl::ShaderLibrary& library);
  // Texture memory of StepTargets(side).
  static std::size_t bytesFor(int side);
};

}  // namespace eik::gpu
