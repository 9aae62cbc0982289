#version 330 core
// ALGORITHM.md step 6, compaction and expansion (Ziegler et al. 2006; thesis §6.2.4): one fragment
// per slot k of the new list (viewport: its Morton box; slots ≥ uTotal are skipped). The histogram
// pyramid over the analysis counts gives the source patch s and sub-index j (lightsim/
// histo_pyramid.glsl). Count 1 copies the patch; count 4 writes child j of its 2×2 split:
//   corners and w from the bilinear patch at (u, v) ∈ {0, ½, 1}² (x0 = (0,0), x1 = (1,0),
//   x2 = (1,1), x3 = (0,1)); child j covers [u_j, u_j + ½] × [v_j, v_j + ½] with (u_j, v_j) =
//   (0,0), (½,0), (0,½), (½,½); w renormalised to n at the new corner; Φ_child = Φ·A_child/Σ A
//   (flux conserved); depth + 1, A0 = A_child; n_in, cos_in and T_fresnel inherited
//   (wavefront.h splitPatch).
#include "common/volume.glsl"
#include "lightsim/grid.glsl"
#include "lightsim/patch.glsl"
#include "lightsim/fate_codes.glsl"
#include "lightsim/histo_pyramid.glsl"

uniform sampler2D uPatch[8];   // the updated list (source)
uniform sampler2D uPyramid;    // histogram pyramid over its counts
uniform sampler2D uLedgerA;    // the analysis' (absorbed, fate): FATE_SPLIT means count 4
uniform int uTotal;            // new list size

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
  if (k >= uTotal) discard;
  int j;
  ivec2 source = hpFind(uPyramid, k, j);
  Patch p;
  FETCH_PATCH(uPatch, source, p);
  int fate = int(texelFetch(uLedgerA, source, 0).w + 0.5);

  if (fate == FATE_SPLIT) {
    // The 3×3 grid of the split at (u, v) = (a/2, b/2); g[a + 3b].
    vec3 g[9];
    for (int b = 0; b < 3; ++b) {
      for (int a = 0; a < 3; ++a) {
        g[a + 3 * b] = bilinear(p.x[0], p.x[1], p.x[2], p.x[3], 0.5 * float(a), 0.5 * float(b));
      }
    }
    // Areas of the four children, A = |½ (c2 − c0) × (c3 − c1)|, for the flux split.
    float areas[4];
    float total = 0.0;
    for (int c = 0; c < 4; ++c) {
      int a0 = c & 1, b0 = c >> 1;
      int i0 = a0 + 3 * b0;  // corner (u_c, v_c)
      areas[c] = length(areaVector(g[i0], g[i0 + 1], g[i0 + 4], g[i0 + 3]));
      total += areas[c];
    }
    int a0 = j & 1, b0 = j >> 1;  // child j's origin (u_j, v_j) = (a0/2, b0/2)
    float ua[4] = float[4](0.0, 1.0, 1.0, 0.0);
    float va[4] = float[4](0.0, 0.0, 1.0, 1.0);
    Patch child = p;
    for (int c = 0; c < 4; ++c) {
      float u = 0.5 * (float(a0) + ua[c]), v = 0.5 * (float(b0) + va[c]);
      child.x[c] = g[(a0 + int(ua[c])) + 3 * (b0 + int(va[c]))];
      vec3 w = bilinear(p.w[0], p.w[1], p.w[2], p.w[3], u, v);
      float len = length(w);
      child.w[c] = len > 0.0 ? w * (sampleIor(child.x[c]) / len) : w;  // |w| = n at the new corner
    }
    child.flux = total > 0.0 ? p.flux * (areas[j] / total) : 0.25 * p.flux;
    child.area0 = areas[j];
    child.depth = p.depth + 1.0;
    p = child;
  }

  vec4 t[8];
  packPatch(p, t);
  oP0 = t[0]; oP1 = t[1]; oP2 = t[2]; oP3 = t[3];
  oW01 = t[4]; oW23 = t[5]; oFlux = t[6]; oMeta = t[7];
}
