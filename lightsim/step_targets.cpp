// The analysis pass's targets (see step_targets.h).
#include "lightsim/step_targets.h"

namespace eik::gpu {

namespace {

const gl::Sampling kNearest{gl::Filter::Nearest, gl::Wrap::ClampToEdge};

}  // namespace

StepTargets::StepTargets(int side, const gl::ShaderLibrary& library)
    : pyramid(side, library),
      depositA({side, side}, gl::TextureFormat::RGBA32F, kNearest),
      depositB({side, side}, gl::TextureFormat::RGBA32F, kNearest),
      ledgerA({side, side}, gl::TextureFormat::RGBA32F, kNearest),
      ledgerB({side, side}, gl::TextureFormat::RGBA32F, kNearest),
      framebuffer({side, side}) {
  framebuffer.attach(0, pyramid.base());
  framebuffer.attach(1, depositA);
  framebuffer.attach(2, depositB);
  framebuffer.attach(3, ledgerA);
  framebuffer.attach(4, ledgerB);
  framebuffer.checkComplete();
}

std::size_t StepTargets::bytesFor(int side) {
  // Pyramid: R32F base + RGBA32F levels (16/3 B a slot); four RGBA32F targets.
  const std::size_t texels = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  return texels * 4 + texels * 16 / 3 + 4 * texels * 16;
}

}  // namespace eik::gpu
