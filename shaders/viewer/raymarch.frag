#version 330 core
// Curved viewing rays through one refractive volume (thesis §5, §6.3) — the first, minimal form of
// the viewer's ray caster: Euler steps of the ray equation in arc length (Eq. 5.11/5.12) with |w|
// renormalised to n, Beer–Lambert attenuation per channel, emission, opaque embeddings, and the
// environment in the exit direction. Fresnel, scattering and dispersion come with the viewer issue.
//
// Defines: the volume layout (gl::VolumeTextureLayout::glslDefines), ENV_CHECKER for a
// checkerboard environment (latitude/longitude cells) instead of a uniform one.
#include "common/constants.glsl"
#include "common/volume.glsl"

uniform mat4 uInvViewProj;      // clip → world
uniform vec3 uEye;              // world
uniform mat4 uWorldToVolume;    // world → the volume's own space (thesis §6.3.1: x' = M⁻¹x)
uniform mat3 uVolumeToWorldDir; // directions back to world, for the environment lookup
uniform vec3 uBoundsMin;        // the volume's box in its own space
uniform vec3 uBoundsMax;
uniform float uStep;            // arc length per step, volume units
uniform int uMaxSteps;
uniform vec3 uEnvColor;

in vec2 vUv;
out vec4 outColor;

vec3 environment(vec3 d) {
#ifdef ENV_CHECKER
  float u = atan(d.z, d.x) / TWO_PI + 0.5;
  float v = acos(clamp(d.y, -1.0, 1.0)) / PI;
  float c = mod(floor(u * 24.0) + floor(v * 12.0), 2.0);
  return uEnvColor * (0.2 + 0.8 * c);
#else
  return uEnvColor;
#endif
}

// Slab test; false when the ray misses the box or it lies behind the origin.
bool intersectBox(vec3 o, vec3 d, out float tNear, out float tFar) {
  vec3 inv = 1.0 / d;
  vec3 t0 = (uBoundsMin - o) * inv;
  vec3 t1 = (uBoundsMax - o) * inv;
  vec3 lo = min(t0, t1);
  vec3 hi = max(t0, t1);
  tNear = max(max(lo.x, lo.y), lo.z);
  tFar = min(min(hi.x, hi.y), hi.z);
  return tFar > max(tNear, 0.0);
}

void main() {
  vec4 far = uInvViewProj * vec4(vUv * 2.0 - 1.0, 1.0, 1.0);
  vec3 dirWorld = normalize(far.xyz / far.w - uEye);
  vec3 o = (uWorldToVolume * vec4(uEye, 1.0)).xyz;
  vec3 d = normalize(mat3(uWorldToVolume) * dirWorld);

  vec3 radiance = vec3(0.0);
  vec3 transmittance = vec3(1.0);
  float tNear, tFar;
  if (intersectBox(o, d, tNear, tFar)) {
    vec3 extent = uBoundsMax - uBoundsMin;
    // Start a hair inside the box: exactly on its face, rounding would put some rays outside and
    // end their march before it began (speckles of unrefracted rays).
    vec3 x = o + d * (max(tNear, 0.0) + 1e-4 * length(extent));
    float n = volumeIor((x - uBoundsMin) / extent);
    vec3 w = d * n;  // |w| = n along an exact ray
    for (int i = 0; i < uMaxSteps; ++i) {
      vec3 uvw = (x - uBoundsMin) / extent;
      if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) break;
      vec4 opaque = volumeOpaque(uvw);
      if (opaque.a > 0.5) {
        radiance += transmittance * opaque.rgb * uEnvColor;
        transmittance = vec3(0.0);
        break;
      }
      transmittance *= exp(-volumeSigmaA(uvw) * uStep);   // Beer–Lambert
      radiance += transmittance * volumeEmission(uvw) * uStep;
      vec3 gradN = volumeIorGrad(uvw);
      x += uStep * w / n;                                   // Eq. 5.11: dx/ds = w / n
      w += uStep * gradN;                                   // Eq. 5.12: dw/ds = ∇n
      n = volumeIor((x - uBoundsMin) / extent);
      w = normalize(w) * n;                                 // keep |w| = n (DESIGN §5)
      if (max(max(transmittance.r, transmittance.g), transmittance.b) < 1e-4) break;
    }
    d = normalize(w);
  }
  radiance += transmittance * environment(normalize(uVolumeToWorldDir * d));
  outColor = vec4(radiance, 1.0);
}
