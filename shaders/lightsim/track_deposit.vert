#version 330 core
// ALGORITHM.md step 4 with the track-length kernel ("Track deposits"; lightsim/track_deposit_pass.h):
// one GL_POINTS vertex per (patch, z-slice), patch = uFirstPatch + gl_VertexID / uSpan, slice = the
// (gl_VertexID mod uSpan)-th of the patch's box. The point covers, in that slice's atlas tile, the
// x/y extent of the voxels whose trilinear hats the swept patch can touch in that slice: centres
// within one voxel of the hull of its 8 corners (before and after the step, which holds every
// sub-path: each is a segment between bilinear points of the two corner quads) cut by the slab of z
// that reaches the slice. track_deposit.frag computes
// each voxel's deposit; fragments outside the box (a square point may spill past it, even into the
// next tile) are discarded there.
#include "lightsim/patch.glsl"
#include "lightsim/atlas.glsl"

uniform sampler2D uBefore[8];  // corners before the step (P0..P3 used)
uniform sampler2D uAfter[8];   // corners after the step
uniform sampler2D uTrackInfo;  // (track_flux, flag): flag < 0 none, ≥ 0 deposit, ≥ 1 clip at the receiver
uniform int uFirstPatch;       // patch of gl_VertexID 0 (batched draws)
uniform int uSpan;             // S = maxExtentVoxels + 2: slices per patch, and the largest point side
uniform vec3 uBoundsMin;       // the grid in the corners' frame (GridUniforms)
uniform vec3 uBoundsMax;
uniform ivec3 uDims;
uniform float uVoxelEdge;      // h of the sub-path lattice (the smallest voxel edge)
uniform float uDimIrradiance;  // patch-steps under this irradiance take the 1-voxel lattice (0: none)
uniform bool uClipEnabled;     // a receiver plane exists (applyTrackDeposits: `receiver`)
uniform vec3 uReceiverPoint;
uniform vec3 uReceiverNormal;  // unit, pointing to the side the light comes from

// The corners in continuous voxel coordinates (voxel centres at integer + ½, GridSpec::toVoxel)
// and their heights above the receiver plane. Both maps are affine, so the bilinear point of these
// is the voxel coordinate and the height of the bilinear point in the world, which the CPU computes.
flat out vec4 vBefore[4];
flat out vec4 vAfter[4];
flat out vec4 vFlux;       // (Φ_sub = track_flux/(n_u·n_v), clip at the receiver: 1, else 0)
// A flux that changes along the step goes from Φ_start to Φ_end geometrically (applyTrackDeposits):
// Φ_sub is then Φ_start/(n_u·n_v) and (κ, 1) = (ln(Φ_start/Φ_end) per channel, 1); else (0, 0).
flat out vec4 vDecay;
flat out ivec4 vBox;       // the voxel box in this slice: (i_min, j_min, i_max, j_max), inclusive
flat out ivec4 vTile;      // (tile origin x, y in the atlas, slice k, n_u + 32·n_v)

// track_deposit.h trackLattice: n = ⌈edge / spacing⌉, 1 ≤ n ≤ kMaxTrackLattice (16), the spacing
// ½ voxel, or 1 voxel for dim light (trackSpacing). The CPU's allowance (1e-9 in double) becomes
// 1e-4 spacings in float, so that an edge of exactly k spacings, which float corners carry with a
// relative error of ~1e-7 × the coordinates, still gets the CPU's k sub-paths.
int trackLattice(float edgeVoxels, float spacing) {
  if (!(edgeVoxels > spacing)) return 1;
  return int(min(16.0, ceil(edgeVoxels / spacing - 1e-4)));
}

// The area of a corner quadrilateral, Patch::area: ½ |(x₂ − x₀) × (x₃ − x₁)|.
float quadArea(vec3 x0, vec3 x1, vec3 x2, vec3 x3) { return 0.5 * length(cross(x2 - x0, x3 - x1)); }

// A corner for track_deposit.frag: (voxel coordinates, height above the receiver plane).
vec4 voxelCorner(vec3 x, vec3 voxel) { return vec4(voxel, dot(x - uReceiverPoint, uReceiverNormal)); }

