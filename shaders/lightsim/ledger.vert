#version 330 core
// The energy ledger (ALGORITHM.md "Bake output", energy check), accumulated on the GPU: one
// GL_POINTS primitive per patch (gl_VertexID = patch index) with additive blending into eight
// small RGBA32F targets, one per entry (lightsim/ledger_pass.h, LedgerPass):
//   0 absorbed (Φ, 0)       (step 2)      4 folded kills (Φ, count)
//   1 reflected (Φ, count)  (step 3)      5 depth kills (Φ, count)
//   2 exited (Φ, count)     (step 5)      6 splits (0, count)
//   3 flux kills (Φ, count) (step 5)      7 unfinished (Φ, count): trapped, and at the end
// The analysis pass computed the per-patch values (ledger A = (absorbed, fate), B = (reflected,
// event)); this pass only sums them. A row per step (uRow); within it patch k adds into bin
// k mod uBins, so no texel sums more than count/uBins values in float (bins and rows are summed in
// double on readback) and the points spread over many texels instead of contending for one.
// Patches with nothing to add are culled. LEDGER_UNFINISHED: the final list, entry 7 only.
// LEDGER_EXTRA: the entries of receivers and sharp interfaces, into a second set of four targets:
//   0 received (Φ, count)   1 blocked (Φ, count)   2 reflections followed (0, count)
//   3 steps undone before a crossing (0, count)
#include "lightsim/patch.glsl"
#include "lightsim/fate_codes.glsl"

uniform sampler2D uLedgerA;  // (absorbed, fate)
uniform sampler2D uLedgerB;  // (reflected, 1 when reflected)
uniform sampler2D uFlux;     // FLUX of the list (after the update; LEDGER_UNFINISHED: the final list)
uniform int uRow;
uniform int uBins;
uniform vec2 uLedgerSize;    // (uBins, rows)

out vec4 vEntry[8];

void main() {
  for (int i = 0; i < 8; ++i) vEntry[i] = vec4(0.0);
  ivec2 texel = mortonTexel(gl_VertexID);
  bool emit = true;
#if defined(LEDGER_UNFINISHED)
  vEntry[7] = vec4(texelFetch(uFlux, texel, 0).rgb, 1.0);
#elif defined(LEDGER_EXTRA)
  int code = int(texelFetch(uLedgerA, texel, 0).w + 0.5);
  int fate = fateOf(code);
  vec4 dead = vec4(texelFetch(uFlux, texel, 0).rgb, 1.0);
  if (fate == FATE_RECEIVED) vEntry[0] = dead;
  // A patch torn at the depth limit whose passing corners' light went to the receiver (ledger B's
  // w = −share, analysis.frag passingShare): that share is received (not counted as a patch).
  float passing = fate == FATE_DEPTH ? max(-texelFetch(uLedgerB, texel, 0).w, 0.0) : 0.0;
  if (passing > 0.0) vEntry[0] = vec4(dead.rgb * passing, 0.0);
  if (fate == FATE_BLOCKED) vEntry[1] = dead;
  if (fateSpawns(code)) vEntry[2] = vec4(0.0, 0.0, 0.0, 1.0);
  if (fateRolledBack(code)) vEntry[3] = vec4(0.0, 0.0, 0.0, 1.0);
  emit = fate == FATE_RECEIVED || fate == FATE_BLOCKED || code >= FATE_SPAWNS || passing > 0.0;
#else
  vec4 a = texelFetch(uLedgerA, texel, 0);
  vec4 b = texelFetch(uLedgerB, texel, 0);
  int fate = fateOf(int(a.w + 0.5));
  vEntry[0] = vec4(a.rgb, 0.0);
  // b.w < 0: not a reflection but the share of a patch torn at the depth limit that was received.
  float passing = b.w < 0.0 ? -b.w : 0.0;
  vEntry[1] = passing > 0.0 ? vec4(0.0) : b;
  vec4 dead = fate >= FATE_EXITED ? vec4(texelFetch(uFlux, texel, 0).rgb, 1.0) : vec4(0.0);
  if (fate == FATE_EXITED) vEntry[2] = dead;
  if (fate == FATE_FLUX) vEntry[3] = dead;
  if (fate == FATE_FOLDED) vEntry[4] = dead;
  if (fate == FATE_DEPTH) vEntry[5] = vec4(dead.rgb * (1.0 - passing), 1.0);
  if (fate == FATE_TRAPPED) vEntry[7] = dead;  // trapped light is unfinished light
  if (fateSplits(fate)) vEntry[6] = vec4(0.0, 0.0, 0.0, 1.0);
  emit = fate >= FATE_SPLIT || b.w > 0.0 || any(notEqual(b.rgb, vec3(0.0))) || any(greaterThan(a.rgb, vec3(0.0)));
#endif
  vec2 ndc = (vec2(float(gl_VertexID % uBins), float(uRow)) + 0.5) / uLedgerSize * 2.0 - 1.0;
  gl_Position = emit ? vec4(ndc, 0.0, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
