// The unpolarised Fresnel equations (docs/physics.md: the corrected thesis Eq. 3.6), the one home
// of the formula for the viewer (viewer/optics.glsl) and the light simulator (lightsim/fresnel.glsl);
// each wraps it in its own guards and boundary rule:
//   R = (Rs + Rp) / 2,  Rs = ((ni cos θi − nt cos θt) / (ni cos θi + nt cos θt))²,
//                       Rp = ((ni cos θt − nt cos θi) / (ni cos θt + nt cos θi))²,
//   R = 1 beyond the critical angle, where Snell's law gives sin²θt ≥ 1.

// sin²θt by Snell's law (ni sin θi = nt sin θt) for cos θi = cosI; ≥ 1: total internal reflection.
float snellSinT2(float ni, float nt, float cosI) {
  float eta = ni / nt;
  return eta * eta * (1.0 - cosI * cosI);
}

// R = (Rs + Rp) / 2 from the cosines of incidence and transmission (below the critical angle).
float fresnelUnpolarised(float ni, float nt, float cosI, float cosT) {
  float rs = (ni * cosI - nt * cosT) / (ni * cosI + nt * cosT);
  float rp = (ni * cosT - nt * cosI) / (ni * cosT + nt * cosI);
  return 0.5 * (rs * rs + rp * rp);
}
