// Unpolarised Fresnel reflectance (seeds/README.md, the corrected Eq. 3.6):
// R = (Rs + Rp)/2, Rs = ((ni cos θi − nt cos θt)/(ni cos θi + nt cos θt))²,
// Rp = ((ni cos θt − nt cos θi)/(ni cos θt + nt cos θi))², R = 1 beyond the critical angle.
float fresnelReflectance(float ni, float nt, float cosI) {
  cosI = min(abs(cosI), 1.0);
  float eta = ni / nt;
  float sinT2 = eta * eta * (1.0 - cosI * cosI);
  if (sinT2 >= 1.0) return 1.0;
  float cosT = sqrt(1.0 - sinT2);
  float rsDen = ni * cosI + nt * cosT, rpDen = ni * cosT + nt * cosI;
  if (rsDen <= 0.0 || rpDen <= 0.0) return 1.0;
  float rs = (ni * cosI - nt * cosT) / rsDen;
  float rp = (ni * cosT - nt * cosI) / rpDen;
  return 0.5 * (rs * rs + rp * rp);
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
