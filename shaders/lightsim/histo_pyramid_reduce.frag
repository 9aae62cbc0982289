#version 330 core
// One level of the histogram pyramid (lightsim/histo_pyramid.h). Each fragment is a node t of
// level m + 1 (a texel of RGBA mip m) and writes the values of its four children at level m, in
// child order (.x (0,0), .y (1,0), .z (0,1), .w (1,1)):
//   HP_FIRST  level 0: the .r of the counts texture (any float texture of the base size);
//   else      level m ≥ 1: the sum of the four components of mip m − 1's texel. The pyramid texture
//             is bound with GL_TEXTURE_BASE_LEVEL = GL_TEXTURE_MAX_LEVEL = m − 1, so level 0 of the
//             sampler is m − 1 and the mip being written lies outside the sampled range (no
//             feedback loop).
// Children whose slot at level m is ≥ uHpSourceLive are 0, whatever the source holds there (stale
// data from an earlier, longer list, or never-written texels, NaN included, are ignored).
#include "lightsim/histo_pyramid.glsl"

uniform sampler2D uHpSource;
uniform int uHpSourceLive;

layout(location = 0) out vec4 oChildren;

#ifdef HP_FIRST
float hpChild(ivec2 c) {
  // Clamped: a 1×1 base has no texel (1, 0) etc. (HP_BASE_SIZE is a constant: free elsewhere.)
  return texelFetch(uHpSource, min(c, ivec2(HP_BASE_SIZE - 1)), 0).r;
}
#else
float hpChild(ivec2 c) {
  vec4 v = texelFetch(uHpSource, c, 0);
  return (v.x + v.y) + (v.z + v.w);
}
#endif

void main() {
  ivec2 t = ivec2(gl_FragCoord.xy);
  ivec2 c = 2 * t;
  vec4 children = vec4(hpChild(c), hpChild(c + ivec2(1, 0)), hpChild(c + ivec2(0, 1)), hpChild(c + ivec2(1, 1)));
  ivec4 slots = ivec4(4 * hpTexelSlot(t)) + ivec4(0, 1, 2, 3);
  // mix with a bvec selects: no 0·NaN.
  oChildren = mix(vec4(0.0), children, lessThan(slots, ivec4(uHpSourceLive)));
}
