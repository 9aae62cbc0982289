// OSMesa back end of GlContext: a headless software context (llvmpipe). It renders into a small
// buffer of our own that only OSMesaMakeCurrent needs; real rendering goes into framebuffer objects.
// OSMesa refuses forward-compatible contexts, so none is asked for (docs/architecture.md).
#include <GL/osmesa.h>  // includes <GL/gl.h> for its types; no gl* function is called here

#include <cstdint>
#include <string>
#include <vector>

#include <glm/common.hpp>

#include "core/error.h"
#include "gl/context_backend.h"

namespace eik::gl::detail {
namespace {

class OSMesaBackend final : public ContextBackend {
 public:
  OSMesaBackend(const ContextOptions& options, bool /*debug: OSMesa has no debug-context flag*/) {
    size_ = glm::max(options.size, glm::ivec2(1));
    const int attributes[] = {OSMESA_FORMAT,
                              OSMESA_RGBA,
                              OSMESA_DEPTH_BITS,
                              24,
                              OSMESA_STENCIL_BITS,
                              8,
                              OSMESA_ACCUM_BITS,
                              0,
                              OSMESA_PROFILE,
                              OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION,
                              3,
                              OSMESA_CONTEXT_MINOR_VERSION,
                              3,
                              0};
    context_ = OSMesaCreateContextAttribs(attributes, nullptr);
    if (!context_) {
      throw RuntimeError(
          "could not create an OpenGL 3.3 core context with OSMesa: OSMesaCreateContextAttribs failed "
          "(this libOSMesa offers no 3.3 core profile; try EIKONAL_GL=egl)");
    }
    buffer_.assign(static_cast<std::size_t>(size_.x) * static_cast<std::size_t>(size_.y), 0u);
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, size_.x, size_.y)) {
      OSMesaDestroyContext(context_);
      throw RuntimeError("could not create an OpenGL 3.3 core context with OSMesa: OSMesaMakeCurrent failed");
    }
    OSMesaPixelStore(OSMESA_Y_UP, 1);
  }

  ~OSMesaBackend() override {
    if (OSMesaGetCurrentContext() == context_) releaseCurrent();
    OSMesaDestroyContext(context_);
  }

  GlBackend kind() const override { return GlBackend::OSMesa; }

  void makeCurrent() override {
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, size_.x, size_.y)) {
      throw RuntimeError("OSMesaMakeCurrent failed");
    }
  }

  void releaseCurrent() override { OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0); }

  GlProcLoader loader() const override { return &OSMesaGetProcAddress; }

  std::string platform() const override { return "OSMesa"; }

  glm::ivec2 framebufferSize() const override { return size_; }

 private:
  OSMesaContext context_ = nullptr;
  glm::ivec2 size_{1, 1};
  std::vector<std::uint32_t> buffer_;  // RGBA8, one word a pixel
};

}  // namespace

std::unique_ptr<ContextBackend> createOSMesaBackend(const ContextOptions& options, bool debug) {
  return std::make_unique<OSMesaBackend>(options, debug);
}

}  // namespace eik::gl::detail
