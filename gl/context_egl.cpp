// EGL back end of GlContext: a headless context with no window system and no surface
// (EGL_KHR_surfaceless_context). Displays are tried in this order:
//   1. EGL_EXT_platform_device: each EGL device, hardware before software (on GPU servers with no
//      display this is the way in, e.g. NVIDIA's EGL);
//   2. EGL_MESA_platform_surfaceless (Mesa);
//   3. eglGetDisplay(EGL_DEFAULT_DISPLAY).
// The first display that gives an OpenGL 3.3 core context wins (EIKONAL_EGL_PLATFORM restricts
// the search to one of the three).
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdlib>
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <glm/common.hpp>

#include "core/error.h"
#include "gl/context_backend.h"

namespace eik::gl::detail {
namespace {

bool hasToken(const char* list, std::string_view token) {
  if (!list) return false;
  std::string_view all(list);
  std::size_t start = 0;
  while (start < all.size()) {
    std::size_t end = all.find(' ', start);
    if (end == std::string_view::npos) end = all.size();
    if (all.substr(start, end - start) == token) return true;
    start = end + 1;
  }
  return false;
}

std::string eglErrorName(EGLint error) {
  switch (error) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: return "EGL error " + std::to_string(error);
  }
}

// eglInitialize/eglTerminate are per display, and displays are shared process-wide: count the
// contexts using each one and terminate it with the last.
std::mutex g_displayMutex;
std::map<EGLDisplay, int> g_displayUsers;

bool acquireDisplay(EGLDisplay display, EGLint* major, EGLint* minor) {
  std::lock_guard lock(g_displayMutex);
  if (!eglInitialize(display, major, minor)) return false;
  ++g_displayUsers[display];
  return true;
}

void releaseDisplay(EGLDisplay display) {
  std::lock_guard lock(g_displayMutex);
  auto it = g_displayUsers.find(display);
  if (it == g_displayUsers.end()) return;
  if (--it->second == 0) {
    g_displayUsers.erase(it);
    eglTerminate(display);
  }
}

struct Candidate {
  std::string name;
  EGLDisplay display = EGL_NO_DISPLAY;
};

class EglBackend final : public ContextBackend {
 public:
  EglBackend(const ContextOptions& options, bool debug) : size_(glm::max(options.size, glm::ivec2(1))) {
    const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!clientExtensions) eglGetError();  // no EGL_EXT_client_extensions: clear EGL_BAD_DISPLAY

    auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    std::vector<Candidate> candidates;
    if (getPlatformDisplay && hasToken(clientExtensions, "EGL_EXT_platform_device")) {
      auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
      auto queryDeviceString =
          reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
      EGLDeviceEXT devices[16];
      EGLint count = 0;
      if (queryDevices && queryDevices(16, devices, &count)) {
        std::vector<Candidate> software;
        for (EGLint i = 0; i < count; ++i) {
          const char* deviceExtensions = queryDeviceString ? queryDeviceString(devices[i], EGL_EXTENSIONS) : nullptr;
          bool isSoftware = hasToken(deviceExtensions, "EGL_MESA_device_software");
          EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
          if (display == EGL_NO_DISPLAY) continue;
          std::string name = "device platform, device " + std::to_string(i);
          if (isSoftware) name += " (software)";
          (isSoftware ? software : candidates).push_back({name, display});
        }
        candidates.insert(candidates.end(), software.begin(), software.end());
      }
      eglGetError();
    }
    if (getPlatformDisplay && hasToken(clientExtensions, "EGL_MESA_platform_surfaceless")) {
      EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (display != EGL_NO_DISPLAY) candidates.push_back({"surfaceless platform", display});
      eglGetError();
    }
    {
      EGLDisplay display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
      if (display != EGL_NO_DISPLAY) candidates.push_back({"default display", display});
      eglGetError();
    }

    // EIKONAL_EGL_PLATFORM=device|surfaceless|default keeps only that kind of display (to debug
    // or test one path).
    if (const char* only = std::getenv("EIKONAL_EGL_PLATFORM"); only && *only) {
      std::string wanted = std::string(only) == "default" ? "default display" : std::string(only) + " platform";
      std::erase_if(candidates, [&](const Candidate& c) { return c.name.rfind(wanted, 0) != 0; });
      if (candidates.empty()) {
        throw RuntimeError("could not create an OpenGL 3.3 core context with EGL: no " + wanted +
                           " display (EIKONAL_EGL_PLATFORM=" + only + "; expected device, surfaceless or default)");
      }
    }

