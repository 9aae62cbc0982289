// Internal to gl/: the interface each context back end implements (context_osmesa.cpp,
// context_egl.cpp, context_window.cpp). These files include their platform headers only, never
// glad: the back ends create, bind and destroy contexts and hand out their getProcAddress.
#pragma once

#include <memory>
#include <string>

#include <glm/vec2.hpp>

#include "gl/context.h"

namespace eik::gl::detail {

using GlProc = void (*)();
using GlProcLoader = GlProc (*)(const char* name);

class ContextBackend {
 public:
  virtual ~ContextBackend() = default;
  virtual GlBackend kind() const = 0;
  virtual void makeCurrent() = 0;
  virtual void releaseCurrent() = 0;
  // The platform's getProcAddress; glad loads the GL entry points through it.
  virtual GlProcLoader loader() const = 0;
  virtual std::string platform() const = 0;
  virtual glm::ivec2 framebufferSize() const = 0;
  virtual GLFWwindow* window() const { return nullptr; }
  virtual void swapBuffers() {}
  virtual bool shouldClose() const { return false; }
};

// Each throws RuntimeError("could not create an OpenGL 3.3 core context with ...: REASON").
std::unique_ptr<ContextBackend> createOSMesaBackend(const ContextOptions& options, bool debug);
// Loads libOSMesa (and with it Mesa and LLVM) if it is not yet: what createOSMesaBackend does first.
void loadOSMesaLibrary();
std::unique_ptr<ContextBackend> createEglBackend(const ContextOptions& options, bool debug);
std::unique_ptr<ContextBackend> createWindowBackend(const ContextOptions& options, bool debug);
void pollWindowEvents();

}  // namespace eik::gl::detail
