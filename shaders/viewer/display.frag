#version 330 core
// The display pass (viewer/display_pass.h): linear HDR radiance → exposure → tone map → sRGB, the
// same formulas as core/tonemap.cpp (toDisplay), so the window shows what a headless PNG holds.
//   TONEMAP 0 linear, 1 Reinhard (x / (1 + x)), 2 ACES fit (Narkowicz 2015, clamped to [0, 1]).
uniform sampler2D uHdr;       // RGBA32F, rows bottom to top (GL order)
uniform float uExposureScale; // 2^exposure_ev
uniform int uToneMapper;
uniform ivec2 uViewportSize;  // the viewport being drawn (pixels); the image is stretched over it

out vec4 outColor;

vec3 toneMapAces(vec3 x) {
  const float a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
  return clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0);
}

float linearToSrgb(float v) {
  v = clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

void main() {
  // Nearest texel: one to one when the image has the viewport's size (the usual case).
  ivec2 texSize = textureSize(uHdr, 0);
  ivec2 texel = ivec2(floor(gl_FragCoord.xy * vec2(texSize) / vec2(uViewportSize)));
  texel = clamp(texel, ivec2(0), texSize - 1);
  vec3 x = max(texelFetch(uHdr, texel, 0).rgb, vec3(0.0)) * uExposureScale;
  if (uToneMapper == 1) x = x / (1.0 + x);
  else if (uToneMapper == 2) x = toneMapAces(x);
  outColor = vec4(linearToSrgb(x.r), linearToSrgb(x.g), linearToSrgb(x.b), 1.0);
}