    std::string reasons;
    for (const Candidate& candidate : candidates) {
      std::string reason;
      if (tryDisplay(candidate, debug, reason)) return;
      reasons += (reasons.empty() ? "" : "; ") + candidate.name + ": " + reason;
    }
    if (candidates.empty()) reasons = "no EGL display (no device, surfaceless or default display)";
    throw RuntimeError("could not create an OpenGL 3.3 core context with EGL: " + reasons);
  }

  ~EglBackend() override {
    if (eglGetCurrentContext() == context_) releaseCurrent();
    eglDestroyContext(display_, context_);
    releaseDisplay(display_);
    // Only with nothing current: eglReleaseThread would also unbind another live context.
    if (eglGetCurrentContext() == EGL_NO_CONTEXT) eglReleaseThread();
  }

  GlBackend kind() const override { return GlBackend::EGL; }

  void makeCurrent() override {
    eglBindAPI(EGL_OPENGL_API);
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      throw RuntimeError("eglMakeCurrent failed: " + eglErrorName(eglGetError()));
    }
  }

  void releaseCurrent() override { eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }

  GlProcLoader loader() const override { return &eglGetProcAddress; }

  std::string platform() const override { return platform_; }

  glm::ivec2 framebufferSize() const override { return size_; }

 private:
  bool tryDisplay(const Candidate& candidate, bool debug, std::string& reason) {
    EGLint major = 0, minor = 0;
    if (!acquireDisplay(candidate.display, &major, &minor)) {
      reason = "eglInitialize failed (" + eglErrorName(eglGetError()) + ")";
      return false;
    }
    EGLDisplay display = candidate.display;
    auto fail = [&](std::string why) {
      reason = std::move(why);
      releaseDisplay(display);
      return false;
    };
    const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
    bool egl15 = major > 1 || (major == 1 && minor >= 5);
    if (!egl15 && !hasToken(extensions, "EGL_KHR_create_context")) {
      return fail("EGL " + std::to_string(major) + "." + std::to_string(minor) +
                  " without EGL_KHR_create_context cannot ask for a core profile");
    }
    if (!hasToken(extensions, "EGL_KHR_surfaceless_context")) return fail("no EGL_KHR_surfaceless_context");
    const char* apis = eglQueryString(display, EGL_CLIENT_APIS);
    if (apis && !hasToken(apis, "OpenGL")) return fail(std::string("no desktop OpenGL (client APIs: ") + apis + ")");
    if (!eglBindAPI(EGL_OPENGL_API)) return fail("eglBindAPI(EGL_OPENGL_API) failed");

    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!hasToken(extensions, "EGL_KHR_no_config_context")) {
      const EGLint configAttributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
      EGLint count = 0;
      if (!eglChooseConfig(display, configAttributes, &config, 1, &count) || count < 1) {
        return fail("no EGL config with EGL_OPENGL_BIT");
      }
    }

    for (bool withDebug : {debug, false}) {
      std::vector<EGLint> attributes = {EGL_CONTEXT_MAJOR_VERSION_KHR, 3, EGL_CONTEXT_MINOR_VERSION_KHR, 3,
                                        EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR,
                                        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR};
      if (withDebug) {
        attributes.insert(attributes.end(), {EGL_CONTEXT_FLAGS_KHR, EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR});
      }
      attributes.push_back(EGL_NONE);
      context_ = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes.data());
      if (context_ != EGL_NO_CONTEXT) break;
      reason = "eglCreateContext failed (" + eglErrorName(eglGetError()) + ")";
      if (!withDebug) break;
    }
    if (context_ == EGL_NO_CONTEXT) return fail(reason);
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      std::string why = "eglMakeCurrent without a surface failed (" + eglErrorName(eglGetError()) + ")";
      eglDestroyContext(display, context_);
      context_ = EGL_NO_CONTEXT;
      return fail(why);
    }
    display_ = display;
    const char* vendor = eglQueryString(display, EGL_VENDOR);
    platform_ = "EGL " + std::to_string(major) + "." + std::to_string(minor) + " " + candidate.name +
                (vendor ? std::string(" (") + vendor + ")" : std::string());
    return true;
  }

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  glm::ivec2 size_;
  std::string platform_;
};

}  // namespace

std::unique_ptr<ContextBackend> createEglBackend(const ContextOptions& options, bool debug) {
  return std::make_unique<EglBackend>(options, debug);
}

}  // namespace eik::gl::detail
