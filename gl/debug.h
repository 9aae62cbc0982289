// OpenGL error checking. On in debug builds (no NDEBUG) or with EIKONAL_GL_DEBUG=1 in any build
// (EIKONAL_GL_DEBUG=0 turns it off in a debug build). When on, GlContext installs a KHR_debug (or
// ARB_debug_output) message callback where the context offers one, and every wrapper in gl/ calls
// checkErrors() after its GL calls: glGetError plus the messages the callback recorded, turned into
// a RuntimeError naming the wrapper. When off, checkErrors() costs one branch.
#pragma once

#include <string>

#include "gl/gl.h"

namespace eik::gl {

// EIKONAL_GL_DEBUG=1 → true, =0 → false, unset → true in debug builds, false with NDEBUG.
// EIKONAL_GL_DEBUG=2 also prints every debug message (performance notes included) on stderr.
bool debugRequestedByEnvironment();

// Whether checkErrors() checks (set per context by GlContext::makeCurrent()).
bool errorChecksEnabled();
void setErrorChecksEnabled(bool enabled);

// Installs the debug message callback in the current context (KHR_debug, else ARB_debug_output).
// Errors are recorded for the next checkErrors(); high-severity messages are printed on stderr.
// Returns false when the context offers neither extension (glGetError alone is used then).
bool installDebugCallback();

// GL_INVALID_ENUM → "GL_INVALID_ENUM", unknown codes as hex.
std::string glErrorName(GLenum error);

namespace detail {
void checkErrorsNow(const char* where);
extern thread_local bool g_errorChecks;
}  // namespace detail

// Throws RuntimeError("OpenGL error in WHERE: GL_INVALID_VALUE (message...)") when checks are on
// and GL reported an error since the last check.
inline void checkErrors(const char* where) {
  if (detail::g_errorChecks) detail::checkErrorsNow(where);
}

// Same, whether checks are on or not (for rare calls that can fail for reasons other than bugs,
// e.g. GL_OUT_OF_MEMORY after allocating a large texture).
void checkErrorsAlways(const char* where);

}  // namespace eik::gl
