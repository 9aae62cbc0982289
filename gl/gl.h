// The one way into OpenGL for Eikonal code: glad's generated 3.3-core loader (built by
// cmake/EikonalGlad.cmake). Every gl* name is a macro over a function pointer that GlContext loads
// from the current context's own getProcAddress, so one binary serves OSMesa, EGL and GLFW
// contexts. Never include <GL/gl.h> or link libGL beside it (docs/architecture.md, "known traps").
#pragma once

#include <glad/gl.h>
