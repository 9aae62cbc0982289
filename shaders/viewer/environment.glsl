// The environment seen where a viewing ray leaves every volume and in reflections (thesis Eq. 5.10,
// the L(x_e) term); viewer/environment.h describes the kinds. One variant per kind (#define
// ENV_UNIFORM / ENV_MAP / ENV_SKY / ENV_CHECKER); the CPU twin is eik::Environment::radiance.
// Needs common/constants.glsl.

uniform vec3 uEnvColor;        // uniform: its radiance; checker: the bright cells (× intensity)
uniform float uEnvIntensity;
uniform vec2 uEnvRotation;     // cos, sin of rotate_deg (about +y)
uniform vec3 uEnvSunDir;       // sky: unit direction towards the sun
uniform float uEnvSunCos;      // sky: cos of the sun disk's angular radius
uniform vec3 uEnvSunRadiance;  // sky: radiance of the sun disk (its irradiance / solid angle), before intensity
#ifdef ENV_MAP
uniform sampler2D uEnvMap;     // equirectangular, rows top (+y) to bottom, mipmapped
uniform vec2 uEnvMapSize;
uniform float uEnvMaxLod;
#endif

// Turns the environment by rotate_deg about +y: the lookup direction is turned back.
vec3 envRotate(vec3 d) {
  return vec3(uEnvRotation.x * d.x + uEnvRotation.y * d.z, d.y, -uEnvRotation.y * d.x + uEnvRotation.x * d.z);
}

// The mip level for a ray whose direction changes by `spread` radians across a pixel.
float envLod(float spread) {
#ifdef ENV_MAP
  return clamp(log2(max(spread * uEnvMapSize.y / PI, 1e-6)), 0.0, uEnvMaxLod);
#else
  return 0.0;
#endif
}

// Radiance arriving along -d (d: the viewing ray's direction, unit, world), at mip level `lod`.
vec3 environmentRadiance(vec3 d, float lod) {
  vec3 r = envRotate(d);
#if defined(ENV_MAP)
  vec2 uv = vec2(0.5 + atan(r.x, -r.z) / TWO_PI, acos(clamp(r.y, -1.0, 1.0)) / PI);
  return textureLod(uEnvMap, uv, lod).rgb * uEnvIntensity;
#elif defined(ENV_CHECKER)
  float u = atan(r.z, r.x) / TWO_PI + 0.5;
  float v = acos(clamp(r.y, -1.0, 1.0)) / PI;
  float c = mod(floor(u * 24.0) + floor(v * 12.0), 2.0);
  return uEnvColor * (0.2 + 0.8 * c);
#elif defined(ENV_SKY)
  // An analytic daylight sky: horizon to zenith blue, a glow around the sun, the sun disk itself
  // (delivering the scene's directional light), a dim ground below the horizon.
  vec3 sky = mix(vec3(0.75, 0.85, 1.0), vec3(0.18, 0.33, 0.75), pow(clamp(r.y, 0.0, 1.0), 0.45));
  float mu = dot(r, uEnvSunDir);
  sky += vec3(1.0, 0.85, 0.6) * 0.6 * pow(max(mu, 0.0), 8.0);
  vec3 below = vec3(0.22, 0.2, 0.18) * (0.5 + 0.5 * clamp(uEnvSunDir.y, 0.0, 1.0));
  vec3 c = mix(below, sky, smoothstep(-0.02, 0.02, r.y));
  if (mu > uEnvSunCos && r.y > 0.0) c += uEnvSunRadiance;
  return c * uEnvIntensity;
#else
  return uEnvColor;
#endif
}
