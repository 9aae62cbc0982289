// The display pass of the interactive viewer: the renderer's linear HDR image (an RGBA32F texture)
// → exposure → tone mapping (linear, Reinhard, ACES fit) → sRGB, drawn into whatever framebuffer
// is bound (the window's back buffer, 8 bits a channel). The formulas are those of
// core/tonemap.h, written again in shaders/viewer/display.frag, so that the window shows what
// `viewer --render OUT.png` writes for the same exposure and tone mapper (to 8-bit rounding).
#pragma once

#include <glm/glm.hpp>

#include "core/tonemap.h"
#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "gl/vertex_array.h"

namespace eik {

class DisplayPass {
 public:
  // Needs a current GL context.
  explicit DisplayPass(const gl::ShaderLibrary& shaders);

  // Draws `hdr` stretched over the viewport (0, 0, viewport) of the bound framebuffer (nearest
  // texel; one to one when the sizes agree). Leaves blending and depth testing off.
  void draw(const gl::Texture2D& hdr, glm::ivec2 viewport, float exposure_ev, ToneMapper tonemap) const;

 private:
  gl::Program program_;
  gl::FullscreenTriangle triangle_;
};

}  // namespace eik
