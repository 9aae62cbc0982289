// GlContext: picks a back end, loads glad from the new context's getProcAddress, checks that the
// context really is 3.3 core (or newer), records its strings and limits, and installs the debug
// callback (gl/debug.h) when asked.
#include "gl/context.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "core/text.h"
#include "gl/context_backend.h"
#include "gl/debug.h"
#include "gl/gl.h"

namespace eik::gl {
namespace {

thread_local GlContext* t_current = nullptr;
std::atomic<unsigned long long> g_nextSerial{1};
// The getProcAddress glad's global function pointers were last loaded from. Pointers from one
// platform (OSMesa's, EGL's, GLX's) must not be used with another platform's context.
thread_local detail::GlProcLoader t_loadedFrom = nullptr;

std::string getString(GLenum name) {
  const GLubyte* text = glGetString(name);
  return text ? reinterpret_cast<const char*>(text) : "";
}

int getInt(GLenum name) {
  GLint value = 0;
  glGetIntegerv(name, &value);
  return value;
}

// "with OSMesa" / "with EGL" / "in a GLFW window", for error messages.
std::string describeBackend(GlBackend backend) {
  switch (backend) {
    case GlBackend::OSMesa: return "with OSMesa";
    case GlBackend::EGL: return "with EGL";
    case GlBackend::Window: return "in a GLFW window";
    case GlBackend::Auto: break;
  }
  return "headless";
}

void loadFunctions(detail::GlProcLoader loader, const std::string& backendName) {
  if (t_loadedFrom == loader) return;
  t_loadedFrom = nullptr;
  if (!gladLoadGL(loader)) {
    throw RuntimeError("could not create an OpenGL 3.3 core context " + backendName +
                       ": could not load the OpenGL functions (gladLoadGL failed)");
  }
  t_loadedFrom = loader;
}

}  // namespace

GlBackend parseGlBackend(std::string_view text, std::string_view source) {
  const std::string name = lower(text);
  if (name == "auto") return GlBackend::Auto;
  if (name == "osmesa") return GlBackend::OSMesa;
  if (name == "egl") return GlBackend::EGL;
  if (name == "window" || name == "glfw") return GlBackend::Window;
  throw InputError(std::string(source), "", "unknown OpenGL back end '" + std::string(text) +
                                                "' (expected auto, osmesa, egl or window)");
}

std::string_view glBackendName(GlBackend backend) {
  switch (backend) {
    case GlBackend::Auto: return "auto";
    case GlBackend::OSMesa: return "osmesa";
    case GlBackend::EGL: return "egl";
    case GlBackend::Window: return "window";
  }
  return "?";
}

bool displayAvailable() {
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (x11 && *x11) || (wayland && *wayland);
}

bool gpuDevicePresent() {
  std::error_code error;
  if (std::filesystem::exists("/dev/nvidia0", error)) return true;
  for (std::filesystem::directory_iterator entry("/dev/dri", error), end; !error && entry != end;
       entry.increment(error))
    if (entry->path().filename().string().rfind("renderD", 0) == 0) return true;
  return false;
}

bool isSoftwareRenderer(const GlInfo& info) {
  const std::string renderer = lower(info.renderer);
  for (const char* name : {"llvmpipe", "softpipe", "swrast", "swiftshader"})
    if (renderer.find(name) != std::string::npos) return true;
  return false;
}

GlBackend glBackendFromEnvironment(GlBackend fallback) {
  const char* value = std::getenv("EIKONAL_GL");
  if (!value || !*value) return fallback;
  return parseGlBackend(value, "EIKONAL_GL");
}

DriverPreload::DriverPreload(const ContextOptions& options) {
  const GlBackend requested = resolveGlBackend(options.backend);
  if (requested == GlBackend::OSMesa || requested == GlBackend::Auto) thread_ = std::thread(detail::loadOSMesaLibrary);
}

DriverPreload::~DriverPreload() {
  if (thread_.joinable()) thread_.join();
}

GlContext::GlContext(const ContextOptions& options) {
  serial_ = g_nextSerial++;
  debug_ = options.debug.value_or(debugRequestedByEnvironment());
  GlBackend requested = resolveGlBackend(options.backend);
  switch (requested) {
    case GlBackend::OSMesa: backend_ = detail::createOSMesaBackend(options, debug_); break;
    case GlBackend::EGL: backend_ = detail::createEglBackend(options, debug_); break;
    case GlBackend::Window: backend_ = detail::createWindowBackend(options, debug_); break;
    case GlBackend::Auto: {
      try {
        backend_ = detail::createOSMesaBackend(options, debug_);
      } catch (const RuntimeError& osmesaError) {
        try {
          backend_ = detail::createEglBackend(options, debug_);
        } catch (const RuntimeError& eglError) {
          throw RuntimeError(std::string("could not create a headless OpenGL 3.3 core context:\n  ") +
                             osmesaError.what() + "\n  " + eglError.what());
        }
      }
      break;
    }
  }
  const std::string backendName = describeBackend(backend_->kind());

  t_loadedFrom = nullptr;  // a new context: always load its own entry points
  loadFunctions(backend_->loader(), backendName);

  info_.backend = backend_->kind();
  info_.platform = backend_->platform();
  info_.vendor = getString(GL_VENDOR);
  info_.renderer = getString(GL_RENDERER);
  info_.version = getString(GL_VERSION);
  info_.glslVersion = getString(GL_SHADING_LANGUAGE_VERSION);
  info_.major = getInt(GL_MAJOR_VERSION);
  info_.minor = getInt(GL_MINOR_VERSION);
  info_.coreProfile = (getInt(GL_CONTEXT_PROFILE_MASK) & GL_CONTEXT_CORE_PROFILE_BIT) != 0;
  if (info_.major * 10 + info_.minor < 33 || !info_.coreProfile) {
    std::string got = info_.version + (info_.coreProfile ? "" : ", not a core profile");
    t_current = nullptr;  // the failed context replaced whatever was current
    backend_->releaseCurrent();
    throw RuntimeError("could not create an OpenGL 3.3 core context " + backendName + ": got OpenGL " + got +
                       " from " + info_.renderer);
  }
  info_.maxTextureSize = getInt(GL_MAX_TEXTURE_SIZE);
  info_.max3DTextureSize = getInt(GL_MAX_3D_TEXTURE_SIZE);
  info_.maxColorAttachments = getInt(GL_MAX_COLOR_ATTACHMENTS);
  info_.maxDrawBuffers = getInt(GL_MAX_DRAW_BUFFERS);
  info_.maxTextureImageUnits = getInt(GL_MAX_TEXTURE_IMAGE_UNITS);
  GLint extensionCount = getInt(GL_NUM_EXTENSIONS);
  for (GLint i = 0; i < extensionCount; ++i) {
    const GLubyte* extension = glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i));
    if (extension) extensions_.emplace_back(reinterpret_cast<const char*>(extension));
  }
  std::sort(extensions_.begin(), extensions_.end());
  while (glGetError() != GL_NO_ERROR) {
  }
  if (debug_) info_.debugOutput = installDebugCallback();
  t_current = this;
  setErrorChecksEnabled(debug_);
}

