// The compaction pass, ALGORITHM.md step 6 (see compact_pass.h).
#include "lightsim/compact_pass.h"

#include "gl/debug.h"
#include "gl/scoped_state.h"

namespace eik::gpu {

CompactPass::CompactPass(const gl::ShaderLibrary& library, const gl::ShaderDefines& pyramidDefines,
                         const std::string& volumeDefines)
    : program_(library.program("common/fullscreen.vert", "lightsim/compact.frag", pyramidDefines, volumeDefines)) {}

void CompactPass::run(const PatchTextures& in, const StepTargets& targets, PatchTextures& out, std::size_t slots,
                      const gl::VolumeTextures& volume, const GridUniforms& grid, float dt, float reflectedDt) const {
  gl::ScopedPassBindings unbind;
  out.framebuffer().bind();
  viewportLiveBox(slots);
  program_.use();
  int unit = in.bind(program_, "uPatch", 0);
  targets.pyramid.bind(unit);
  program_.setSampler("uPyramid", unit++);
  targets.ledgerA.bind(unit);
  program_.setSampler("uLedgerA", unit++);
  volume.bind(program_, unit);
  grid.set(program_);
  program_.set("uDt", dt);
  program_.set("uReflectedDt", reflectedDt > 0.0f ? reflectedDt : dt);
  triangle_.draw();
  gl::checkErrors("CompactPass");
}

}  // namespace eik::gpu
