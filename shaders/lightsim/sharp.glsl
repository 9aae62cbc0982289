// Sharp interfaces in the light simulator's shaders (ALGORITHM.md "Sharp interfaces"; the GPU twin
// of lightsim/interface_crossing.h, core/interfaces.h): the slot distances, the material of a
// point, n and ∇n inside a material, the interface's normal, the crossing of a chord, Snell's law
// with the exact Fresnel R, one corner's step across interfaces, and the reflected wavefront.
// Every function follows its CPU namesake line by line, in float. Needs common/volume.glsl,
// lightsim/grid.glsl and lightsim/fresnel.glsl, and the defines INTEGRATOR_*.

const int kMaxCrossingsPerStep = 4;  // interface_crossing.h

// The slot table (core/interfaces.h InterfaceTable; lightsim/interface_uniforms.h).
uniform int uSlotCount;
uniform float uSlotIor[4];
uniform int uSlotGraded;  // bit k: slot k takes n and ∇n from the ior / ior_grad fields
uniform int uSlotOpaque;  // bit k: slot k stops light
#ifdef MATERIAL_ABSORPTION
uniform vec3 uSlotSigmaA[4];  // σa per material (VolumeSampler::absorptionPerMaterial)
#ifdef AIR_BOX
// Smoke in the air (core/interfaces.h airMediumBox; AIR_BOX_LO, AIR_BOX_HI grid-local, AIR_SIGMA_A).
#include "common/box.glsl"
vec3 materialSigmaA(int slot) { return slot >= 0 ? uSlotSigmaA[slot] : AIR_SIGMA_A; }
#else
vec3 materialSigmaA(int slot) { return slot >= 0 ? uSlotSigmaA[slot] : vec3(0.0); }
#endif
// ∫σa ds along the straight piece a → b of `len` in material `slot`: in air only the share of it
// inside the smoke's box (VolumeSampler::pieceOpticalDepth).
vec3 pieceOpticalDepth(int slot, vec3 a, vec3 b, float len) {
#ifdef AIR_BOX
  if (slot < 0) return AIR_SIGMA_A * (len * boxShare(a, b, AIR_BOX_LO, AIR_BOX_HI));
#endif
  return materialSigmaA(slot) * len;
}
#endif

// The slot distances d_k at x (trilinear, clamp to edge; unused slots read +band).
vec4 sampleDistances(vec3 x) {
#if defined(EXACT_TRILINEAR) && defined(HAS_INTERFACES)
  return exactTrilinear(INTERFACES_SAMPLER, gridUvw(x)).INTERFACES_SWZ;
#else
  return volumeInterfaces(gridUvw(x));
#endif
}

// The first slot whose distance is negative (innermost wins), −1 for air (core/interfaces.h).
int materialSlot(vec4 d) {
  for (int k = 0; k < 4; ++k)
    if (k < uSlotCount && d[k] < 0.0) return k;
  return -1;
}
int materialAt(vec3 x) { return materialSlot(sampleDistances(x)); }
bool slotOpaque(int slot) { return slot >= 0 && ((uSlotOpaque >> slot) & 1) != 0; }

// (n, ∇n) inside material `slot` at x: air (1, 0), a homogeneous slot (n_k, 0), a graded slot
// the ior / ior_grad fields (VolumeSampler::materialOptics).
vec4 materialOptics(int slot, vec3 x) {
  if (slot < 0) return vec4(1.0, 0.0, 0.0, 0.0);
  if (((uSlotGraded >> slot) & 1) == 0) return vec4(uSlotIor[slot], 0.0, 0.0, 0.0);
  return vec4(sampleIor(x), sampleIorGrad(x));
}

// The unit outward normal ∇d_k by central differences of half a voxel (VolumeSampler::
// interfaceNormal); 0 where the distance is flat.
vec3 interfaceNormal(int slot, vec3 x) {
  vec3 h = 0.5 / (uInvExtent * vec3(uDims));
  vec3 g;
  for (int a = 0; a < 3; ++a) {
    vec3 e = vec3(0.0);
    e[a] = h[a];
    g[a] = (sampleDistances(x + e)[slot] - sampleDistances(x - e)[slot]) / (2.0 * h[a]);
  }
  float len = length(g);
  return len > 0.0 ? g / len : vec3(0.0);
}

