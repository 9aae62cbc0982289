// GLFW back end of GlContext: an OpenGL 3.3 core context in a window (visible or hidden,
// resizable), for the interactive viewer and for tests under Xvfb. No GLFW_OPENGL_FORWARD_COMPAT:
// Mesa does not need it and OSMesa-style drivers refuse it (docs/architecture.md).
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <atomic>
#include <mutex>
#include <string>

#include <glm/common.hpp>

#include "core/error.h"
#include "gl/context_backend.h"

namespace eik::gl::detail {
namespace {

// GLFW is initialised with the first window and terminated with the last.
std::mutex g_glfwMutex;
std::atomic<int> g_glfwUsers = 0;
std::string g_lastGlfwError;  // guarded by g_glfwMutex while creating

void onGlfwError(int code, const char* description) {
  g_lastGlfwError = std::string(description ? description : "unknown error") + " (GLFW error " +
                    std::to_string(code) + ")";
}

std::string takeGlfwError() {
  std::string error = g_lastGlfwError.empty() ? std::string("unknown GLFW error") : g_lastGlfwError;
  g_lastGlfwError.clear();
  return error;
}

class WindowBackend final : public ContextBackend {
 public:
  WindowBackend(const ContextOptions& options, bool debug) {
    std::lock_guard lock(g_glfwMutex);
    glfwSetErrorCallback(onGlfwError);
    if (g_glfwUsers == 0 && !glfwInit()) {
      throw RuntimeError("could not create an OpenGL 3.3 core context in a GLFW window: glfwInit failed: " +
                         takeGlfwError());
    }
    ++g_glfwUsers;
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, debug ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_RESIZABLE, options.resizable ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
    glfwWindowHint(GLFW_STENCIL_BITS, 8);
    glm::ivec2 size = glm::max(options.size, glm::ivec2(1));
    window_ = glfwCreateWindow(size.x, size.y, options.title.c_str(), nullptr, nullptr);
    if (!window_) {
      std::string error = takeGlfwError();
      terminateIfLast();
      throw RuntimeError("could not create an OpenGL 3.3 core context in a GLFW window: " + error);
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(options.swapInterval);
    int major = 0, minor = 0, revision = 0;
    glfwGetVersion(&major, &minor, &revision);
    platform_ = "GLFW " + std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(revision);
    platform_ += options.visible ? " window" : " hidden window";
  }

  ~WindowBackend() override {
    std::lock_guard lock(g_glfwMutex);
    if (glfwGetCurrentContext() == window_) glfwMakeContextCurrent(nullptr);
    glfwDestroyWindow(window_);
    terminateIfLast();
  }

  GlBackend kind() const override { return GlBackend::Window; }
  void makeCurrent() override { glfwMakeContextCurrent(window_); }
  void releaseCurrent() override { glfwMakeContextCurrent(nullptr); }
  GlProcLoader loader() const override { return &glfwGetProcAddress; }
  std::string platform() const override { return platform_; }

  glm::ivec2 framebufferSize() const override {
    glm::ivec2 size(0);
    glfwGetFramebufferSize(window_, &size.x, &size.y);
    return size;
  }

  GLFWwindow* window() const override { return window_; }
  void swapBuffers() override { glfwSwapBuffers(window_); }
  bool shouldClose() const override { return glfwWindowShouldClose(window_) != 0; }

 private:
  static void terminateIfLast() {
    if (--g_glfwUsers == 0) glfwTerminate();
  }

  GLFWwindow* window_ = nullptr;
  std::string platform_;
};

}  // namespace

std::unique_ptr<ContextBackend> createWindowBackend(const ContextOptions& options, bool debug) {
  return std::make_unique<WindowBackend>(options, debug);
}

void pollWindowEvents() {
  if (g_glfwUsers.load() > 0) glfwPollEvents();  // no lock: event callbacks may do anything
}

}  // namespace eik::gl::detail
