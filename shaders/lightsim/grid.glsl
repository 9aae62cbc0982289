// The volume grid as the light simulator's shaders see it (lightsim/atlas.h GridUniforms), and the
// field sampling of ALGORITHM.md "Units and inputs": trilinear at voxel centres, clamp to edge,
// uvw = (x − bounds_min) / extent. Needs common/volume.glsl (the volume's layout defines).
uniform vec3 uBoundsMin;
uniform vec3 uBoundsMax;
uniform vec3 uInvExtent;
uniform float uVoxelEdge;    // h, the smallest voxel edge
uniform float uVoxelVolume;  // V_voxel

vec3 gridUvw(vec3 x) { return (x - uBoundsMin) * uInvExtent; }
float sampleIor(vec3 x) { return volumeIor(gridUvw(x)); }
vec3 sampleIorGrad(vec3 x) { return volumeIorGrad(gridUvw(x)); }
vec3 sampleSigmaA(vec3 x) { return volumeSigmaA(gridUvw(x)); }

// Inside the closed box [bounds_min, bounds_max] (wavefront.h insideBox).
bool insideGrid(vec3 x) { return all(greaterThanEqual(x, uBoundsMin)) && all(lessThanEqual(x, uBoundsMax)); }

// Whether the ray x + t·d, t ≥ 0, meets the closed grid box (slab test, as wavefront.h rayHitsBox:
// a zero component misses unless x lies within that slab).
bool rayHitsGrid(vec3 x, vec3 d) {
  float tNear = 0.0, tFar = 3.4e38;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (x[a] < uBoundsMin[a] || x[a] > uBoundsMax[a]) return false;
      continue;
    }
    float t1 = (uBoundsMin[a] - x[a]) / d[a];
    float t2 = (uBoundsMax[a] - x[a]) / d[a];
    tNear = max(tNear, min(t1, t2));
    tFar = min(tFar, max(t1, t2));
  }
  return tNear <= tFar;
}

// Absorption factor of ALGORITHM.md step 2 for a patch whose midpoint was m_old:
// exp(−σa(m)·Δs_m) with Δs_m = Δt / n(m) (Eq. 4.11).
vec3 absorptionFactor(vec3 mOld, float dt) {
  float dsm = dt / sampleIor(mOld);
  return exp(-sampleSigmaA(mOld) * dsm);
}
