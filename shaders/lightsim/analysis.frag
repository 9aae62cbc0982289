#version 330 core
// ALGORITHM.md step 5, analysis (thesis §6.2.4), and everything else a step needs per patch, in one
// full-screen MRT pass over the updated list (fragment work runs on every core; the point passes
// that follow only fetch its results):
//   0 count        slots of the new list: 0, 1, 2 or 4, + 1 for a followed reflection (the base
//                  of the histogram pyramid, step 6)
//   1 deposit A    step 4. DEPOSIT_TRACK (track-length deposits, track_deposit_pass.h):
//   2 deposit B      A = (Φ along the step = ½ (Φ_old + Φ_new), flag: < 0 none, 0 deposit,
//                    1 deposit and clip at the receiver plane), B = (Φ received, 1 when received);
//                  otherwise at the new midpoint m, in the voxel containing it (inside the grid):
//                    accumulate: A = (Φ·Δs_m/V_voxel, atlas x), B = (lum(Φ)·Δs_m·d, atlas y)
//                    max:        A = (E = Φ/A, atlas x),         B = (d, atlas y)
//                    atlas x = −1: no deposit. Δs_m = Δt/n(m_old) (Eq. 4.11).
//   3 ledger A     (flux absorbed in step 2, code = fate + FATE_SPAWNS + FATE_ROLLED_BACK)
//   4 ledger B     (flux reflected in step 3 and not followed, 1 when it reflected)
// Slots at or beyond liveCount() get count 0 and FATE_NONE.
// RECEIVER: a patch whose midpoint crosses the receiver plane in this step, or that left the box
// heading for it, is received (receiver.h): its footprint (the corners' rays on the plane) must
// exist. SHARP_INTERFACES: the update pass's events (sharp.glsl, patch.glsl), blocked and trapped
// patches, and the reflected wavefront followed once every corner is through (CPU twin stepPatch).
#include "common/volume.glsl"
#include "lightsim/grid.glsl"
#include "lightsim/patch.glsl"
#include "lightsim/live_count.glsl"
#include "lightsim/fresnel.glsl"
#include "lightsim/fate.glsl"
#include "lightsim/atlas.glsl"
#ifdef SHARP_INTERFACES
#include "lightsim/sharp.glsl"
uniform int uBounces;          // reflections followed per wavefront (--bounces)
const int kMaxTotalReflections = 16;  // cpu_simulator.cpp: trapped by total internal reflection
#endif
#ifdef RECEIVER
uniform vec3 uReceiverPoint;   // the plane, in the grid's local coordinates
uniform vec3 uReceiverNormal;  // unit, facing the light
uniform bool uPassToReceiver;  // a patch torn at the depth limit gives the receiver the light that
                               // passes the object by (passingShare; not in a scene's chain of boxes)
#endif

uniform sampler2D uPatch[8];      // the list after the update
uniform sampler2D uPrevious[4];   // P0..P3 before the update
uniform sampler2D uPreviousFlux;  // FLUX before the update
uniform float uDt;                // Δt
uniform float uStepDt;            // an ordinary step's time: Δt, or a straight step's (the reach of a reflection)
uniform float uReflectedStepDt;    // a reflected wavefront's (StepContext::reflected_step_dt)

layout(location = 0) out vec4 oCount;
layout(location = 1) out vec4 oDepositA;
layout(location = 2) out vec4 oDepositB;
layout(location = 3) out vec4 oLedgerA;
layout(location = 4) out vec4 oLedgerB;

#ifdef RECEIVER
// The patch's footprint on the plane exists: every corner's ray meets the plane, none runs parallel
// to it or away from it above it (patchFootprint).
bool footprintExists(Patch p) {
  for (int c = 0; c < 4; ++c) {
    float facing = dot(p.w[c], uReceiverNormal);
    if (facing == 0.0 || (facing > 0.0 && dot(p.x[c] - uReceiverPoint, uReceiverNormal) > 0.0)) return false;
  }
  return true;
}
#endif

