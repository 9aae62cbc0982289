// ALGORITHM.md step 5, analysis (thesis §6.2.4): what becomes of a patch after its update.
// Codes (also the ledger's rows, lightsim/gpu_simulator.cpp):
const int FATE_NONE = 0;     // no patch at this slot
const int FATE_KEEP = 1;     // count 1
const int FATE_SPLIT = 2;    // count 4
const int FATE_EXITED = 3;   // count 0: outside the box, heading away
const int FATE_FLUX = 4;     // count 0: max(Φ) under the threshold
const int FATE_FOLDED = 5;   // count 0: N·d ≤ 0 (caustic singularity)
const int FATE_DEPTH = 6;    // count 0: needs a split beyond max_depth

uniform float uFluxKill;     // flux_threshold · Φ_ref
uniform float uSplitLength;  // split_voxels · h
uniform float uMaxDepth;     // max_depth

int patchFate(Patch p) {
  vec3 m = patchMidpoint(p);
  vec3 d = patchDirection(p);
  // flux: max(Φ) < flux_threshold · Φ_ref / 4^depth
  if (max(max(p.flux.r, p.flux.g), p.flux.b) < uFluxKill * exp2(-2.0 * p.depth)) return FATE_FLUX;
  // exited: m outside the grid box and the straight ray (m, d) misses it
  if (!insideGrid(m) && !rayHitsGrid(m, d)) return FATE_EXITED;
#ifdef DEPOSIT_MAX
  // folded: N · d ≤ 0 (or NaN). Only in `max` mode, like the CPU twin: an accumulate deposit does
  // not divide by the area, so a caustic singularity does no harm there.
  if (!(dot(patchAreaVector(p), d) > 0.0)) return FATE_FOLDED;
#endif
  // split when the longest of the four sides exceeds split_voxels · h
  float longest = max(max(distance(p.x[0], p.x[1]), distance(p.x[1], p.x[2])),
                      max(distance(p.x[2], p.x[3]), distance(p.x[3], p.x[0])));
  if (longest > uSplitLength) return p.depth >= uMaxDepth ? FATE_DEPTH : FATE_SPLIT;
  return FATE_KEEP;
}

float fateCount(int fate) { return fate == FATE_KEEP ? 1.0 : (fate == FATE_SPLIT ? 4.0 : 0.0); }
