// OSMesa back end of GlContext: a headless software context (llvmpipe). It renders into a small
// buffer of our own that only OSMesaMakeCurrent needs; real rendering goes into framebuffer objects.
// OSMesa refuses forward-compatible contexts, so none is asked for (docs/architecture.md).
//
// libOSMesa is opened with dlopen when the first OSMesa context is made, not linked: it pulls in
// LLVM (115 MB, about 0.05 s of dynamic linking on every start), which the CPU twin never needs,
// and a GPU server without Mesa must still run the programs through EGL.
#include <GL/osmesa.h>  // declarations and types only: every OSMesa entry point is reached by dlsym
#include <dlfcn.h>

#include <cstdint>
#include <string>
#include <vector>

#include <glm/common.hpp>

#include "core/error.h"
#include "gl/context_backend.h"

namespace eik::gl::detail {
namespace {

// The OSMesa entry points this back end calls, looked up once per process. The library stays
// loaded until the process ends (LLVM does not support being unloaded).
struct OSMesaLibrary {
  decltype(&::OSMesaCreateContextAttribs) createContextAttribs = nullptr;
  decltype(&::OSMesaMakeCurrent) makeCurrent = nullptr;
  decltype(&::OSMesaDestroyContext) destroyContext = nullptr;
  decltype(&::OSMesaGetCurrentContext) getCurrentContext = nullptr;
  decltype(&::OSMesaPixelStore) pixelStore = nullptr;
  decltype(&::OSMesaGetProcAddress) getProcAddress = nullptr;
  std::string error;  // why it could not be loaded; empty when it was
};

template <typename F>
bool lookUp(void* handle, const char* name, F& function, std::string& error) {
  function = reinterpret_cast<F>(dlsym(handle, name));
  if (!function && error.empty()) error = std::string("libOSMesa has no ") + name;
  return function != nullptr;
}

const OSMesaLibrary& osmesaLibrary() {
  static const OSMesaLibrary library = [] {
    OSMesaLibrary l;
    void* handle = dlopen("libOSMesa.so.8", RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = dlerror();  // the versioned name's reason, the one a user can act on
      l.error = std::string("libOSMesa.so.8 could not be loaded (") + (why ? why : "not found") +
                "; Debian: apt-get install libosmesa6, or use EIKONAL_GL=egl)";
      handle = dlopen("libOSMesa.so", RTLD_NOW | RTLD_LOCAL);  // a development symlink only
      if (!handle) return l;
      l.error.clear();
    }
    lookUp(handle, "OSMesaCreateContextAttribs", l.createContextAttribs, l.error);
    lookUp(handle, "OSMesaMakeCurrent", l.makeCurrent, l.error);
    lookUp(handle, "OSMesaDestroyContext", l.destroyContext, l.error);
    lookUp(handle, "OSMesaGetCurrentContext", l.getCurrentContext, l.error);
    lookUp(handle, "OSMesaPixelStore", l.pixelStore, l.error);
    lookUp(handle, "OSMesaGetProcAddress", l.getProcAddress, l.error);
    return l;
  }();
  return library;
}

// The loaded library, or RuntimeError saying why there is none.
const OSMesaLibrary& requireOSMesa() {
  const OSMesaLibrary& l = osmesaLibrary();
  if (!l.error.empty()) throw RuntimeError("could not create an OpenGL 3.3 core context with OSMesa: " + l.error);
  return l;
}

class OSMesaBackend final : public ContextBackend {
 public:
  OSMesaBackend(const ContextOptions& options, bool /*debug: OSMesa has no debug-context flag*/)
      : osmesa_(requireOSMesa()) {
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
    context_ = osmesa_.createContextAttribs(attributes, nullptr);
    if (!context_) {
      throw RuntimeError(
          "could not create an OpenGL 3.3 core context with OSMesa: OSMesaCreateContextAttribs failed "
          "(this libOSMesa offers no 3.3 core profile; try EIKONAL_GL=egl)");
    }
    buffer_.assign(static_cast<std::size_t>(size_.x) * static_cast<std::size_t>(size_.y), 0u);
    if (!osmesa_.makeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, size_.x, size_.y)) {
      osmesa_.destroyContext(context_);
      throw RuntimeError("could not create an OpenGL 3.3 core context with OSMesa: OSMesaMakeCurrent failed");
    }
    osmesa_.pixelStore(OSMESA_Y_UP, 1);
  }

  ~OSMesaBackend() override {
    if (osmesa_.getCurrentContext() == context_) releaseCurrent();
    osmesa_.destroyContext(context_);
  }

  GlBackend kind() const override { return GlBackend::OSMesa; }

  void makeCurrent() override {
    if (!osmesa_.makeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, size_.x, size_.y)) {
      throw RuntimeError("OSMesaMakeCurrent failed");
    }
  }

  void releaseCurrent() override { osmesa_.makeCurrent(nullptr, nullptr, 0, 0, 0); }

  GlProcLoader loader() const override { return osmesa_.getProcAddress; }

  std::string platform() const override { return "OSMesa"; }

  glm::ivec2 framebufferSize() const override { return size_; }

 private:
  const OSMesaLibrary& osmesa_;
  OSMesaContext context_ = nullptr;
  glm::ivec2 size_{1, 1};
  std::vector<std::uint32_t> buffer_;  // RGBA8, one word a pixel
};

}  // namespace

void loadOSMesaLibrary() { (void)osmesaLibrary(); }

std::unique_ptr<ContextBackend> createOSMesaBackend(const ContextOptions& options, bool debug) {
  return std::make_unique<OSMesaBackend>(options, debug);
}

}  // namespace eik::gl::detail
