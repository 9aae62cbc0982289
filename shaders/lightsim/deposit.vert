#version 330 core
// ALGORITHM.md step 4, deposit (atlas voxelisation, thesis §6.2.3): one GL_POINTS primitive per
// live patch (gl_VertexID = patch index), landing on the atlas texel the analysis pass chose (the
// voxel of the new midpoint; atlas x < 0: outside the grid, culled) with what it computed:
//   DEPOSIT_ACCUMULATE: (Φ·Δs_m/V_voxel, 0) and (lum(Φ)·Δs_m·d, 1), summed by additive blending;
//   DEPOSIT_MAX:        (E, lum(E)) and (d, 1) of the patch with the smallest depth
//                       ½ / (1 + lum(E)/E_ref), i.e. the largest lum(E) (depth test GL_LESS).
#include "lightsim/patch.glsl"
#include "lightsim/atlas.glsl"

uniform sampler2D uDepositA;  // (value, atlas x)
uniform sampler2D uDepositB;  // (direction, atlas y)
uniform float uEnergyRef;     // E_ref of the max-mode depth mapping

out vec4 vEnergy;
out vec4 vDirection;
out float vDepth;

void main() {
  ivec2 texel = mortonTexel(gl_VertexID);
  vec4 a = texelFetch(uDepositA, texel, 0);
  vec4 b = texelFetch(uDepositB, texel, 0);
  vDirection = vec4(b.xyz, 1.0);
  vDepth = 1.0;
#ifdef DEPOSIT_MAX
  vEnergy = vec4(a.rgb, lum(a.rgb));
  vDepth = 0.5 / (1.0 + lum(a.rgb) / uEnergyRef);  // < 1 (the clear value) even for E = 0
#else
  vEnergy = vec4(a.rgb, 0.0);
#endif
  gl_Position = a.w < 0.0 ? kCulledPoint : atlasPointPosition(ivec2(int(a.w), int(b.w)));
}
