// Optics shared by the viewer's ray caster: Fresnel (the shared formula of common/fresnel.glsl with
// the viewer's guard), Henyey–Greenstein (the 3D-normalised form, not Eq. 3.5), the renormalisation
// of w across a boundary layer. Needs common/constants.glsl.
#include "common/fresnel.glsl"

// Unpolarised Fresnel reflectance R = (Rs + Rp) / 2 (corrected Eq. 3.6) going from index n1 into
// n2 at an angle of incidence with cosine cosI (clamped to [0, 1]); 1 beyond the critical angle.
float fresnelReflectance(float n1, float n2, float cosI) {
  cosI = clamp(cosI, 0.0, 1.0);
  float sinT2 = snellSinT2(n1, n2, cosI);
  if (sinT2 >= 1.0) return 1.0;
  return fresnelUnpolarised(n1, n2, cosI, sqrt(1.0 - sinT2));
}

// Henyey–Greenstein phase function, normalised over the sphere: (1 − g²) / (4π (1 + g² − 2g cosθ)^1.5),
// θ the angle between the light's direction of travel and the scattered light's.
float henyeyGreenstein(float g, float cosTheta) {
  float denom = 1.0 + g * g - 2.0 * g * cosTheta;
  return (1.0 - g * g) * INV_FOUR_PI / (denom * sqrt(max(denom, 1e-12)));
}

float maxComponent(vec3 v) { return max(max(v.x, v.y), v.z); }

// w rescaled to |w| = n (docs/physics.md: an exact ray keeps |w| = n). The correction goes along ∇n, the
// direction in which the ray equation changes w (Eq. 5.12), so the component of w across ∇n is
// kept: in a layered medium that component is n·sin θ, and keeping it is Snell's law exactly.
// Where it cannot (at the turning point of a total internal reflection, where the step overshot
// into n < |w across|), w is left as it is: the next steps turn it round with n·sin θ intact.
vec3 renormalised(vec3 w, float n, vec3 gradN) {
  // Branch-free (selects, no early returns): llvmpipe runs this every step of every ray.
  float g2 = dot(gradN, gradN);
  vec3 normal = gradN * inversesqrt(max(g2, 1e-30));
  float along = dot(w, normal);
  vec3 across = w - along * normal;
  float rest = n * n - dot(across, across);
  vec3 keepAcross = across + normal * ((along >= 0.0 ? 1.0 : -1.0) * sqrt(max(rest, 0.0)));
  vec3 kept = rest > 0.0 ? keepAcross : w;
  return g2 > 1e-12 ? kept : w * (n * inversesqrt(max(dot(w, w), 1e-30)));
}
