#version 330 core
// The energy ledger (ALGORITHM.md "Bake output", energy check), accumulated on the GPU: one
// GL_POINTS primitive per patch (gl_VertexID = patch index) with additive blending into eight
// small RGBA32F targets, one per entry (lightsim/gpu_simulator.cpp, Ledger):
//   0 absorbed Φ·(1 − exp(−σa Δs_m))        (step 2)      4 folded kills (Φ, count)
//   1 reflected Φ'·R (Φ' after absorption)  (step 3)      5 depth kills (Φ, count)
//   2 exited (Φ, count)                     (step 5)      6 splits (0, count)
//   3 flux kills (Φ, count)                 (step 5)      7 unfinished (Φ, count), at the end
// A row per step (uRow); within it patch k adds into bin k mod uBins, so no texel sums more than
// count/uBins values in float (the bins and rows are summed in double on readback) and the points
// spread over many texels instead of contending for one. Patches with nothing to add are culled.
// LEDGER_UNFINISHED: the final list, entry 7 only.
#include "common/volume.glsl"
#include "lightsim/grid.glsl"
#include "lightsim/patch.glsl"
#include "lightsim/fate.glsl"

uniform sampler2D uPatch[8];     // the list after the update (LEDGER_UNFINISHED: the final list)
uniform sampler2D uPrevious[8];  // the list before the update
uniform sampler2D uFate;         // fate codes of the analysis
uniform float uDt;
uniform int uRow;
uniform int uBins;
uniform vec2 uLedgerSize;        // (uBins, rows)

out vec4 vEntry[8];

void main() {
  for (int i = 0; i < 8; ++i) vEntry[i] = vec4(0.0);
  ivec2 texel = mortonTexel(gl_VertexID);
  bool emit = false;
#ifdef LEDGER_UNFINISHED
  vEntry[7] = vec4(texelFetch(uPatch[6], texel, 0).rgb, 1.0);
  emit = true;
#else
  vec3 fluxOld = texelFetch(uPrevious[6], texel, 0).rgb;
#ifdef HAS_SIGMA_A
  // Recompute step 2's factor exactly as update.frag did (same inputs, same code).
  vec3 o0, o1, o2, o3;
  FETCH_CORNERS(uPrevious, texel, o0, o1, o2, o3);
  vec3 a = absorptionFactor(0.25 * (o0 + o1 + o2 + o3), uDt);
  vEntry[0] = vec4(fluxOld * (1.0 - a), 0.0);
  emit = emit || any(greaterThan(vEntry[0].rgb, vec3(0.0)));
#else
  vec3 a = vec3(1.0);
#endif
  float t = texelFetch(uPatch[7], texel, 0).w;  // T_fresnel of this step
  if (t < 1.0) {
    vEntry[1] = vec4(fluxOld * a * (1.0 - t), 1.0);
    emit = true;
  }
  int fate = int(texelFetch(uFate, texel, 0).r + 0.5);
  vec4 dead = vec4(texelFetch(uPatch[6], texel, 0).rgb, 1.0);
  if (fate == FATE_EXITED) vEntry[2] = dead;
  if (fate == FATE_FLUX) vEntry[3] = dead;
  if (fate == FATE_FOLDED) vEntry[4] = dead;
  if (fate == FATE_DEPTH) vEntry[5] = dead;
  if (fate == FATE_SPLIT) vEntry[6] = vec4(0.0, 0.0, 0.0, 1.0);
  emit = emit || fate >= FATE_SPLIT;
#endif
  vec2 ndc = (vec2(float(gl_VertexID % uBins), float(uRow)) + 0.5) / uLedgerSize * 2.0 - 1.0;
  gl_Position = emit ? vec4(ndc, 0.0, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
