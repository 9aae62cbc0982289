#version 330 core
// Receiver-map deposits (ALGORITHM.md "Receivers"; lightsim/receiver_pass.h), the GPU twin of
// patchFootprint + depositFootprint (lightsim/receiver.h). GL_TRIANGLES without vertex buffers,
// 12 vertices a patch: gl_VertexID / 12 is the patch index, then footprint triangle 0 (corners
// 0, 1, 2) or 1 (corners 0, 2, 3), 6 vertices each: a quad (two GL triangles) over the triangle's
// bounding box grown outwards to whole texels, in the map's texel coordinates. The fragment shader
// (receiver.frag) clips the triangle against each texel of that box.
//
// Everything is in texel units relative to the map's corner (texel (i, j) covers [i, i+1]×[j, j+1]),
// so float coordinates stay as small as the map.
#include "lightsim/patch.glsl"

uniform sampler2D uPatch[8];     // the patches (grid-local coordinates), patch.glsl layout
uniform sampler2D uReceiveInfo;  // (Φ at the plane, received > 0), patch k at mortonTexel(k)
uniform vec3 uCorner;            // the map's corner on the plane (texel coordinates (0, 0)), grid-local
uniform vec3 uNormal;            // the plane's unit normal
uniform vec3 uAxisU;             // its unit in-plane axes (texel x along u, y along v)
uniform vec3 uAxisV;
uniform float uPitch;            // texel edge, world units
uniform vec2 uTexels;            // the map's size in texels

// The footprint triangle, the same for all its vertices (flat).
flat out vec2 vA;
flat out vec2 vB;
flat out vec2 vC;
flat out vec3 vDensity;  // its flux share / |its area| (per texel²); vWhole: the whole share
flat out int vWhole;     // 1: degenerate triangle, all of vDensity to the (one) texel of the quad

// A position outside the clip volume: every vertex of a culled triangle goes there, so the
// primitive has no area and no fragments.
const vec4 kCulled = vec4(2.0, 2.0, 2.0, 1.0);
// Corners of the quad (lo, lo), (hi, lo), (hi, hi), (lo, hi) for its two GL triangles.
const int kQuadCorner[6] = int[6](0, 1, 2, 0, 2, 3);
// A triangle whose height over its longest edge is below 1e-5 of that edge is degenerate: float
// cannot resolve its area (its relative error is about 1e-7 · longest² / area).
const float kThin = 0.5e-5;
// Footprint coordinates at or beyond this many texels (and NaN) are culled: a triangle that long
// puts a negligible part of its flux on a map of at most GL_MAX_TEXTURE_SIZE texels, and products
// of such coordinates would overflow float.
const float kFar = 1e15;

float cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }

void main() {
  gl_Position = kCulled;
  vA = vec2(0.0);
  vB = vec2(0.0);
  vC = vec2(0.0);
  vDensity = vec3(0.0);
  vWhole = 0;

  int patchIndex = gl_VertexID / 12;
  int local = gl_VertexID - 12 * patchIndex;
  int triangle = local / 6;
  int quadCorner = kQuadCorner[local - 6 * triangle];
  ivec2 texel = mortonTexel(patchIndex);
  vec4 info = texelFetch(uReceiveInfo, texel, 0);
  if (!(info.a > 0.0)) return;  // not received: deposits nothing

  Patch p;
  FETCH_PATCH(uPatch, texel, p);
  // patchFootprint: each corner's ray x_c + t·w_c meets the plane where its height over the plane
  // is zero: height = dot(x − point, normal), p = x − (height/facing)·w, facing = dot(w, normal).
  // The plane's point is the map's corner, so dot(p − point, u|v)/pitch are the texel coordinates
  // (planeCoordinates(p) − origin)/pitch. A ray parallel to the plane: no footprint (culled).
  vec2 f[4];
  for (int c = 0; c < 4; ++c) {
    float facing = dot(p.w[c], uNormal);
    if (facing == 0.0) return;
    float height = dot(p.x[c] - uCorner, uNormal);
    vec3 q = p.x[c] - (height / facing) * p.w[c] - uCorner;
    f[c] = vec2(dot(q, uAxisU), dot(q, uAxisV)) / uPitch;
    if (!(abs(f[c].x) < kFar && abs(f[c].y) < kFar)) return;
  }

  // depositFootprint: triangles (0, 1, 2) and (0, 2, 3), each with Φ·|its area|/(|area 1| + |area 2|)
  // (half each when both are degenerate).
  float area1 = 0.5 * abs(cross2(f[1] - f[0], f[2] - f[0]));
  float area2 = 0.5 * abs(cross2(f[2] - f[0], f[3] - f[0]));
  float total = area1 + area2;
  float share = total > 0.0 ? area1 / total : 0.5;
  vec2 a = f[0];
  vec2 b = triangle == 0 ? f[1] : f[2];
  vec2 c = triangle == 0 ? f[2] : f[3];
  vec3 flux = info.rgb * (triangle == 0 ? share : 1.0 - share);
  if (!any(notEqual(flux, vec3(0.0)))) return;  // nothing to add

  float area = 0.5 * abs(cross2(b - a, c - a));
  float longest2 = max(dot(b - a, b - a), max(dot(c - b, c - b), dot(a - c, a - c)));
  vec2 lo, hi;
  if (!(area > kThin * longest2)) {
    // depositTriangle's degenerate case: the flux goes to the texel of the triangle's centroid.
    lo = floor((a + b + c) / 3.0);
    hi = lo + 1.0;
    vDensity = flux;
    vWhole = 1;
  } else {
    // The bounding box grown outwards to whole texels: every texel the triangle touches.
    lo = floor(min(a, min(b, c)));
    hi = floor(max(a, max(b, c))) + 1.0;
    vDensity = flux / area;
  }
  // Flux off the map is dropped: only the map's texels are drawn.
  lo = max(lo, vec2(0.0));
  hi = min(hi, uTexels);
  if (any(greaterThanEqual(lo, hi))) return;

  vA = a;
  vB = b;
  vC = c;
  vec2 corner = vec2(quadCorner == 1 || quadCorner == 2 ? hi.x : lo.x, quadCorner >= 2 ? hi.y : lo.y);
  gl_Position = vec4(corner / uTexels * 2.0 - 1.0, 0.0, 1.0);
}
