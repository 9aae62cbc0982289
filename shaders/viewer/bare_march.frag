#version 330 core
// The bare refractive march for `viewer --bench` (viewer/bench.h): the cost floor of a curved-ray
// caster. Euler steps of the ray equation (Eq. 5.11/5.12) with ONE texture fetch a step, of a
// packed RGBA texture (∇n in RGB, n in A), no shading, no early termination, no empty-space
// skipping. Out: RGB the exit direction (world, as 0.5 + 0.5·d), A the number of steps taken, so
// the caller can count the samples exactly.
#include "common/box.glsl"

uniform sampler3D uPacked;      // (∂n/∂x, ∂n/∂y, ∂n/∂z, n) in the volume's own units
uniform mat4 uInvViewProj;      // clip → world
uniform vec3 uEye;              // world
uniform mat4 uWorldToVolume;    // world → the volume's own space
uniform mat3 uVolumeToWorldDir;
uniform vec3 uBoundsMin;
uniform vec3 uBoundsMax;
uniform float uStep;            // arc length per step, volume units
uniform int uMaxSteps;

in vec2 vUv;
out vec4 outColor;

void main() {
  vec4 far = uInvViewProj * vec4(vUv * 2.0 - 1.0, 1.0, 1.0);
  vec3 dirWorld = normalize(far.xyz / far.w - uEye);
  vec3 o = (uWorldToVolume * vec4(uEye, 1.0)).xyz;
  vec3 d = normalize(mat3(uWorldToVolume) * dirWorld);

  float tNear, tFar;
  int steps = 0;
  if (intersectBox(o, d, uBoundsMin, uBoundsMax, tNear, tFar)) {
    vec3 extent = uBoundsMax - uBoundsMin;
    vec3 x = o + d * (max(tNear, 0.0) + 1e-4 * length(extent));
    vec3 w = d;  // |w| = n after the first step
    for (; steps < uMaxSteps; ++steps) {
      vec3 uvw = (x - uBoundsMin) / extent;
      if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) break;
      vec4 s = texture(uPacked, uvw);      // the one fetch: ∇n and n at x
      w = normalize(w) * s.a;              // |w| = n
      x += uStep * w / s.a;                // Eq. 5.11
      w += uStep * s.rgb;                  // Eq. 5.12
    }
    d = normalize(w);
  }
  outColor = vec4(0.5 + 0.5 * normalize(uVolumeToWorldDir * d), float(steps));
}