#if defined(SHARP_INTERFACES) && defined(RECEIVER) && defined(DEPOSIT_TRACK)
// passingShare (cpu_simulator.cpp): a patch torn at the depth limit, as it was before the step;
// `met` the corners that met the surface. Each other corner in air whose straight ray meets no
// interface before it leaves the box or reaches the plane carries a quarter of the patch's light
// straight to the receiver. 0 when a corner is not in air or the footprint does not exist.
float passingShare(Patch p, int met) {
  if (!uPassToReceiver) return 0.0;
  int passing = 0;
  for (int c = 0; c < 4; ++c) {
    if (p.medium[c] != -1) return 0.0;
    if (((met >> c) & 1) != 0) continue;
    vec3 d = normalize(p.w[c]);
    float facing = dot(d, uReceiverNormal);
    float above = dot(p.x[c] - uReceiverPoint, uReceiverNormal);
    if (!(facing < 0.0) || !(above > 0.0)) continue;
    float tEnd = -above / facing;
    for (int a = 0; a < 3; ++a)
      if (d[a] != 0.0) tEnd = min(tEnd, ((d[a] > 0.0 ? uBoxMax[a] : uBoxMin[a]) - p.x[c][a]) / d[a]);
    float f;
    int k, entered;
    if (tEnd > 0.0 && findInterfaceOnChord(p.x[c], p.x[c] + tEnd * d, -1, f, k, entered)) continue;
    ++passing;
  }
  return passing > 0 && footprintExists(p) ? 0.25 * float(passing) : 0.0;
}
#endif

// Step 2's factor a as the update pass applied it, read from its result: Φ = Φ_old · a · T_fresnel
// per channel. The step's time (Δt, a straight step's or a free flight's) is the update's alone.
// Where σa(m_old) = 0, a = 1 exactly (with σa per material the corners may absorb wherever the
// midpoint is: always read); 1 where no flux came in.
vec3 stepAbsorptionFactor(vec3 mOld, vec3 fluxOld, vec3 flux, float tFresnel) {
#ifndef MATERIAL_ABSORPTION
  if (all(equal(sampleSigmaA(mOld), vec3(0.0)))) return vec3(1.0);
#endif
  vec3 a = vec3(1.0);
  for (int c = 0; c < 3; ++c) {
    float before = fluxOld[c] * tFresnel;
    if (before > 0.0) a[c] = flux[c] / before;
  }
  return a;
}

void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy);
  oDepositA = vec4(0.0, 0.0, 0.0, -1.0);
  oDepositB = vec4(0.0);
  oLedgerB = vec4(0.0);
  if (mortonIndex(texel) >= liveCount()) {
    oCount = vec4(0.0);
    oLedgerA = vec4(0.0, 0.0, 0.0, float(FATE_NONE));
    return;
  }
  Patch p;
  FETCH_PATCH(uPatch, texel, p);
  vec3 o0, o1, o2, o3;
  FETCH_CORNERS(uPrevious, texel, o0, o1, o2, o3);
  vec3 mOld = 0.25 * (o0 + o1 + o2 + o3);
  vec3 fluxOld = texelFetch(uPreviousFlux, texel, 0).rgb;
  vec3 m = patchMidpoint(p);
  vec3 d = patchDirection(p);

#ifdef SHARP_INTERFACES
  // Undone steps: the patch (as it was) splits, or dies torn at the depth limit; nothing else
  // happened in them.
  if ((p.event & (SHARP_EVENT_SPLIT_U | SHARP_EVENT_SPLIT_V)) != 0) {
    int axes = p.event & 3;
    int fate = axes == 3 ? FATE_SPLIT : axes == 1 ? FATE_SPLIT_U : FATE_SPLIT_V;
    oCount = vec4(fateCount(fate), 0.0, 0.0, 0.0);
    oLedgerA = vec4(0.0, 0.0, 0.0, float(fate + FATE_ROLLED_BACK));
    return;
  }
  if ((p.event & SHARP_EVENT_TORN) != 0) {
    oCount = vec4(0.0);
    oLedgerA = vec4(0.0, 0.0, 0.0, float(FATE_DEPTH));
#if defined(RECEIVER) && defined(DEPOSIT_TRACK)
    // The light it carries past the object goes to the receiver (its footprint, this flux), and
    // the ledger's B says which share of its flux that is (w = −share: received, not killed).
    float share = passingShare(p, p.event / SHARP_EVENT_MET_UNIT);
    if (share > 0.0) {
      oDepositB = vec4(share * p.flux, 1.0);
      oLedgerB = vec4(0.0, 0.0, 0.0, -share);
    }
#endif
    return;
  }
  vec3 a = stepAbsorptionFactor(mOld, fluxOld, p.flux, p.tFresnel);
  vec3 reflected = fluxOld * a * (1.0 - p.tFresnel);
  // The reflected wavefront leaves the interface once every corner is through (bounces).
  bool spawns = false;
  vec3 spawnFlux = vec3(0.0);
  if (p.crossed == 15 && p.bounce < uBounces && p.reflectPending > 0.0 && p.reflectPending < 1.0) {
    spawnFlux = p.flux * (p.reflectPending / (1.0 - p.reflectPending));
    Patch r;
    spawns = max(max(spawnFlux.r, spawnFlux.g), spawnFlux.b) >= uFluxKill * exp2(-2.0 * p.depth) &&
             reflectedPatch(p, 4.0 * (p.bounce > 0 ? uReflectedStepDt : uStepDt) + 2.0 * uVoxelEdge, r);
  }
  int blocked = p.event / SHARP_EVENT_BLOCKED;
  bool splittable = oneMedium(p) && blocked == 0;
