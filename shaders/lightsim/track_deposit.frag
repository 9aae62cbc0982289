#version 330 core
// ALGORITHM.md step 4 with the track-length kernel ("Track deposits"; lightsim/track_deposit_pass.h):
// one fragment is one voxel v of one patch-step's box (track_deposit.vert). It walks the patch's
// n_u × n_v sub-paths as applyTrackDeposits (cpu_simulator.cpp) does, and for each adds its share
// to v only: the weight w_v = ∫₀¹ K_v(a + t(b − a)) dt of forEachTrackWeight (track_deposit.h), here
// computed for the one hat K_v, exactly. Additive blending sums the patches:
//   target 0 += (Φ_sub · Σ L·w_v / V_voxel, 0)        irradiance
//   target 1 += (lum(Φ_sub) · Σ (b − a)·w_v, 1)       direction sum (L·d̂ = b − a), one count
#include "lightsim/patch.glsl"

uniform vec3 uBoundsMin;  // the grid in the corners' frame (GridUniforms)
uniform vec3 uBoundsMax;
uniform ivec3 uDims;
uniform float uInvVoxelVolume;  // 1 / V_voxel

flat in vec4 vBefore[4];  // corners: (continuous voxel coordinates, height above the receiver)
flat in vec4 vAfter[4];
flat in vec4 vFlux;   // (Φ_sub, clip at the receiver 1/0)
flat in vec4 vDecay;  // (κ, decays 1/0): Φ(t) = Φ_sub·exp(−κ t) along the step (track_deposit.vert)
flat in ivec4 vBox;   // (i_min, j_min, i_max, j_max) of this slice, inclusive
flat in ivec4 vTile;  // (tile origin x, y, slice k, n_u + 32·n_v)

layout(location = 0) out vec4 oEnergy;
layout(location = 1) out vec4 oDirection;

// The bilinear patch through x₀ = (0,0), x₁ = (1,0), x₂ = (1,1), x₃ = (0,1) (wavefront.h bilinear).
vec4 bilinearPoint(vec4 c0, vec4 c1, vec4 c2, vec4 c3, float u, float v) {
  return ((1.0 - u) * (1.0 - v)) * c0 + (u * (1.0 - v)) * c1 + (u * v) * c2 + ((1.0 - u) * v) * c3;
}

// The trilinear hat of the voxel centred at c (continuous voxel coordinates): Π max(0, 1 − |p − c|).
float hat(vec3 p, vec3 c) {
  vec3 t = max(vec3(0.0), 1.0 - abs(p - c));
  return t.x * t.y * t.z;
}

// A decaying flux (vDecay.w): the step's parameter at t = 1 of the sub-path being integrated (short
// of 1 where the receiver cuts it), so that a node at t lies at gStepAt1·t of the step.
float gStepAt1 = 1.0;

// ∫ K_c over the parameter interval [s0, s1] of p(t) = pa + t·dv, where K_c is a cubic polynomial
// of t (no kink inside): 2-point Gauss–Legendre, exact for cubics, with the nodes of track_deposit.h.
// Per channel, each node weighted by the flux's decay there, exp(−κ·gStepAt1·t) (1 without decay).
vec3 hatPiece(vec3 pa, vec3 dv, vec3 c, float s0, float s1) {
  float len = s1 - s0;
  if (!(len > 0.0)) return vec3(0.0);
  const float kGauss = 0.28867513459481288;  // 1/(2√3): the nodes at ½ ± this
  float sp = s0 + (0.5 - kGauss) * len, sq = s0 + (0.5 + kGauss) * len;
  float hp = hat(pa + sp * dv, c), hq = hat(pa + sq * dv, c);
  if (vDecay.w < 0.5) return vec3(0.5 * len * (hp + hq));
  return 0.5 * len * (hp * exp(-vDecay.xyz * (gStepAt1 * sp)) + hq * exp(-vDecay.xyz * (gStepAt1 * sq)));
}