// The material just past slot k's surface at p, going along dir (entering it when `inside`).
int materialBeyond(vec3 p, vec3 dir, int k, bool inside) {
  vec4 d = sampleDistances(p + (0.1 * uVoxelEdge) * dir);
  d[k] = inside ? -1.0 : 1.0;
  return materialSlot(d);
}

// The crossing of an interface on the chord a → b from material `from` (findInterface): the
// fraction f, the slot of the surface and the material entered. False when b is still in `from`.
bool findInterface(vec3 a, vec3 b, int from, out float fraction, out int slot, out int entered) {
  fraction = 1.0;
  slot = -1;
  entered = -1;
  vec4 da = sampleDistances(a), db = sampleDistances(b);
  int endSlot = materialSlot(db);
  if (endSlot == from) return false;
  float fs[4];
  int ks[4];
  int count = 0;
  for (int k = 0; k < 4; ++k) {
    if (k >= uSlotCount) break;
    bool inA = da[k] < 0.0, inB = db[k] < 0.0;
    if (inA == inB) continue;
    // Regula falsi on the distance along the chord, two refinements.
    float f0 = 0.0, f1 = 1.0, g0 = da[k], g1 = db[k];
    float f = g0 / (g0 - g1);
    for (int it = 0; it < 2; ++it) {
      float g = sampleDistances(a + f * (b - a))[k];
      if ((g < 0.0) == (g0 < 0.0)) {
        f0 = f;
        g0 = g;
      } else {
        f1 = f;
        g1 = g;
      }
      f = g0 == g1 ? 0.5 * (f0 + f1) : f0 + (f1 - f0) * g0 / (g0 - g1);
    }
    // Insertion in order of (f, k).
    int i = count++;
    while (i > 0 && (fs[i - 1] > f || (fs[i - 1] == f && ks[i - 1] > k))) {
      fs[i] = fs[i - 1];
      ks[i] = ks[i - 1];
      --i;
    }
    fs[i] = f;
    ks[i] = k;
  }
  vec3 dir = normalize(b - a);
  for (int i = 0; i < 4; ++i) {
    if (i >= count) break;
    int beyond = materialBeyond(a + fs[i] * (b - a), dir, ks[i], !(da[ks[i]] < 0.0));
    if (beyond == from) continue;
    fraction = fs[i];
    slot = ks[i];
    entered = beyond;
    return true;
  }
  // The corner sits on a surface it just crossed: the crossing is here.
  fraction = 0.0;
  slot = from >= 0 ? from : endSlot;
  entered = endSlot;
  return slot >= 0;
}

// Snell's law and the Fresnel R for a ray along unit d at a surface of unit normal `normal` from
// n1 into n2 (refract): the new unit direction; true for total internal reflection (R = 1, the
// mirror direction).
bool refractAt(vec3 d, vec3 normal, float n1, float n2, out vec3 direction, out float reflectance) {
  vec3 nf = dot(d, normal) < 0.0 ? normal : -normal;  // against the ray
  float cosI = min(1.0, -dot(d, nf));
  float eta = n1 / n2;
  float sin2T = eta * eta * max(0.0, 1.0 - cosI * cosI);
  if (sin2T >= 1.0) {
    reflectance = 1.0;
    direction = normalize(d + 2.0 * cosI * nf);
    return true;
  }
  float cosT = sqrt(1.0 - sin2T);
  direction = normalize(eta * d + (eta * cosI - cosT) * nf);
  reflectance = fresnelReflectance(n1, n2, cosI);
  return false;
}

