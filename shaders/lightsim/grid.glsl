// The volume grid as the light simulator's shaders see it (lightsim/grid_uniforms.h GridUniforms), and the
// field sampling of ALGORITHM.md "Units and inputs": trilinear at voxel centres, clamp to edge,
// uvw = (x − bounds_min) / extent. Needs common/volume.glsl (the volume's layout defines).
uniform vec3 uBoundsMin;
uniform vec3 uBoundsMax;
uniform vec3 uInvExtent;
uniform float uVoxelEdge;    // h, the smallest voxel edge
uniform float uVoxelVolume;  // V_voxel
uniform ivec3 uDims;         // voxels per axis

vec3 gridUvw(vec3 x) { return (x - uBoundsMin) * uInvExtent; }

#ifdef EXACT_TRILINEAR
// GL_LINEAR + GL_CLAMP_TO_EDGE filtering done by hand with texelFetch and float weights, in the
// order of the CPU twin's sampler (wavefront.cpp interpolate): hardware filtering quantises the
// weights (to 1/256 on NVIDIA GPUs), this agrees with the CPU to float rounding. 8 fetches a lookup.
vec4 exactTrilinear(sampler3D s, vec3 uvw) {
  vec3 top = vec3(uDims - 1);
  vec3 c = clamp(uvw * vec3(uDims) - 0.5, vec3(0.0), top);
  ivec3 i0 = min(ivec3(floor(c)), uDims - 1);
  ivec3 i1 = min(i0 + 1, uDims - 1);
  vec3 f = c - vec3(i0), g = 1.0 - f;
  vec4 c00 = texelFetch(s, ivec3(i0.x, i0.y, i0.z), 0) * g.x + texelFetch(s, ivec3(i1.x, i0.y, i0.z), 0) * f.x;
  vec4 c10 = texelFetch(s, ivec3(i0.x, i1.y, i0.z), 0) * g.x + texelFetch(s, ivec3(i1.x, i1.y, i0.z), 0) * f.x;
  vec4 c01 = texelFetch(s, ivec3(i0.x, i0.y, i1.z), 0) * g.x + texelFetch(s, ivec3(i1.x, i0.y, i1.z), 0) * f.x;
  vec4 c11 = texelFetch(s, ivec3(i0.x, i1.y, i1.z), 0) * g.x + texelFetch(s, ivec3(i1.x, i1.y, i1.z), 0) * f.x;
  return (c00 * g.y + c10 * f.y) * g.z + (c01 * g.y + c11 * f.y) * f.z;
}
#ifdef HAS_IOR
float sampleIor(vec3 x) { return exactTrilinear(IOR_SAMPLER, gridUvw(x)).IOR_SWZ; }
#else
float sampleIor(vec3 x) { return 1.0; }
#endif
#ifdef HAS_IOR_GRAD
vec3 sampleIorGrad(vec3 x) { return exactTrilinear(IOR_GRAD_SAMPLER, gridUvw(x)).IOR_GRAD_SWZ; }
#else
vec3 sampleIorGrad(vec3 x) { return vec3(0.0); }
#endif
#ifdef HAS_SIGMA_A
vec3 sampleSigmaA(vec3 x) { return exactTrilinear(SIGMA_A_SAMPLER, gridUvw(x)).SIGMA_A_SWZ; }
#else
vec3 sampleSigmaA(vec3 x) { return vec3(0.0); }
#endif
#else
// The texture units' own trilinear filtering (common/volume.glsl).
float sampleIor(vec3 x) { return volumeIor(gridUvw(x)); }
vec3 sampleIorGrad(vec3 x) { return volumeIorGrad(gridUvw(x)); }
vec3 sampleSigmaA(vec3 x) { return volumeSigmaA(gridUvw(x)); }
#endif

// Inside the closed box [lo, hi] (wavefront.h insideBox).
bool insideBox(vec3 x, vec3 lo, vec3 hi) { return all(greaterThanEqual(x, lo)) && all(lessThanEqual(x, hi)); }
// Whether the ray x + t·d, t ≥ 0, meets the closed box [lo, hi] (slab test, as wavefront.h
// rayHitsBox: a zero component misses unless x lies within that slab).
bool rayHitsBox(vec3 x, vec3 d, vec3 lo, vec3 hi) {
  float tNear = 0.0, tFar = 3.4e38;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (x[a] < lo[a] || x[a] > hi[a]) return false;
      continue;
    }
    float t1 = (lo[a] - x[a]) / d[a];
    float t2 = (hi[a] - x[a]) / d[a];
    tNear = max(tNear, min(t1, t2));
    tFar = min(tFar, max(t1, t2));
  }
  return tNear <= tFar;
}
bool insideGrid(vec3 x) { return insideBox(x, uBoundsMin, uBoundsMax); }
bool rayHitsGrid(vec3 x, vec3 d) { return rayHitsBox(x, d, uBoundsMin, uBoundsMax); }

// Absorption factor of ALGORITHM.md step 2 for a patch whose midpoint was m_old:
// exp(−σa(m)·Δs_m) with Δs_m = Δt / n(m) (Eq. 4.11).
vec3 absorptionFactor(vec3 mOld, float dt) {
  float dsm = dt / sampleIor(mOld);
  return exp(-sampleSigmaA(mOld) * dsm);
}