void main() {
  int patchIndex = uFirstPatch + gl_VertexID / uSpan;
  int slot = gl_VertexID - (gl_VertexID / uSpan) * uSpan;
  ivec2 texel = mortonTexel(patchIndex);
  vec4 info = texelFetch(uTrackInfo, texel, 0);
  gl_PointSize = 1.0;
  gl_Position = kCulledPoint;
  if (!(info.a >= 0.0)) return;  // no deposit (also NaN)
  vec3 a0, a1, a2, a3, b0, b1, b2, b3;
  FETCH_CORNERS(uBefore, texel, a0, a1, a2, a3)
  FETCH_CORNERS(uAfter, texel, b0, b1, b2, b3)

  // The voxel box of the support: voxel n (centre n + ½ in continuous voxel coordinates) has a
  // non-zero hat somewhere on [lo, hi] iff lo − 1 < n + ½ < hi + 1, i.e. the integers strictly
  // inside (lo − 1.5, hi + 0.5); at most ⌈hi − lo⌉ + 2 ≤ S of them when hi − lo ≤ maxExtentVoxels.
  // The 8 corners in continuous voxel coordinates, a0..a3 then b0..b3.
  vec3 voxelSize = (uBoundsMax - uBoundsMin) / vec3(uDims);
  vec3 c[8] = vec3[8](a0, a1, a2, a3, b0, b1, b2, b3);
  vec3 lo = vec3(1e30), hi = vec3(-1e30);
  for (int i = 0; i < 8; ++i) {
    c[i] = (c[i] - uBoundsMin) / voxelSize;
    lo = min(lo, c[i]);
    hi = max(hi, c[i]);
  }
  if (any(isnan(lo)) || any(isnan(hi))) return;
  // Clamped first so that far-away corners convert to int safely (the box is clamped to the grid).
  vec3 top = vec3(uDims) + 2.0;
  ivec3 vmin = ivec3(floor(clamp(lo, vec3(-4.0), top) - 1.5)) + 1;
  ivec3 vmax = ivec3(ceil(clamp(hi, vec3(-4.0), top) + 0.5)) - 1;
  vmin = max(vmin, ivec3(0));
  vmax = min(min(vmax, uDims - 1), vmin + uSpan - 1);  // an underestimated bound loses the far end
  int k = vmin.z + slot;
  if (any(greaterThan(vmin, vmax)) || k > vmax.z) return;

  // This slice's own x/y box: only points with z in (k − ½, k + 1½) reach voxel k's hats, so the
  // x/y extent that matters is that of the swept hull cut by that slab. The hull of the 8 corners
  // cut by a slab is a convex polytope whose vertices are corners inside the slab or crossings of
  // the slab's planes by hull edges; every edge is one of the 28 corner pairs, and a pair that is no
  // edge crosses inside the hull, so the box of those points is the box of the cut, exactly. A slanted
  // flight covers a few voxels of its whole box in each slice: the fragments (the pass' cost) shrink.
  // 1e-3 voxel of allowance: float crossings must not shave a voxel whose hat the CPU reaches.
  float zLow = float(k) - 0.5 - 1e-3, zHigh = float(k) + 1.5 + 1e-3;
  vec2 cutLo = vec2(1e30), cutHi = vec2(-1e30);
  for (int i = 0; i < 8; ++i) {
    if (c[i].z >= zLow && c[i].z <= zHigh) {
      cutLo = min(cutLo, c[i].xy);
      cutHi = max(cutHi, c[i].xy);
    }
    for (int j = i + 1; j < 8; ++j) {
      float dz = c[j].z - c[i].z;
      for (int side = 0; side < 2; ++side) {
        float plane = side == 0 ? zLow : zHigh;
        if ((c[i].z - plane) * (c[j].z - plane) < 0.0) {
          vec2 q = mix(c[i].xy, c[j].xy, (plane - c[i].z) / dz);
          cutLo = min(cutLo, q);
          cutHi = max(cutHi, q);
        }
      }
    }
  }
  if (!(cutLo.x <= cutHi.x && cutLo.y <= cutHi.y)) return;  // the hull misses this slice's hats
  cutLo = clamp(cutLo - 1e-3, vec2(-4.0), top.xy);
  cutHi = clamp(cutHi + 1e-3, vec2(-4.0), top.xy);
  vmin.xy = max(vmin.xy, ivec2(floor(cutLo - 1.5)) + 1);
  vmax.xy = min(vmax.xy, ivec2(ceil(cutHi + 0.5)) - 1);
  if (any(greaterThan(vmin.xy, vmax.xy))) return;

  // The lattice (cpu_simulator.cpp subPathLattice): the longer of the two u edges (x₀x₁, x₃x₂) and
  // v edges (x₁x₂, x₀x₃), before or after the step, in units of h.
  float eu = max(max(length(a1 - a0), length(a2 - a3)), max(length(b1 - b0), length(b2 - b3)));
  float ev = max(max(length(a2 - a1), length(a3 - a0)), max(length(b2 - b1), length(b3 - b0)));
  // track_deposit.h trackSpacing: the flux (max channel) against the irradiance bound times the
  // smaller of the two areas.
  float area = min(quadArea(a0, a1, a2, a3), quadArea(b0, b1, b2, b3));
  float spacing = uDimIrradiance > 0.0 && max(info.r, max(info.g, info.b)) < uDimIrradiance * area ? 1.0 : 0.5;
  int nu = trackLattice(eu / uVoxelEdge, spacing), nv = trackLattice(ev / uVoxelEdge, spacing);

  vBefore[0] = voxelCorner(a0, c[0]); vBefore[1] = voxelCorner(a1, c[1]);
  vBefore[2] = voxelCorner(a2, c[2]); vBefore[3] = voxelCorner(a3, c[3]);
  vAfter[0] = voxelCorner(b0, c[4]); vAfter[1] = voxelCorner(b1, c[5]);
  vAfter[2] = voxelCorner(b2, c[6]); vAfter[3] = voxelCorner(b3, c[7]);
  vec3 fluxStart = texelFetch(uBefore[6], texel, 0).rgb, fluxEnd = texelFetch(uAfter[6], texel, 0).rgb;
  vFlux = vec4(info.rgb / float(nu * nv), info.a >= 1.0 && uClipEnabled ? 1.0 : 0.0);
  vDecay = vec4(0.0);
  if (fluxStart != fluxEnd) {
    // cpu_simulator.cpp kMaxTrackDecay, kMeanTrackDecay: up to κ = 10⁻³ the mean is deposited.
    const float kMaxDecay = 50.0, kMeanDecay = 1e-3;
    for (int ch = 0; ch < 3; ++ch)
      vDecay[ch] = fluxStart[ch] > 0.0 && fluxEnd[ch] > 0.0 ? clamp(log(fluxStart[ch] / fluxEnd[ch]), -kMaxDecay, kMaxDecay)
                                                           : (fluxStart[ch] > 0.0 ? kMaxDecay : 0.0);
    if (any(greaterThan(abs(vDecay.xyz), vec3(kMeanDecay)))) {
      vDecay.w = 1.0;
      vFlux.rgb = fluxStart / float(nu * nv);
    } else {
      vDecay = vec4(0.0);
    }
  }
  vBox = ivec4(vmin.xy, vmax.xy);
  ivec2 origin = ivec2((k % ATLAS_TILES_X) * ATLAS_DIMS.x, (k / ATLAS_TILES_X) * ATLAS_DIMS.y);
  vTile = ivec4(origin, k, nu + 32 * nv);

  // One square point of side s covering the box's texels [x0, x1) × [y0, y1) of this tile: its
  // lower corner `start` is an integer, so its edges lie on texel edges and it covers exactly the
  // s × s texels [start, start + s) (fragment centres are never on an edge). GL drops a point whose
  // centre start + s/2 is outside the viewport, so the start is also kept where the centre lies in
  // [½, size − ½] (always possible next to a box inside the atlas, for a side of at least 2 texels).
  int s = max(vmax.x - vmin.x, vmax.y - vmin.y) + 1;
  ivec2 x0 = origin + vmin.xy, x1 = origin + vmax.xy + 1;
  ivec2 size = ivec2(ATLAS_SIZE);
  ivec2 lowest = max(x1 - s, ivec2(-((s - 1) / 2)));
  ivec2 highest = size - 1 - s / 2;
  ivec2 start = max(lowest, min(x0, highest));
  gl_PointSize = float(s);
  vec2 centre = vec2(start) + 0.5 * float(s);
  gl_Position = vec4(centre / ATLAS_SIZE * 2.0 - 1.0, 0.0, 1.0);
}