#else
  vec3 a = stepAbsorptionFactor(mOld, fluxOld, p.flux, p.tFresnel);
  vec3 reflected = p.tFresnel < 1.0 ? fluxOld * a * (1.0 - p.tFresnel) : vec3(0.0);
  bool spawns = false;
  vec3 spawnFlux = vec3(0.0);
  int blocked = 0;
  bool splittable = true;
#endif

  // The receiver: the midpoint crossed the plane in this step, or it left the box towards it.
  bool reached = false;
#ifdef RECEIVER
  float aboveOld = dot(mOld - uReceiverPoint, uReceiverNormal);
  float aboveNew = dot(m - uReceiverPoint, uReceiverNormal);
  bool crossedPlane = aboveOld > 0.0 && aboveNew <= 0.0;
  bool headingThere = !insideBox(m, uBoxMin, uBoxMax) && !rayHitsBox(m, d, uBoxMin, uBoxMax) && aboveNew > 0.0 &&
                      dot(d, uReceiverNormal) < 0.0;
  reached = (crossedPlane || headingThere) && footprintExists(p);
#endif

  // Step 5.
  int fate;
  if (reached) fate = FATE_RECEIVED;
  else if (blocked >= 2) fate = FATE_BLOCKED;
#ifdef SHARP_INTERFACES
  else if (p.reflections > kMaxTotalReflections) fate = FATE_TRAPPED;
#endif
  else fate = patchFate(p, splittable);
  oCount = vec4(fateCount(fate) + (spawns ? 1.0 : 0.0), 0.0, 0.0, 0.0);

  // The ledger: step 2's factor as update.frag applied it (stepAbsorptionFactor), step 3's
  // reflection from it and T_fresnel, less what a followed reflection carries on.
  oLedgerA = vec4(fluxOld * (1.0 - a), float(fate + (spawns ? FATE_SPAWNS : 0)));
  if (p.tFresnel < 1.0 || spawns) oLedgerB = vec4(reflected - (spawns ? spawnFlux : vec3(0.0)), p.tFresnel < 1.0 ? 1.0 : 0.0);

#ifdef DEPOSIT_TRACK
  oDepositA = vec4(0.5 * (fluxOld + p.flux), reached ? 1.0 : 0.0);
  if (reached) oDepositB = vec4(p.flux, 1.0);
#else
  // Step 4: the voxel containing m, floor of the continuous voxel coordinate, inside [0, dims).
  vec3 c = floor((m - uBoundsMin) * uInvExtent * vec3(ATLAS_DIMS));
  if (!(all(greaterThanEqual(c, vec3(0.0))) && all(lessThan(c, vec3(ATLAS_DIMS))))) return;
  vec2 at = vec2(atlasTexel(ivec3(c)));
#ifdef DEPOSIT_MAX
  float area = length(patchAreaVector(p));
  vec3 e = area > 0.0 ? p.flux / area : vec3(0.0);  // Eq. 4.16: E = Φ / A
  oDepositA = vec4(e, at.x);
  oDepositB = vec4(d, at.y);
#else
#ifdef SHARP_INTERFACES
  float dsm = uDt / mediumIor(mOld);  // Δs_m, Eq. 4.11, n of m_old's material
#else
  float dsm = uDt / sampleIor(mOld);  // Δs_m, Eq. 4.11
#endif
  oDepositA = vec4(p.flux * (dsm / uVoxelVolume), at.x);
  oDepositB = vec4(lum(p.flux) * dsm * d, at.y);
#endif
#endif
}