GlContext::~GlContext() {
  if (t_current == this) {
    t_current = nullptr;
    setErrorChecksEnabled(false);
  }
  // The back end releases the context if it is current on this thread, then destroys it.
  backend_.reset();
}

GlContext* GlContext::current() { return t_current; }
unsigned long long GlContext::currentSerial() { return t_current ? t_current->serial_ : 0; }

void GlContext::makeCurrent() {
  backend_->makeCurrent();
  loadFunctions(backend_->loader(), describeBackend(backend_->kind()));
  t_current = this;
  setErrorChecksEnabled(debug_);
}

GlBackend GlContext::backend() const { return backend_->kind(); }

std::string GlContext::summary() const {
  return info_.renderer + ", OpenGL " + info_.version + ", via " + info_.platform;
}

bool GlContext::hasExtension(std::string_view name) const {
  return std::binary_search(extensions_.begin(), extensions_.end(), name, std::less<>());
}

bool GlContext::isWindow() const { return backend_->window() != nullptr; }
GLFWwindow* GlContext::window() const { return backend_->window(); }
void GlContext::swapBuffers() { backend_->swapBuffers(); }
bool GlContext::shouldClose() const { return backend_->shouldClose(); }
glm::ivec2 GlContext::framebufferSize() const { return backend_->framebufferSize(); }
void GlContext::pollEvents() { detail::pollWindowEvents(); }

}  // namespace eik::gl
