// The update pass, ALGORITHM.md steps 1–3 (see update_pass.h).
#include "lightsim/update_pass.h"

#include "gl/debug.h"
#include "gl/scoped_state.h"

namespace eik::gpu {

namespace {

const char* integratorDefine(Integrator integrator) {
  switch (integrator) {
    case Integrator::RK4: return "INTEGRATOR_RK4";
    case Integrator::RK2: return "INTEGRATOR_RK2";
    case Integrator::Euler: break;
  }
  return "INTEGRATOR_EULER";
}

}  // namespace

UpdatePass::UpdatePass(const gl::ShaderLibrary& library, Integrator integrator, const std::string& volumeDefines)
    : program_(library.program("common/fullscreen.vert", "lightsim/update.frag", {{integratorDefine(integrator), "1"}},
                               volumeDefines)) {}

void UpdatePass::run(const PatchTextures& in, PatchTextures& out, std::size_t count, const gl::VolumeTextures& volume,
                     const GridUniforms& grid, const StepUniforms& step) const {
  gl::ScopedPassBindings unbind;
  out.framebuffer().bind();
  viewportLiveBox(count);
  program_.use();
  volume.bind(program_, in.bind(program_, "uPatch", 0));
  grid.set(program_);
  program_.set("uCount", static_cast<int>(count));
  program_.set("uDt", step.dt);
  program_.set("uBoundaryOn", step.boundaryOn);
  program_.set("uBoundaryOff", step.boundaryOff);
  program_.set("uSplitLength", step.splitLength);  // sharp interfaces: tears
  program_.set("uMaxDepth", step.maxDepth);
  program_.set("uAxisSplit", step.axisSplit);
  triangle_.draw();
  gl::checkErrors("UpdatePass");
}

}  // namespace eik::gpu
