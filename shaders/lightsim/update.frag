#version 330 core
// ALGORITHM.md steps 1–3 for one patch (one texel of the list; the viewport covers the live
// patches' Morton box, patches ≥ uCount are skipped). Reads the list uPatch, writes the new state
// to the eight MRT attachments of the other list.
//   1. Update (thesis §6.2.2): per corner, the time-parameterised ray equation (Eq. 4.12/4.13)
//      x' = w/n², w' = ∇n/n, stepped with Euler (Eq. 6.1/6.2), RK2 (midpoint) or RK4
//      (INTEGRATOR_EULER / _RK2 / _RK4), then w renormalised to n at the new position.
//   2. Absorption: Φ ← Φ·exp(−σa(m_old)·Δs_m), Δs_m = Δt / n(m_old) (Eq. 4.11).
//   3. Fresnel boundary tracking (docs/physics.md): enter a layer when |∇n(m_new)|·h > g_on, leave it
//      when < g_off and keep the transmitted fraction 1 − R (boundaryReflectance, fresnel.glsl).
#include "common/volume.glsl"
#include "lightsim/grid.glsl"
#include "lightsim/patch.glsl"
#include "lightsim/fresnel.glsl"

uniform sampler2D uPatch[8];
uniform int uCount;            // live patches
uniform float uDt;             // Δt = step_voxels·h
uniform float uBoundaryOn;     // g_on  (|∇n|·h entering a layer)
uniform float uBoundaryOff;    // g_off (|∇n|·h leaving it)

layout(location = 0) out vec4 oP0;
layout(location = 1) out vec4 oP1;
layout(location = 2) out vec4 oP2;
layout(location = 3) out vec4 oP3;
layout(location = 4) out vec4 oW01;
layout(location = 5) out vec4 oW23;
layout(location = 6) out vec4 oFlux;
layout(location = 7) out vec4 oMeta;

// Right-hand side of Eq. 4.12/4.13: dx/dt = w/n², dw/dt = ∇n/n.
void rayRhs(vec3 x, vec3 w, out vec3 dx, out vec3 dw) {
  float n = sampleIor(x);
  dx = w / (n * n);
  dw = sampleIorGrad(x) / n;
}

// Step 1 for one corner.
void stepCorner(inout vec3 x, inout vec3 w) {
  vec3 k1x, k1w;
  rayRhs(x, w, k1x, k1w);
#if defined(INTEGRATOR_RK4)
  vec3 k2x, k2w, k3x, k3w, k4x, k4w;
  rayRhs(x + 0.5 * uDt * k1x, w + 0.5 * uDt * k1w, k2x, k2w);
  rayRhs(x + 0.5 * uDt * k2x, w + 0.5 * uDt * k2w, k3x, k3w);
  rayRhs(x + uDt * k3x, w + uDt * k3w, k4x, k4w);
  vec3 xn = x + (uDt / 6.0) * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
  vec3 wn = w + (uDt / 6.0) * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
#elif defined(INTEGRATOR_RK2)
  vec3 k2x, k2w;
  rayRhs(x + 0.5 * uDt * k1x, w + 0.5 * uDt * k1w, k2x, k2w);  // midpoint
  vec3 xn = x + uDt * k2x;
  vec3 wn = w + uDt * k2w;
#else
  vec3 xn = x + uDt * k1x;  // Eq. 6.1: x ← x + Δt·w/n²
  vec3 wn = w + uDt * k1w;  // Eq. 6.2: w ← w + Δt·∇n/n
#endif
  x = xn;
  w = normalize(wn) * sampleIor(xn);  // |w| = n(x_new)
}

void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy);
  if (mortonIndex(texel) >= uCount) discard;
  Patch p;
  FETCH_PATCH(uPatch, texel, p);

  vec3 mOld = patchMidpoint(p);
  vec3 dOld = patchDirection(p);

  // Step 1: Eq. 6.1/6.2 (or RK2/RK4) per corner.
  for (int c = 0; c < 4; ++c) stepCorner(p.x[c], p.w[c]);

  // Step 2: absorption at the old midpoint.
  p.flux *= absorptionFactor(mOld, uDt);

  // Step 3: Fresnel boundary tracking.
  vec3 mNew = patchMidpoint(p);
  vec3 grad = sampleIorGrad(mNew);
  float g = length(grad) * uVoxelEdge;  // index change per voxel
  p.tFresnel = 1.0;
  if (p.nIn == 0.0) {
    if (g > uBoundaryOn) {
      p.nIn = sampleIor(mOld);
      p.cosIn = abs(dot(dOld, grad / length(grad)));
    }
  } else if (g < uBoundaryOff) {
    float gradLength = length(grad);
    float cosOut = gradLength > 0.0 ? abs(dot(patchDirection(p), grad / gradLength)) : -1.0;
    float r = boundaryReflectance(p.nIn, p.cosIn, sampleIor(mNew), cosOut, uBoundaryOff);
    p.flux *= 1.0 - r;
    p.tFresnel = 1.0 - r;
    p.nIn = 0.0;
  }

  vec4 t[8];
  packPatch(p, t);
  oP0 = t[0]; oP1 = t[1]; oP2 = t[2]; oP3 = t[3];
  oW01 = t[4]; oW23 = t[5]; oFlux = t[6]; oMeta = t[7];
}
