// ListSet: the GPU simulator's working set for one patch list side: the two patch lists it
// ping-pongs between (patch_textures.h) and the targets of their analysis (step_targets.h).
//
//   a  the current list: read by the update pass, written by the compaction
//   b  the updated list: written by the update pass, read by analysis, ledger and compaction
//
// The simulator grows the list by making a new ListSet of the next power of two and compacting
// into its list a (nothing to copy: compaction writes every live patch); the old set goes after.
#pragma once

#include <cstddef>

#include "gl/shader_library.h"
#include "lightsim/patch_textures.h"
#include "lightsim/step_targets.h"

namespace eik::gpu {

struct ListSet {
  PatchTextures a, b;  // a: the current list; b: the updated one
  StepTargets targets;

  ListSet(int side, const gl::ShaderLibrary& library) : a(side), b(side), targets(side, library) {}
  int side() const { return a.side(); }
  // Texture memory of ListSet(side): two lists of eight RGBA32F textures and the step targets
  // (about 330 B a slot).
  static std::size_t bytesFor(int side) {
    const std::size_t texels = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
    return 2 * texels * PatchTextures::kAttachments * 16 + StepTargets::bytesFor(side);
  }
};

}  // namespace eik::gpu
