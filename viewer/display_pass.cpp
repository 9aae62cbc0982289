#include "viewer/display_pass.h"

#include <cmath>

namespace eik {

DisplayPass::DisplayPass(const gl::ShaderLibrary& shaders)
    : program_(shaders.program("common/fullscreen.vert", "viewer/display.frag")) {}

void DisplayPass::draw(const gl::Texture2D& hdr, glm::ivec2 viewport, float exposure_ev, ToneMapper tonemap) const {
  glViewport(0, 0, viewport.x, viewport.y);
  glDisable(GL_BLEND);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_FRAMEBUFFER_SRGB);  // the shader encodes sRGB itself
  hdr.bind(0);
  program_.use();
  program_.set("uHdr", 0);
  program_.set("uExposureScale", std::exp2(exposure_ev));
  program_.set("uToneMapper", tonemap == ToneMapper::Linear ? 0 : tonemap == ToneMapper::Reinhard ? 1 : 2);
  program_.set("uViewportSize", viewport);
  triangle_.draw();
}

}  // namespace eik
