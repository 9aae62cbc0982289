// ALGORITHM.md step 5, analysis (thesis §6.2.4): what becomes of a patch after its update.
// Needs lightsim/grid.glsl and lightsim/patch.glsl.
#include "lightsim/fate_codes.glsl"

uniform float uFluxKill;     // flux_threshold · Φ_ref
uniform float uSplitLength;  // split_voxels · h
uniform float uMaxDepth;     // max_depth
uniform bool uKillAtMaxDepth;  // DepthLimit::Kill (else a patch at max_depth is kept unsplit)
uniform bool uAxisSplit;     // SplitRule::Axis: halve only the directions whose edges are too long
uniform vec3 uBoxMin;        // the propagation box (wavefront.h propagationBox): the grid's,
uniform vec3 uBoxMax;        //   grown by h for track deposits

// The fate of an updated patch; `splittable` false keeps (or kills at the edge limit) a patch that
// must not split (with sharp interfaces: corners in different materials, or stopped ones).
int patchFate(Patch p, bool splittable) {
  vec3 m = patchMidpoint(p);
  vec3 d = patchDirection(p);
  // flux: max(Φ) < flux_threshold · Φ_ref / 4^depth
  if (max(max(p.flux.r, p.flux.g), p.flux.b) < uFluxKill * exp2(-2.0 * p.depth)) return FATE_FLUX;
  // exited: m outside the grid box and the straight ray (m, d) misses it
  if (!insideBox(m, uBoxMin, uBoxMax) && !rayHitsBox(m, d, uBoxMin, uBoxMax)) return FATE_EXITED;
#ifdef DEPOSIT_MAX
  // folded: N · d ≤ 0 (or NaN). Only in `max` mode, like the CPU twin: an accumulate deposit does
  // not divide by the area, so a caustic singularity does no harm there.
  if (!(dot(patchAreaVector(p), d) > 0.0)) return FATE_FOLDED;
#endif
  // split (wavefront.h splitAxes): u edges x0x1, x3x2; v edges x1x2, x0x3
  float splitLength = splitLengthOf(p, uSplitLength);
  float uEdge = max(distance(p.x[0], p.x[1]), distance(p.x[3], p.x[2]));
  float vEdge = max(distance(p.x[1], p.x[2]), distance(p.x[0], p.x[3]));
  bool splitU, splitV;
  if (uAxisSplit) {
    splitU = uEdge > splitLength;
    splitV = vEdge > splitLength;
  } else {
    splitU = splitV = max(uEdge, vEdge) > splitLength;  // Quad: the longest side decides
  }
  if (!(splitU || splitV)) return FATE_KEEP;
  // At max_depth: kept unsplit (DepthLimit::Keep) while the longest edge is at most
  // kMaxUnsplitEdge (4) split lengths (wavefront.h), else killed.
  if (!splittable || p.depth >= uMaxDepth) return uKillAtMaxDepth || max(uEdge, vEdge) > 4.0 * uSplitLength ? FATE_DEPTH : FATE_KEEP;
  return splitU && splitV ? FATE_SPLIT : splitU ? FATE_SPLIT_U : FATE_SPLIT_V;
}
