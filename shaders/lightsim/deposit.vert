#version 330 core
// ALGORITHM.md step 4, deposit (atlas voxelisation, thesis §6.2.3): one GL_POINTS primitive per
// live patch (gl_VertexID = patch index). The point lands on the atlas texel of the voxel holding
// the new midpoint m, and only while m lies inside the grid.
//   DEPOSIT_ACCUMULATE: irradiance += Φ·Δs_m / V_voxel; direction sum += lum(Φ)·Δs_m·d
//   DEPOSIT_MAX:        E = Φ / A and d of the patch with the largest lum(E) (depth test)
// Δs_m = Δt / n(m_old) (Eq. 4.11) with m_old the midpoint before the update (list uPrevious).
#include "common/volume.glsl"
#include "lightsim/grid.glsl"
#include "lightsim/patch.glsl"
#include "lightsim/atlas.glsl"

uniform sampler2D uPatch[8];     // the list after the update
uniform sampler2D uPrevious[8];  // the list before it (P0..P3 are read)
uniform float uDt;               // Δt
uniform float uEnergyRef;        // E_ref of the max-mode depth mapping

out vec4 vEnergy;     // accumulate: (Φ·Δs_m/V, 0);  max: (E, lum(E))
out vec4 vDirection;  // accumulate: (lum(Φ)·Δs_m·d, 1);  max: (d, 1)
out float vDepth;     // max: ½ / (1 + lum(E)/E_ref), smaller wins

void main() {
  ivec2 texel = mortonTexel(gl_VertexID);
  Patch p;
  FETCH_PATCH(uPatch, texel, p);
  vec3 m = patchMidpoint(p);
  vEnergy = vec4(0.0);
  vDirection = vec4(0.0);
  vDepth = 1.0;
  // The voxel containing m: floor of the continuous voxel coordinate, inside [0, dims) only.
  vec3 c = floor((m - uBoundsMin) * uInvExtent * vec3(ATLAS_DIMS));
  if (!(all(greaterThanEqual(c, vec3(0.0))) && all(lessThan(c, vec3(ATLAS_DIMS))))) {
    gl_Position = kCulledPoint;
    return;
  }
  ivec3 voxel = ivec3(c);
  gl_Position = atlasPointPosition(atlasTexel(voxel));
  vec3 d = patchDirection(p);
#ifdef DEPOSIT_ACCUMULATE
  vec3 o0, o1, o2, o3;
  FETCH_CORNERS(uPrevious, texel, o0, o1, o2, o3);
  float dsm = uDt / sampleIor(0.25 * (o0 + o1 + o2 + o3));  // Δs_m, Eq. 4.11
  vEnergy = vec4(p.flux * (dsm / uVoxelVolume), 0.0);
  vDirection = vec4(lum(p.flux) * dsm * d, 1.0);
#else
  float area = length(patchAreaVector(p));
  vec3 e = p.flux / max(area, 1e-30);  // Eq. 4.16: E = Φ / A
  vEnergy = vec4(e, lum(e));
  vDirection = vec4(d, 1.0);
  vDepth = 0.5 / (1.0 + lum(e) / uEnergyRef);  // < 1 (the clear value) even for E = 0
#endif
}