// One step of the ray equation (Eq. 4.12/4.13: dx/dt = w/n², dw/dt = ∇n/n) inside material
// `medium`, without crossing (Euler: Eq. 6.1/6.2; RK2 midpoint; RK4).
void materialRhs(vec3 x, vec3 w, int medium, out vec3 dx, out vec3 dw) {
  vec4 s = materialOptics(medium, x);
  dx = w / (s.x * s.x);
  dw = s.yzw / s.x;
}
void materialStep(inout vec3 x, inout vec3 w, float dt, int medium) {
  vec3 k1x, k1w;
  materialRhs(x, w, medium, k1x, k1w);
#if defined(INTEGRATOR_RK4)
  vec3 k2x, k2w, k3x, k3w, k4x, k4w;
  materialRhs(x + 0.5 * dt * k1x, w + 0.5 * dt * k1w, medium, k2x, k2w);
  materialRhs(x + 0.5 * dt * k2x, w + 0.5 * dt * k2w, medium, k3x, k3w);
  materialRhs(x + dt * k3x, w + dt * k3w, medium, k4x, k4w);
  x += (dt / 6.0) * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
  w += (dt / 6.0) * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
#elif defined(INTEGRATOR_RK2)
  vec3 k2x, k2w;
  materialRhs(x + 0.5 * dt * k1x, w + 0.5 * dt * k1w, medium, k2x, k2w);
  x += dt * k2x;
  w += dt * k2w;
#else
  x += dt * k1x;
  w += dt * k1w;
#endif
}

// What one corner met in one step (CornerCrossings).
struct CornerCrossings {
  int transmitted;      // refractions
  int reflected;        // total internal reflections
  bool blocked;         // stopped at an opaque surface
  float transmittance;  // Π (1 − R) over its refractions
  vec3 opticalDepth;    // ∫σa ds, each chord piece with its material's σa (MATERIAL_ABSORPTION)
};

// The pieces of at most kChordPieceVoxels voxels a chord of `len` is looked at in (chordPieces,
// interface_crossing.h): one for an ordinary straight step; a reflected wavefront's longer steps
// are cut up, so that a chord through a wall thinner than itself still meets it.
const float kChordPieceVoxels = 2.0;
int chordPieces(float len) {
  return int(clamp(ceil(len / (kChordPieceVoxels * uVoxelEdge) - 1e-4), 1.0, 1024.0));
}

// findInterface on the chord a → b in chordPieces equal pieces, nearest first (findInterfaceOnChord);
// the fraction is of the whole chord.
bool findInterfaceOnChord(vec3 a, vec3 b, int from, out float fraction, out int slot, out int entered) {
  int pieces = chordPieces(distance(a, b));
  if (pieces == 1) return findInterface(a, b, from, fraction, slot, entered);
  vec3 piece = (b - a) / float(pieces);
  for (int j = 0; j < pieces; ++j) {
    vec3 end = j + 1 == pieces ? b : a + float(j + 1) * piece;
    if (findInterface(a + float(j) * piece, end, from, fraction, slot, entered)) {
      fraction = (float(j) + fraction) / float(pieces);
      return true;
    }
  }
  return false;
}

