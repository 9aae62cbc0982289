#version 330 core
// ALGORITHM.md step 6, compaction and expansion (Ziegler et al. 2006; thesis §6.2.4): one fragment
// per slot k of the new list (viewport: a Morton box at least as large; slots ≥ the pyramid's
// total, hpTotal, are skipped). The histogram pyramid over the analysis counts gives the source
// patch s and sub-index j (lightsim/histo_pyramid.glsl). Count 1 copies the patch; a split fate writes child j of its nu × nv split
// (2×2, or 1×2 along one axis): corners and w from the bilinear patch (x0 = (0,0), x1 = (1,0),
// x2 = (1,1), x3 = (0,1)) at the child's parameter cell (j mod nu, j div nu); w renormalised to n
// at the new corner; Φ_child = Φ·A_child/Σ A (flux conserved); depth + 1 (2×2) or + ½ (1×2),
// A0 = A_child; n_in, cos_in and T_fresnel inherited (wavefront.h splitPatch).
// SHARP_INTERFACES: children take the parent's material (a patch splits only inside one) and w is
// renormalised to that material's n; a crossing whose corners are all through is closed (crossed
// and reflect_pending reset); a code with FATE_SPAWNS adds, as the source's last slot, the
// reflected wavefront (sharp.glsl reflectedPatch) with the flux Φ·R/(1 − R) the crossing reflected,
// one bounce more (cpu_simulator.cpp stepPatch, step 3).
#include "common/volume.glsl"
#include "lightsim/grid.glsl"
#include "lightsim/patch.glsl"
#include "lightsim/fate_codes.glsl"
#include "lightsim/histo_pyramid.glsl"
#ifdef SHARP_INTERFACES
#include "lightsim/fresnel.glsl"
#include "lightsim/sharp.glsl"
uniform float uDt;  // an ordinary step's time, Δt or a straight step's (the reach of reflectedPatch: 4 Δt + 2 h)
uniform float uReflectedDt;  // a reflected wavefront's (StepContext::reflected_step_dt)
#endif

uniform sampler2D uPatch[8];   // the updated list (source)
uniform sampler2D uPyramid;    // histogram pyramid over its counts
uniform sampler2D uLedgerA;    // the analysis' (absorbed, fate): which split, if any

layout(location = 0) out vec4 oP0;
layout(location = 1) out vec4 oP1;
layout(location = 2) out vec4 oP2;
layout(location = 3) out vec4 oP3;
layout(location = 4) out vec4 oW01;
layout(location = 5) out vec4 oW23;
layout(location = 6) out vec4 oFlux;
layout(location = 7) out vec4 oMeta;

// The bilinear patch through c0 = (0,0), c1 = (1,0), c2 = (1,1), c3 = (0,1) at (u, v).
vec3 bilinear(vec3 c0, vec3 c1, vec3 c2, vec3 c3, float u, float v) {
  return ((1.0 - u) * (1.0 - v)) * c0 + (u * (1.0 - v)) * c1 + (u * v) * c2 + ((1.0 - u) * v) * c3;
}

void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy);
  int k = hpTexelSlot(texel);
  if (k >= hpTotal(uPyramid)) discard;  // the new list's size
  int j;
  ivec2 source = hpFind(uPyramid, k, j);
  Patch p;
  FETCH_PATCH(uPatch, source, p);
  int code = int(texelFetch(uLedgerA, source, 0).w + 0.5);
  int fate = fateOf(code);
  bool reflection = fateSpawns(code) && float(j) == fateCount(fate);  // the source's last slot
#ifdef SHARP_INTERFACES
  p.event = 0;
  if (reflection) {
    // The reflected wavefront (computed exactly as the analysis did when it counted the slot).
    Patch r;
    reflectedPatch(p, 4.0 * (p.bounce > 0 ? uReflectedDt : uDt) + 2.0 * uVoxelEdge, r);
    r.flux = p.flux * (p.reflectPending / (1.0 - p.reflectPending));
    r.area0 = length(patchAreaVector(r));
    r.bounce = p.bounce + 1;
    r.reflectPending = 0.0;
    r.crossed = 0;
    r.reflected = 0;
    r.tFresnel = 1.0;
    p = r;
  } else if (p.crossed == 15) {
    p.crossed = 0;  // every corner is through: the crossing is closed
    p.reflectPending = 0.0;
  }
#endif
  if (fateSplits(fate) && !reflection) {
    // nu × nv children (2×2, 2×1 or 1×2); child j covers parameter cell (j mod nu, j div nu) of
    // the grid (u, v) = (a/nu, b/nv) (wavefront.h splitPatch).
    ivec2 cells = fateSplitCells(fate);
    int nu = cells.x, nv = cells.y;
    vec2 scale = 1.0 / vec2(cells);
    float ua[4] = float[4](0.0, 1.0, 1.0, 0.0);
    float va[4] = float[4](0.0, 0.0, 1.0, 1.0);
    // Areas of the children, A = |½ (c2 − c0) × (c3 − c1)|, for the flux split.
    float areas[4];
    float total = 0.0;
    for (int c = 0; c < 4; ++c) {
      areas[c] = 0.0;
      if (c >= nu * nv) continue;
      vec3 q[4];
      for (int k = 0; k < 4; ++k) {
        vec2 uv = (vec2(float(c % nu), float(c / nu)) + vec2(ua[k], va[k])) * scale;
        q[k] = bilinear(p.x[0], p.x[1], p.x[2], p.x[3], uv.x, uv.y);
      }
      areas[c] = length(areaVector(q[0], q[1], q[2], q[3]));
      total += areas[c];
    }
    Patch child = p;
    for (int c = 0; c < 4; ++c) {
      vec2 uv = (vec2(float(j % nu), float(j / nu)) + vec2(ua[c], va[c])) * scale;
      child.x[c] = bilinear(p.x[0], p.x[1], p.x[2], p.x[3], uv.x, uv.y);
      vec3 w = bilinear(p.w[0], p.w[1], p.w[2], p.w[3], uv.x, uv.y);
      float len = length(w);
#ifdef SHARP_INTERFACES
      child.medium[c] = oneMedium(p) ? p.medium[0] : materialAt(child.x[c]);
      float n = materialOptics(child.medium[c], child.x[c]).x;
#else
      float n = sampleIor(child.x[c]);
#endif
      child.w[c] = len > 0.0 ? w * (n / len) : w;  // |w| = n at the new corner
    }
    float children = float(nu * nv);
    child.flux = total > 0.0 ? p.flux * (areas[j] / total) : p.flux / children;
    child.area0 = areas[j];
    child.depth = p.depth + 0.25 * children;  // +1 for 2×2, +½ for 1×2
    p = child;
  }

  vec4 t[8];
  packPatch(p, t);
  oP0 = t[0]; oP1 = t[1]; oP2 = t[2]; oP3 = t[3];
  oW01 = t[4]; oW23 = t[5]; oFlux = t[6]; oMeta = t[7];
}
