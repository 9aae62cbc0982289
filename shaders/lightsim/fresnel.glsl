// The light simulator's Fresnel reflectance: the shared unpolarised formula (common/fresnel.glsl,
// the corrected Eq. 3.6) with this program's guards, and its rule for a boundary layer.
#include "common/fresnel.glsl"

// R going from index ni into nt at an angle of incidence with cosine |cosI|; 1 beyond the critical
// angle, and where the indices make a denominator vanish.
float fresnelReflectance(float ni, float nt, float cosI) {
  cosI = min(abs(cosI), 1.0);
  float sinT2 = snellSinT2(ni, nt, cosI);
  if (sinT2 >= 1.0) return 1.0;
  float cosT = sqrt(1.0 - sinT2);
  if (ni * cosI + nt * cosT <= 0.0 || ni * cosT + nt * cosI <= 0.0) return 1.0;
  return fresnelUnpolarised(ni, nt, cosI, cosT);
}

// The reflectance a patch gets on leaving a boundary layer (ALGORITHM.md step 3 as the CPU twin
// implements it, lightsim/wavefront.h boundaryReflectance):
//  1. |n_out − n_in| < tolerance (g_off): no interface was crossed (the patch skimmed the layer or
//     was turned back by total internal reflection): R = 0;
//  2. otherwise R on the side of lower index: R(n_in → n_out, cos_in) when n_in ≤ n_out (or when
//     cos_out < 0, i.e. ∇n = 0 where the patch left), else R(n_out → n_in, cos_out) (reciprocity).
float boundaryReflectance(float nIn, float cosIn, float nOut, float cosOut, float tolerance) {
  if (abs(nOut - nIn) < tolerance) return 0.0;
  if (nIn <= nOut || cosOut < 0.0) return fresnelReflectance(nIn, nOut, cosIn);
  return fresnelReflectance(nOut, nIn, cosOut);
}
