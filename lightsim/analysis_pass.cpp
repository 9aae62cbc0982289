// The analysis pass, ALGORITHM.md step 5 and the per-patch work of steps 2–4 (see analysis_pass.h).
#include "lightsim/analysis_pass.h"

#include "gl/debug.h"
#include "gl/scoped_state.h"

namespace eik::gpu {

namespace {

const char* depositDefine(DepositMode mode) { return mode == DepositMode::Max ? "DEPOSIT_MAX" : "DEPOSIT_ACCUMULATE"; }

}  // namespace

AnalysisPass::AnalysisPass(const gl::ShaderLibrary& library, DepositMode mode, const AtlasLayout& atlas,
                           const std::string& volumeDefines, bool track, bool receiver) {
  gl::ShaderDefines defines = atlas.defines();
  defines.emplace_back(depositDefine(mode), "1");
  if (track) defines.emplace_back("DEPOSIT_TRACK", "1");
  if (receiver) defines.emplace_back("RECEIVER", "1");
  program_ = library.program("common/fullscreen.vert", "lightsim/analysis.frag", defines, volumeDefines);
}

void AnalysisPass::run(const PatchTextures& current, const PatchTextures& previous, const LiveCount& live,
                       std::size_t slots, StepTargets& targets, const gl::VolumeTextures& volume, const GridUniforms& grid,
                       const StepUniforms& step) const {
  gl::ScopedPassBindings unbind;
  targets.framebuffer.bind();
  viewportLiveBox(slots);
  program_.use();
  int unit = current.bind(program_, "uPatch", 0);  // 8 units
  for (int c = 0; c < 4; ++c, ++unit) {
    previous.texture(PatchTextures::kP0 + c).bind(unit);
    program_.setSampler("uPrevious[" + std::to_string(c) + "]", unit);
  }
  previous.texture(PatchTextures::kFlux).bind(unit);
  program_.setSampler("uPreviousFlux", unit++);
  unit = volume.bind(program_, unit);  // at most 2 (optics, absorption)
  live.bind(program_, unit);           // 16 units in all, as many as GL 3.3 guarantees
  grid.set(program_);
  program_.set("uDt", step.dt);
  program_.set("uStepDt", step.stepDt);
  program_.set("uReflectedStepDt", step.reflectedStepDt);
  program_.set("uFluxKill", step.fluxKill);
  program_.set("uSplitLength", step.splitLength);
  program_.set("uMaxDepth", step.maxDepth);
  program_.set("uAxisSplit", step.axisSplit);
  program_.set("uKillAtMaxDepth", step.killAtMaxDepth);
  program_.set("uBoxMin", step.boxMin);
  program_.set("uBoxMax", step.boxMax);
  program_.set("uBounces", step.bounces);
  program_.set("uReceiverPoint", step.receiverPoint);
  program_.set("uReceiverNormal", step.receiverNormal);
  program_.set("uPassToReceiver", step.passToReceiver);
  triangle_.draw();
  gl::checkErrors("AnalysisPass");
}

}  // namespace eik::gpu
