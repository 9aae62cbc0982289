#version 330 core
// The bare refractive march for `viewer --bench` (viewer/bench.h): the cost floor of a curved-ray
// caster over a whole scene. Through each object's box in the order the ray meets them, Euler
// steps of the ray equation (Eq. 5.11/5.12) with ONE texture fetch a step, of a packed RGBA texture
// (∇n in RGB, n in A); straight between boxes; then one hit test of the ground plane. No shading,
// no early termination, no empty-space skipping. Out: RGB the final direction (world, as
// 0.5 + 0.5·d), A the number of steps taken, so the caller can count the samples exactly.
// OBJECTS (1..8, a define) objects; GROUND: the ground plane's hit test.
#include "common/box.glsl"

uniform sampler3D uPacked[OBJECTS];      // (∂n/∂x, ∂n/∂y, ∂n/∂z, n) in each volume's own units
uniform mat4 uInvViewProj;               // clip → world
uniform vec3 uEye;                       // world
uniform mat4 uWorldToVolume[OBJECTS];    // world → each volume's own space
uniform mat4 uVolumeToWorld[OBJECTS];
uniform vec3 uBoundsMin[OBJECTS];
uniform vec3 uBoundsMax[OBJECTS];
uniform float uStep[OBJECTS];            // arc length per step, volume units
uniform int uMaxSteps[OBJECTS];
uniform vec3 uGroundPoint;               // GROUND: the plane (world)
uniform vec3 uGroundNormal;

in vec2 vUv;
out vec4 outColor;

// Steps through one box from x (inside, volume space) along w; returns the steps taken.
int march(sampler3D field, inout vec3 x, inout vec3 w, vec3 bmin, vec3 bmax, float stepLength, int maxSteps) {
  vec3 extent = bmax - bmin;
  int steps = 0;
  for (; steps < maxSteps; ++steps) {
    vec3 uvw = (x - bmin) / extent;
    if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) break;
    vec4 s = texture(field, uvw);          // the one fetch: ∇n and n at x
    w = normalize(w) * s.a;               // |w| = n
    x += stepLength * w / s.a;            // Eq. 5.11
    w += stepLength * s.rgb;              // Eq. 5.12
  }
  return steps;
}

void main() {
  vec4 far = uInvViewProj * vec4(vUv * 2.0 - 1.0, 1.0, 1.0);
  vec3 origin = uEye;
  vec3 dir = normalize(far.xyz / far.w - uEye);  // world
  int steps = 0;
  int visited = 0;
  for (int pass = 0; pass < OBJECTS; ++pass) {
    // The nearest box not yet crossed along the straight ray (origin, dir).
    int best = -1;
    float bestDistance = 1e30;
    vec3 bestEntry = vec3(0.0), bestDir = vec3(0.0);
    for (int i = 0; i < OBJECTS; ++i) {
      if ((visited & (1 << i)) != 0) continue;
      vec3 o = (uWorldToVolume[i] * vec4(origin, 1.0)).xyz;
      vec3 d = normalize(mat3(uWorldToVolume[i]) * dir);
      float tNear, tFar;
      if (!intersectBox(o, d, uBoundsMin[i], uBoundsMax[i], tNear, tFar)) continue;
      vec3 entry = o + d * (max(tNear, 0.0) + 1e-4 * length(uBoundsMax[i] - uBoundsMin[i]));
      float distance = length((uVolumeToWorld[i] * vec4(entry, 1.0)).xyz - origin);
      if (distance < bestDistance) {
        best = i;
        bestDistance = distance;
        bestEntry = entry;
        bestDir = d;
      }
    }
    if (best < 0) break;
    visited |= 1 << best;
    vec3 x = bestEntry, w = bestDir;  // |w| = n after the first step
    // Constant indices into the sampler array (GLSL 3.30).
    if (best == 0) steps += march(uPacked[0], x, w, uBoundsMin[0], uBoundsMax[0], uStep[0], uMaxSteps[0]);
#if OBJECTS > 1
    else if (best == 1) steps += march(uPacked[1], x, w, uBoundsMin[1], uBoundsMax[1], uStep[1], uMaxSteps[1]);
#endif
#if OBJECTS > 2
    else if (best == 2) steps += march(uPacked[2], x, w, uBoundsMin[2], uBoundsMax[2], uStep[2], uMaxSteps[2]);
#endif
#if OBJECTS > 3
    else if (best == 3) steps += march(uPacked[3], x, w, uBoundsMin[3], uBoundsMax[3], uStep[3], uMaxSteps[3]);
#endif
#if OBJECTS > 4
    else if (best == 4) steps += march(uPacked[4], x, w, uBoundsMin[4], uBoundsMax[4], uStep[4], uMaxSteps[4]);
#endif
#if OBJECTS > 5
    else if (best == 5) steps += march(uPacked[5], x, w, uBoundsMin[5], uBoundsMax[5], uStep[5], uMaxSteps[5]);
#endif
#if OBJECTS > 6
    else if (best == 6) steps += march(uPacked[6], x, w, uBoundsMin[6], uBoundsMax[6], uStep[6], uMaxSteps[6]);
#endif
#if OBJECTS > 7
    else if (best == 7) steps += march(uPacked[7], x, w, uBoundsMin[7], uBoundsMax[7], uStep[7], uMaxSteps[7]);
#endif
    origin = (uVolumeToWorld[best] * vec4(x, 1.0)).xyz;
    dir = normalize(mat3(uVolumeToWorld[best]) * w);
  }
#if defined(GROUND)
  // The ground's hit test (the full renderer shades the point it finds).
  float facing = dot(dir, uGroundNormal);
  if (facing < 0.0) {
    float t = dot(uGroundPoint - origin, uGroundNormal) / facing;
    if (t > 0.0) dir = reflect(dir, uGroundNormal);
  }
#endif
  outColor = vec4(0.5 + 0.5 * dir, float(steps));
}