// advanceCornerSharp: corner (x, w) in `medium` goes on for Δt = dt, stopping at each interface
// its chord meets (at most kMaxCrossingsPerStep): opaque → stops; past the critical angle →
// mirrored; else refracted by Snell's law, keeping 1 − R.
CornerCrossings advanceCornerSharp(inout vec3 x, inout vec3 w, inout int medium, float dt) {
  CornerCrossings result = CornerCrossings(0, 0, false, 1.0, vec3(0.0));
  float remaining = dt;
  for (int crossing = 0; crossing <= kMaxCrossingsPerStep; ++crossing) {
    if (!(remaining > 0.0)) break;
    vec3 x1 = x, w1 = w;
    materialStep(x1, w1, remaining, medium);
    float f;
    int slot, entered;
    if (crossing == kMaxCrossingsPerStep || !findInterfaceOnChord(x, x1, medium, f, slot, entered) || entered == medium) {
#ifdef MATERIAL_ABSORPTION
      result.opticalDepth += pieceOpticalDepth(medium, x, x1, distance(x, x1));
#endif
      x = x1;
      w = normalize(w1) * materialOptics(medium, x).x;  // |w| = n (ALGORITHM.md step 1)
      return result;
    }
    vec3 p = x + f * (x1 - x);
    remaining *= 1.0 - f;
#ifdef MATERIAL_ABSORPTION
    result.opticalDepth += pieceOpticalDepth(medium, x, p, distance(x, p));
#endif
    x = p;
    vec3 normal = interfaceNormal(slot, p);
    if (slotOpaque(entered)) {
      result.blocked = true;
      return result;
    }
    float n1 = materialOptics(medium, p).x;
    float n2 = materialOptics(entered, p).x;
    vec3 d = normalize(w1);
    if (dot(normal, normal) == 0.0) {  // no usable normal: on into the new material unbent
      medium = entered;
      w = d * n2;
      continue;
    }
    vec3 dir;
    float r;
    if (refractAt(d, normal, n1, n2, dir, r)) {
      ++result.reflected;
      w = dir * n1;
    } else {
      ++result.transmitted;
      result.transmittance *= 1.0 - r;
      medium = entered;
      w = dir * n2;
    }
  }
  return result;
}

// reflectedPatch: the wavefront Fresnel reflection sends back at the interface every corner of p
// has crossed — each corner traced back along its ray to the interface (within `reach`), the
// incident direction recovered by Snell's law in reverse, mirrored, and moved as far along the
// mirror ray as the transmitted corner went ahead. Flux, depth and A₀ are the caller's. False when
// a corner finds no interface behind it.
bool reflectedPatch(Patch p, float reach, out Patch r) {
  r = p;
  for (int c = 0; c < 4; ++c) {
    vec3 x = p.x[c];
    vec3 d = normalize(p.w[c]);
    int medium = p.medium[c];
    // Back along the ray in pieces of at most two voxels, nearest first (interface_crossing.cpp: a
    // long chord through a thin part of the object ends in the corner's own material).
    float f;
    int slot, entered;
    float back_by = -1.0;
    float piece = 2.0 * uVoxelEdge;
    for (float done = 0.0; done < reach && back_by < 0.0; done += piece) {
      float len = min(piece, reach - done);
      if (findInterface(x - done * d, x - (done + len) * d, medium, f, slot, entered)) back_by = done + f * len;
    }
    if (back_by < 0.0 || entered == medium) return false;
    vec3 q = x - back_by * d;
    vec3 normal = interfaceNormal(slot, q);
    if (dot(normal, normal) == 0.0 || slotOpaque(entered)) return false;
    float n2 = materialOptics(medium, q).x, n1 = materialOptics(entered, q).x;
    vec3 back;
    float unused;
    if (refractAt(-d, normal, n2, n1, back, unused)) return false;
    vec3 incident = -back;
    vec3 m = incident - 2.0 * dot(incident, normal) * normal;
    float travelled = back_by * n2 / n1;
    r.x[c] = q + travelled * m;
    r.w[c] = n1 * m;
    r.medium[c] = entered;
  }
  // A mirror turns the corners' order around: swap corners 1 and 3 (N along the propagation).
  vec3 tx = r.x[1]; r.x[1] = r.x[3]; r.x[3] = tx;
  vec3 tw = r.w[1]; r.w[1] = r.w[3]; r.w[3] = tw;
  int tm = r.medium[1]; r.medium[1] = r.medium[3]; r.medium[3] = tm;
  return true;
}

bool oneMedium(Patch p) {
  return p.medium[0] == p.medium[1] && p.medium[1] == p.medium[2] && p.medium[2] == p.medium[3];
}

// n of the material a point is in (the CPU twin's n_mid with sharp interfaces).
float mediumIor(vec3 x) { return materialOptics(materialAt(x), x).x; }
// Step 2's factor exp(−σa(m)·Δs_m), Δs_m = Δt / n(m) with n of m's material (Eq. 4.11).
vec3 sharpAbsorptionFactor(vec3 mOld, float dt) { return exp(-sampleSigmaA(mOld) * (dt / mediumIor(mOld))); }
