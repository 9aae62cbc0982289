// OpenGL error checking: the debug message callback and the glGetError checks (see debug.h).
#include "gl/debug.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"

namespace eik::gl {

namespace detail {
thread_local bool g_errorChecks = false;
}  // namespace detail

namespace {

// Messages of type ERROR recorded by the callback since the last check (the callback runs
// synchronously, inside the GL call, on the calling thread).
thread_local std::vector<std::string> t_recordedErrors;

int debugLevel() {
  const char* value = std::getenv("EIKONAL_GL_DEBUG");
  if (value && *value) return std::atoi(value);
#ifdef NDEBUG
  return 0;
#else
  return 1;
#endif
}

const char* sourceName(GLenum source) {
  switch (source) {
    case GL_DEBUG_SOURCE_API: return "api";
    case GL_DEBUG_SOURCE_WINDOW_SYSTEM: return "window system";
    case GL_DEBUG_SOURCE_SHADER_COMPILER: return "shader compiler";
    case GL_DEBUG_SOURCE_THIRD_PARTY: return "third party";
    case GL_DEBUG_SOURCE_APPLICATION: return "application";
    default: return "other";
  }
}

const char* typeName(GLenum type) {
  switch (type) {
    case GL_DEBUG_TYPE_ERROR: return "error";
    case GL_DEBUG_TYPE_DEPRECATED_BEHAVIOR: return "deprecated";
    case GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR: return "undefined behaviour";
    case GL_DEBUG_TYPE_PORTABILITY: return "portability";
    case GL_DEBUG_TYPE_PERFORMANCE: return "performance";
    default: return "other";
  }
}

void GLAD_API_PTR onDebugMessage(GLenum source, GLenum type, GLuint /*id*/, GLenum severity, GLsizei length,
                                 const GLchar* message, const void* /*user*/) {
  std::string text = length >= 0 ? std::string(message, static_cast<std::size_t>(length)) : std::string(message);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  // Compile and link failures come back through the info log (gl/program.cpp) with file names;
  // Mesa repeats them here as errors, which must not fail the next, unrelated check.
  if (source == GL_DEBUG_SOURCE_SHADER_COMPILER) {
    if (debugLevel() >= 2) std::fprintf(stderr, "GL debug (shader compiler): %s\n", text.c_str());
    return;
  }
  if (type == GL_DEBUG_TYPE_ERROR) {
    if (t_recordedErrors.size() < 16) t_recordedErrors.push_back(text);
    return;  // reported by the next check, as an exception
  }
  // Never throw from here: the callback runs inside the driver.
  if (severity == GL_DEBUG_SEVERITY_HIGH || debugLevel() >= 2) {
    std::fprintf(stderr, "GL debug (%s, %s): %s\n", sourceName(source), typeName(type), text.c_str());
  }
}

}  // namespace

bool debugRequestedByEnvironment() { return debugLevel() >= 1; }

bool errorChecksEnabled() { return detail::g_errorChecks; }
void setErrorChecksEnabled(bool enabled) { detail::g_errorChecks = enabled; }

bool installDebugCallback() {
  if (GLAD_GL_KHR_debug) {
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(onDebugMessage, nullptr);
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
  } else if (GLAD_GL_ARB_debug_output) {
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS_ARB);
    glDebugMessageCallbackARB(onDebugMessage, nullptr);
    glDebugMessageControlARB(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
  } else {
    return false;
  }
  while (glGetError() != GL_NO_ERROR) {
  }
  return true;
}

std::string glErrorName(GLenum error) {
  switch (error) {
    case GL_NO_ERROR: return "GL_NO_ERROR";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
    case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
    default: {
      char buffer[32];
      std::snprintf(buffer, sizeof buffer, "GL error 0x%04x", error);
      return buffer;
    }
  }
}

void detail::checkErrorsNow(const char* where) { checkErrorsAlways(where); }

void checkErrorsAlways(const char* where) {
  std::string codes;
  for (int i = 0; i < 8; ++i) {  // a lost context can report errors forever: stop after a few
    GLenum error = glGetError();
    if (error == GL_NO_ERROR) break;
    if (!codes.empty()) codes += ", ";
    codes += glErrorName(error);
  }
  if (codes.empty() && t_recordedErrors.empty()) return;
  std::string message = std::string("OpenGL error in ") + where + ": " + (codes.empty() ? "debug message" : codes);
  for (const std::string& text : t_recordedErrors) message += "\n  " + text;
  t_recordedErrors.clear();
  throw RuntimeError(message);
}

}  // namespace eik::gl
