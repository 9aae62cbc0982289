// The update pass, ALGORITHM.md steps 1–3 (see update_pass.h).
#include "lightsim/update_pass.h"

#include <stdexcept>

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

gl::ShaderDefines defines(Integrator integrator, bool freeFlight, bool absorberMap) {
  gl::ShaderDefines d{{integratorDefine(integrator), "1"}};
  if (freeFlight) d.push_back({"FREE_FLIGHT", "1"});
  if (absorberMap) d.push_back({"ABSORBER_MAP", "1"});
  return d;
}

}  // namespace

UpdatePass::UpdatePass(const gl::ShaderLibrary& library, Integrator integrator, const std::string& volumeDefines,
                       bool freeFlight, bool absorberMap)
    : program_(library.program("common/fullscreen.vert", "lightsim/update.frag",
                               defines(integrator, freeFlight, absorberMap), volumeDefines)),
      freeFlight_(freeFlight),
      absorberMap_(absorberMap) {}

void UpdatePass::run(const PatchTextures& in, PatchTextures& out, const LiveCount& live, std::size_t slots,
                     const gl::VolumeTextures& volume, const GridUniforms& grid, const StepUniforms& step,
                     const UpdateMaps& maps) const {
  gl::ScopedPassBindings unbind;
  out.framebuffer().bind();
  viewportLiveBox(slots);
  program_.use();
  int unit = volume.bind(program_, in.bind(program_, "uPatch", 0));
  if (freeFlight_ != (maps.quiet && *maps.quiet) || absorberMap_ != (maps.absorbers && *maps.absorbers))
    throw std::logic_error("UpdatePass::run: the quiet maps differ from the ones the pass was made for");
  if (freeFlight_) maps.quiet->bind(program_, "uQuietSat", unit++);
  if (absorberMap_) maps.absorbers->bind(program_, "uAbsorberSat", unit++);
  live.bind(program_, unit++);
  grid.set(program_);
  program_.set("uDt", step.dt);
  program_.set("uStepDt", step.stepDt);
  program_.set("uReflectedStepDt", step.reflectedStepDt);
  program_.set("uStraightReach", step.straightReach);
  program_.set("uFlightCap", step.flightCap);
  program_.set("uFlightExtentVoxels", step.flightExtentVoxels);
  program_.set("uMergeSteps", step.mergeSteps);
  program_.set("uBoxMin", step.boxMin);
  program_.set("uBoxMax", step.boxMax);
  program_.set("uKeepAtMaxDepth", !step.killAtMaxDepth);
  program_.set("uBoundaryOn", step.boundaryOn);
  program_.set("uBoundaryOff", step.boundaryOff);
  program_.set("uSplitLength", step.splitLength);  // sharp interfaces: tears
  program_.set("uMaxDepth", step.maxDepth);
  program_.set("uAxisSplit", step.axisSplit);
  program_.set("uRetakeAtInterfaces", step.retakeAtInterfaces);
  triangle_.draw();
  gl::checkErrors("UpdatePass");
}

}  // namespace eik::gpu