// forEachTrackWeight's weight for the one voxel centred at c: ∫₀¹ K_c(pa + t·dv) dt. K_c is non-zero
// only where |p − c| < 1 on every axis, a parameter interval [t0, t1]; there each factor 1 − |p − c|
// is linear but for one kink where p = c on that axis. Cut at those ≤ 3 kinks, every piece is a
// cubic, integrated exactly. (The CPU cuts at every plane through voxel centres, which holds these
// cuts; between them both integrate the same polynomial.)
vec3 trackWeight(vec3 pa, vec3 dv, vec3 c) {
  float t0 = 0.0, t1 = 1.0;
  vec3 kink = vec3(1.0);
  for (int axis = 0; axis < 3; ++axis) {
    float r = c[axis] - pa[axis];
    if (dv[axis] == 0.0) {
      if (!(abs(r) < 1.0)) return vec3(0.0);  // the whole path is off this hat's support
      continue;
    }
    float inv = 1.0 / dv[axis];
    float ta = (r - 1.0) * inv, tb = (r + 1.0) * inv;
    t0 = max(t0, min(ta, tb));
    t1 = min(t1, max(ta, tb));
    kink[axis] = r * inv;
  }
  if (!(t1 > t0)) return vec3(0.0);
  kink = clamp(kink, t0, t1);
  // Sort the three kinks (a 3-element network).
  float k0 = min(kink.x, kink.y), k1 = max(kink.x, kink.y), k2 = kink.z;
  float m = min(k1, k2);
  k2 = max(k1, k2);
  k1 = max(k0, m);
  k0 = min(k0, m);
  return hatPiece(pa, dv, c, t0, k0) + hatPiece(pa, dv, c, k0, k1) + hatPiece(pa, dv, c, k1, k2) +
         hatPiece(pa, dv, c, k2, t1);
}

void main() {
  ivec2 ij = ivec2(gl_FragCoord.xy) - vTile.xy;
  // A square point may reach past the box, or into the next tile: not this patch's voxels.
  if (any(lessThan(ij, vBox.xy)) || any(greaterThan(ij, vBox.zw))) discard;
  vec3 c = vec3(ivec3(ij, vTile.z)) + 0.5;  // the voxel's centre
  vec3 voxelSize = (uBoundsMax - uBoundsMin) / vec3(uDims);
  int nu = vTile.w % 32, nv = vTile.w / 32;
  bool clip = vFlux.w > 0.5;
  vec3 sumLength = vec3(0.0);     // Σ L·w_v over the sub-paths (per channel: w_v holds the decay)
  vec3 sumDirection = vec3(0.0);  // Σ (b − a)·w_v (world), w_v by luminance with a decay
  for (int iv = 0; iv < nv; ++iv) {
    float v = (float(iv) + 0.5) / float(nv);
    for (int iu = 0; iu < nu; ++iu) {
      float u = (float(iu) + 0.5) / float(nu);
      vec4 a = bilinearPoint(vBefore[0], vBefore[1], vBefore[2], vBefore[3], u, v);
      vec4 b = bilinearPoint(vAfter[0], vAfter[1], vAfter[2], vAfter[3], u, v);
      vec3 pa = a.xyz, pb = b.xyz;
      gStepAt1 = 1.0;
      if (clip) {
        // The receiver: a sub-path already on or under the plane deposits nothing, one that crosses
        // it stops there (applyTrackDeposits; a.w, b.w are the heights of its ends).
        if (a.w <= 0.0) continue;
        if (b.w < 0.0) {
          gStepAt1 = a.w / (a.w - b.w);
          pb = pa + gStepAt1 * (pb - pa);
        }
      }
      vec3 dv = pb - pa;
      vec3 d = dv * voxelSize;  // b − a in the world
      float len = length(d);
      if (!(len > 0.0)) continue;
      vec3 w = trackWeight(pa, dv, c);
      sumLength += len * w;
      sumDirection += d * (vDecay.w < 0.5 ? w.x : lum(vFlux.rgb * w));
    }
  }
  if (!(max(sumLength.x, max(sumLength.y, sumLength.z)) > 0.0)) discard;  // this voxel's hat missed every sub-path
  oEnergy = vec4(vFlux.rgb * (sumLength * uInvVoxelVolume), 0.0);
  oDirection = vec4((vDecay.w < 0.5 ? lum(vFlux.rgb) : 1.0) * sumDirection, 1.0);
}
