#version 330 core
// Receiver-map deposits (ALGORITHM.md "Receivers"; lightsim/receiver_pass.h): one fragment per
// texel of a footprint triangle's (conservative) bounding box adds the triangle's flux times the
// area of triangle ∩ texel over the triangle's area (depositTriangle and triangleSquareOverlap,
// lightsim/receiver.cpp); additive blending sums the patches.
//
// The triangle comes in texel units relative to the map's corner; it is moved to coordinates
// relative to this texel's corner (exact: the shift is a whole number of texels), so the texel is
// the unit square and the clipping is as exact as float numbers of the size of one texel allow.
flat in vec2 vA;
flat in vec2 vB;
flat in vec2 vC;
flat in vec3 vDensity;  // flux share / |triangle area|, or the whole share when vWhole
flat in int vWhole;

layout(location = 0) out vec4 oFlux;  // (flux, 0)

float cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }

// One Sutherland–Hodgman step: src[0 .. n) clipped against the half-plane
// sign·(p[axis] − bound) ≤ 0 into dst (clipAgainst in receiver.cpp). A crossing point lies on the
// clip line exactly, its other coordinate interpolated from the endpoint nearer the line (so a
// far-away vertex does not cost precision). A triangle clipped by 4 half-planes has at most 7
// vertices; dst is never overrun.
int clipAgainst(vec2 src[8], int n, out vec2 dst[8], int axis, float bound, float sign) {
  for (int i = 0; i < 8; ++i) dst[i] = vec2(0.0);
  int m = 0;
  for (int i = 0; i < n; ++i) {
    vec2 a = src[i];
    vec2 b = src[i + 1 == n ? 0 : i + 1];
    float da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
    if (da <= 0.0 && m < 8) dst[m++] = a;
    if (((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) && m < 8) {
      vec2 q = abs(da) <= abs(db) ? a + (da / (da - db)) * (b - a) : b + (db / (db - da)) * (a - b);
      q[axis] = bound;
      dst[m++] = q;
    }
  }
  return m;
}

void main() {
  if (vWhole != 0) {  // a degenerate triangle: all of its flux to its centroid's texel
    oFlux = vec4(vDensity, 0.0);
    return;
  }
  vec2 texel = floor(gl_FragCoord.xy);
  vec2 a = vA - texel, b = vB - texel, c = vC - texel;

  // As depositTriangle: edge functions, positive inside whatever the winding; a texel with its
  // four corners inside all three edges is covered whole, one with its four corners outside one
  // edge not at all; only the texels an edge passes through are clipped.
  float orient = cross2(b - a, c - a) > 0.0 ? 1.0 : -1.0;
  vec2 p0[3] = vec2[3](a, b, c), p1[3] = vec2[3](b, c, a);
  vec2 squareCorners[4] = vec2[4](vec2(0.0), vec2(1.0, 0.0), vec2(0.0, 1.0), vec2(1.0));
  bool allInside = true;
  for (int e = 0; e < 3; ++e) {
    int inside = 0;
    for (int k = 0; k < 4; ++k) inside += orient * cross2(p1[e] - p0[e], squareCorners[k] - p0[e]) >= 0.0 ? 1 : 0;
    if (inside == 0) discard;
    if (inside != 4) allInside = false;
  }
  float overlap = 1.0;
  if (!allInside) {
    // triangleSquareOverlap: clip against x ≥ 0, x ≤ 1, y ≥ 0, y ≤ 1, then the shoelace area (as a
    // fan around the first vertex, so the products stay as small as the polygon).
    vec2 poly[8], tmp[8];
    for (int i = 0; i < 8; ++i) poly[i] = vec2(0.0);
    poly[0] = a;
    poly[1] = b;
    poly[2] = c;
    int n = clipAgainst(poly, 3, tmp, 0, 0.0, -1.0);
    n = clipAgainst(tmp, n, poly, 0, 1.0, 1.0);
    n = clipAgainst(poly, n, tmp, 1, 0.0, -1.0);
    n = clipAgainst(tmp, n, poly, 1, 1.0, 1.0);
    if (n < 3) discard;
    float twice = 0.0;
    for (int i = 1; i + 1 < n; ++i) twice += cross2(poly[i] - poly[0], poly[i + 1] - poly[0]);
    overlap = 0.5 * abs(twice);
    if (!(overlap > 0.0)) discard;
  }
  oFlux = vec4(vDensity * overlap, 0.0);
}
