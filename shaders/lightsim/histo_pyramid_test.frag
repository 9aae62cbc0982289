#version 330 core
// Test pass of lightsim/histo_pyramid_test.cpp: for every output slot k (Morton texel) below the
// total, writes (source texel x, y, sub-index j, 1) found by hpFind; (−1, −1, −1, −1) beyond it.
// HP_TEST_TOTAL_FROM_TEXTURE: take the total from the pyramid's top (hpTotal) instead of uTotal.
#include "lightsim/histo_pyramid.glsl"

uniform sampler2D uPyramid;
uniform int uTotal;

layout(location = 0) out vec4 oEntry;

void main() {
  int k = hpTexelSlot(ivec2(gl_FragCoord.xy));
#ifdef HP_TEST_TOTAL_FROM_TEXTURE
  int total = hpTotal(uPyramid);
#else
  int total = uTotal;
#endif
  if (k >= total) {
    oEntry = vec4(-1.0);
    return;
  }
  int j;
  ivec2 source = hpFind(uPyramid, k, j);
  oEntry = vec4(vec2(source), float(j), 1.0);
}
