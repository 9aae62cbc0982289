// An OpenGL 3.3 core context (docs/architecture.md): one interface, three back ends.
//   OSMesa  headless, software (llvmpipe); the default headless back end.
//   EGL     headless without a display: EGL_EXT_platform_device (GPU servers), then
//           EGL_MESA_platform_surfaceless, then the default display. Survives Mesa ≥ 25.1, which
//           dropped OSMesa.
//   Window  a GLFW window (X11/Wayland), visible or hidden, for the interactive viewer.
// Every back end asks for 3.3 core and accepts anything newer (Mesa gives 4.5). Creating a context
// makes it current and loads glad's function pointers from that context's own getProcAddress
// (when creation fails, no GlContext is current afterwards).
//
// Headless contexts have no usable default framebuffer: render into a gl::Framebuffer.
// GL objects (gl/texture.h, ...) must be destroyed while their context is current and before it;
// an object that outlives its context skips its glDelete* (the context took everything with it).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <glm/vec2.hpp>

struct GLFWwindow;

namespace eik::gl {

enum class GlBackend { Auto, OSMesa, EGL, Window };

// "auto" | "osmesa" | "egl" | "window" (any case); InputError naming `source` otherwise.
GlBackend parseGlBackend(std::string_view text, std::string_view source = "--gl");
std::string_view glBackendName(GlBackend backend);
// The back end EIKONAL_GL names, or `fallback` when it is unset or empty.
GlBackend glBackendFromEnvironment(GlBackend fallback = GlBackend::Auto);
// What a context asked for `requested` tries: EIKONAL_GL's back end for Auto (Auto again when it is
// unset: OSMesa, then EGL), the back end itself otherwise.
inline GlBackend resolveGlBackend(GlBackend requested) {
  return requested == GlBackend::Auto ? glBackendFromEnvironment() : requested;
}
// Whether a window can be opened at all (DISPLAY or WAYLAND_DISPLAY is set): the viewer opens a
// Window when this holds and nothing else was asked for, else renders headless.
bool displayAvailable();
// Whether this machine shows a GPU device to user space (a DRM render node /dev/dri/renderD*, or
// NVIDIA's /dev/nvidia0): without one no OpenGL context can be hardware accelerated, whatever the
// back end, so a caller choosing between the GPU path and a CPU twin need not load a driver to
// find that out (loading Mesa's OSMesa and LLVM costs 0.05-0.1 s and 55 MB on two cores).
bool gpuDevicePresent();

struct ContextOptions {
  // Auto: EIKONAL_GL when set, else headless: OSMesa, then EGL if OSMesa fails.
  GlBackend backend = GlBackend::Auto;
  // Window: the window size in screen coordinates. OSMesa: its own (unused) colour buffer.
  glm::ivec2 size{1, 1};
  std::string title = "Eikonal";  // Window
  bool visible = true;            // Window: false makes a hidden window (off-screen rendering)
  bool resizable = true;          // Window
  int swapInterval = 1;           // Window: 1 = vsync
  // GL error checks and the debug message callback (gl/debug.h); default: debugRequestedByEnvironment().
  std::optional<bool> debug = std::nullopt;
};

struct GlInfo {
  GlBackend backend = GlBackend::Auto;
  std::string platform;  // "OSMesa", "EGL 1.5 surfaceless (Mesa Project)", "GLFW 3.3.8 X11 GLX ..."
  std::string vendor;    // GL_VENDOR, e.g. "Mesa"
  std::string renderer;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version;   // GL_VERSION, e.g. "4.5 (Core Profile) Mesa 22.3.6"
  std::string glslVersion;
  int major = 0, minor = 0;
  bool coreProfile = false;
  bool debugOutput = false;  // a debug message callback is installed
  int maxTextureSize = 0;
  int max3DTextureSize = 0;
  int maxColorAttachments = 0;
  int maxDrawBuffers = 0;
  int maxTextureImageUnits = 0;  // in the fragment shader
};

// Whether GL_RENDERER names a software rasterizer (llvmpipe, softpipe, swrast, SwiftShader).
bool isSoftwareRenderer(const GlInfo& info);

namespace detail {
class ContextBackend;
}

// Loads the driver a context of these options would load — OSMesa's library, and with it Mesa and
// LLVM, 0.05 s on two cores — on a thread of its own, so that a program reads its input meanwhile;
// a context made later waits for the load if it is not done. Nothing for the other back ends (a
// window's or EGL's driver is found by the platform). Joins the thread when destroyed; a library
// that fails to load is reported by the context, as without a preload.
class DriverPreload {
 public:
  explicit DriverPreload(const ContextOptions& options);
  ~DriverPreload();
  DriverPreload(const DriverPreload&) = delete;
  DriverPreload& operator=(const DriverPreload&) = delete;

 private:
  std::thread thread_;
};

class GlContext {
 public:
  // Creates the context and makes it current. Throws RuntimeError("could not create an OpenGL 3.3
  // core context with OSMesa: ...") when the back end cannot give one.
  explicit GlContext(const ContextOptions& options = {});
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // The context current on this thread (made current through this class), or nullptr.
  static GlContext* current();
  // A number that no other context of this process has had (addresses can be reused): GL objects
  // remember it to delete themselves only in the context that made them.
  unsigned long long serial() const { return serial_; }
  // The serial of the context current on this thread, 0 if none.
  static unsigned long long currentSerial();

  // Makes this context current on this thread (reloading the function pointers if the previous
  // current context came from another back end).
  void makeCurrent();

  GlBackend backend() const;
  const GlInfo& info() const { return info_; }
  // "llvmpipe (LLVM 15.0.6, 256 bits), OpenGL 4.5 (Core Profile) Mesa 22.3.6, via OSMesa"
  std::string summary() const;
  bool hasExtension(std::string_view name) const;
  bool debug() const { return debug_; }

  // Window back end; for headless contexts window() is nullptr and the rest do nothing.
  bool isWindow() const;
  GLFWwindow* window() const;
  void swapBuffers();
  bool shouldClose() const;
  glm::ivec2 framebufferSize() const;  // in pixels; headless: the size asked for
  static void pollEvents();            // GLFW events of every window (no-op without a window)

 private:
  std::unique_ptr<detail::ContextBackend> backend_;
  GlInfo info_;
  std::vector<std::string> extensions_;  // sorted
  bool debug_ = false;
  unsigned long long serial_ = 0;
};

}  // namespace eik::gl
