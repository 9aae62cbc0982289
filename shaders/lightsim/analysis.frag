#version 330 core
// ALGORITHM.md step 5, analysis (thesis §6.2.4), and everything else a step needs per patch, in one
// full-screen MRT pass over the updated list (fragment work runs on every core; the point passes
// that follow only fetch its results):
//   0 count        0, 1 or 4: the base of the histogram pyramid (step 6)
//   1 deposit A    step 4 at the new midpoint m, in the voxel containing it (inside the grid only):
//   2 deposit B      accumulate: A = (Φ·Δs_m/V_voxel, atlas x), B = (lum(Φ)·Δs_m·d, atlas y)
//                    max:        A = (E = Φ/A, atlas x),         B = (d, atlas y)
//                    atlas x = −1: no deposit. Δs_m = Δt/n(m_old) (Eq. 4.11).
//   3 ledger A     (flux absorbed in step 2, fate code of lightsim/fate.glsl)
//   4 ledger B     (flux reflected in step 3, 1 when the patch left a boundary layer)
// Slots at or beyond uCount get count 0 and FATE_NONE.
#include "common/volume.glsl"
#include "lightsim/grid.glsl"
#include "lightsim/patch.glsl"
#include "lightsim/fate.glsl"
#include "lightsim/atlas.glsl"

uniform sampler2D uPatch[8];      // the list after the update
uniform sampler2D uPrevious[4];   // P0..P3 before the update
uniform sampler2D uPreviousFlux;  // FLUX before the update
uniform int uCount;
uniform float uDt;                // Δt

layout(location = 0) out vec4 oCount;
layout(location = 1) out vec4 oDepositA;
layout(location = 2) out vec4 oDepositB;
layout(location = 3) out vec4 oLedgerA;
layout(location = 4) out vec4 oLedgerB;

void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy);
  if (mortonIndex(texel) >= uCount) {
    oCount = vec4(0.0);
    oDepositA = vec4(0.0, 0.0, 0.0, -1.0);
    oDepositB = vec4(0.0);
    oLedgerA = vec4(0.0, 0.0, 0.0, float(FATE_NONE));
    oLedgerB = vec4(0.0);
    return;
  }
  Patch p;
  FETCH_PATCH(uPatch, texel, p);
  vec3 o0, o1, o2, o3;
  FETCH_CORNERS(uPrevious, texel, o0, o1, o2, o3);
  vec3 mOld = 0.25 * (o0 + o1 + o2 + o3);
  vec3 fluxOld = texelFetch(uPreviousFlux, texel, 0).rgb;

  // Step 5.
  int fate = patchFate(p);
  oCount = vec4(fateCount(fate), 0.0, 0.0, 0.0);

  // The ledger: step 2's factor recomputed exactly as update.frag did (same inputs, same code),
  // and step 3's reflection from it and T_fresnel.
  vec3 a = absorptionFactor(mOld, uDt);
  oLedgerA = vec4(fluxOld * (1.0 - a), float(fate));
  oLedgerB = p.tFresnel < 1.0 ? vec4(fluxOld * a * (1.0 - p.tFresnel), 1.0) : vec4(0.0);

  // Step 4: the voxel containing m, floor of the continuous voxel coordinate, inside [0, dims).
  vec3 m = patchMidpoint(p);
  vec3 c = floor((m - uBoundsMin) * uInvExtent * vec3(ATLAS_DIMS));
  if (!(all(greaterThanEqual(c, vec3(0.0))) && all(lessThan(c, vec3(ATLAS_DIMS))))) {
    oDepositA = vec4(0.0, 0.0, 0.0, -1.0);
    oDepositB = vec4(0.0);
    return;
  }
  vec2 at = vec2(atlasTexel(ivec3(c)));
  vec3 d = patchDirection(p);
#ifdef DEPOSIT_MAX
  float area = length(patchAreaVector(p));
  vec3 e = area > 0.0 ? p.flux / area : vec3(0.0);  // Eq. 4.16: E = Φ / A
  oDepositA = vec4(e, at.x);
  oDepositB = vec4(d, at.y);
#else
  float dsm = uDt / sampleIor(mOld);  // Δs_m, Eq. 4.11
  oDepositA = vec4(p.flux * (dsm / uVoxelVolume), at.x);
  oDepositB = vec4(lum(p.flux) * dsm * d, at.y);
#endif
}
