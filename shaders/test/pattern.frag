#version 330 core
// Test pattern (gl/ tests): a gradient over the viewport plus a checkerboard, so readback can be
// checked pixel by pixel. MODE 1: gradient only; MODE 2: gradient + checker in blue.
// SECOND_TARGET: also write the checker alone to colour attachment 1 (MRT).
#include "test/checker.glsl"
#include "common/constants.glsl"

#ifndef MODE
#define MODE 2
#endif
#ifndef CHECKER_CELL
#define CHECKER_CELL 8.0
#endif

uniform vec2 uSize;
in vec2 vUv;
layout(location = 0) out vec4 outColor;
#ifdef SECOND_TARGET
layout(location = 1) out vec4 outSecond;
#endif

void main() {
  vec2 p = gl_FragCoord.xy;
  float c = checker(p, CHECKER_CELL);
#if MODE == 1
  outColor = vec4(p.x / uSize.x, p.y / uSize.y, 0.25, 1.0);
#elif MODE == 2
  outColor = vec4(p.x / uSize.x, p.y / uSize.y, 0.25 + 0.5 * c, 1.0);
#else
#error "MODE must be 1 or 2"
#endif
#ifdef SECOND_TARGET
  outSecond = vec4(c, 1.0 - c, PI, -1.0);
#endif
}
