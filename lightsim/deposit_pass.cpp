// The deposit pass, ALGORITHM.md step 4 (see deposit_pass.h).
#include "lightsim/deposit_pass.h"

#include "gl/debug.h"
#include "gl/scoped_state.h"

namespace eik::gpu {

DepositPass::DepositPass(const gl::ShaderLibrary& library, const AtlasLayout& layout, DepositMode mode)
    : vao_(gl::VertexArray::create()), mode_(mode) {
  gl::ShaderDefines defines = layout.defines();
  defines.emplace_back(mode == DepositMode::Max ? "DEPOSIT_MAX" : "DEPOSIT_ACCUMULATE", "1");
  program_ = library.program("lightsim/deposit.vert", "lightsim/deposit.frag", defines);
}

void DepositPass::run(const gl::Texture2D& depositA, const gl::Texture2D& depositB, std::size_t count,
                      AtlasTargets& atlas, float energyRef) const {
  if (count == 0) return;
  gl::ScopedPassBindings unbind;
  atlas.framebuffer().bind();
  program_.use();
  depositA.bind(0);
  program_.setSampler("uDepositA", 0);
  depositB.bind(1);
  program_.setSampler("uDepositB", 1);
  program_.set("uEnergyRef", energyRef);
  vao_.bind();
  if (mode_ == DepositMode::Accumulate) {
    gl::ScopedBlendAdd blend;
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(count));
  } else {
    gl::ScopedDepthTest depth(GL_LESS);
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(count));
  }
  gl::checkErrors("DepositPass");
}

}  // namespace eik::gpu
