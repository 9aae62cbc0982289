// The GPU patch list (ALGORITHM.md "Patch state", lightsim/patch_textures.h): eight RGBA32F
// textures, patch k at texel mortonTexel(k):
//   [0..3] P0..P3 = (x_c, w_c.x)   [4] W01 = (w0.yz, w1.yz)   [5] W23 = (w2.yz, w3.yz)
//   [6] FLUX = (Φ.rgb, A0)         [7] META = (depth, n_in, cos_in, T_fresnel)
// With SHARP_INTERFACES META holds the sharp-interface state instead (patch_textures.h):
//   META = (depth + 64·(reflections + 256·bounce), Σ (medium_c + 1)·8^c + 4096·crossed + 65536·reflected,
//           reflect_pending, T_fresnel + 2·event)
// where `event` is what the update pass tells the analysis about this step (SHARP_EVENT_*).
// A list is read through a sampler array `uniform sampler2D NAME[8];` indexed with constants only
// (GLSL 3.30 cannot index sampler arrays with a variable, docs/architecture.md): FETCH_PATCH(NAME, texel, p).

struct Patch {
  vec3 x[4];     // corner positions (world)
  vec3 w[4];     // corner directions, |w_c| = n(x_c)
  vec3 flux;     // Φ (W, RGB)
  float area0;   // A0
  float depth;   // splits since initialisation
  float nIn;     // boundary tracking: n before the layer, 0 outside a layer
  float cosIn;   // |cos| of the incidence angle on entering the layer
  float tFresnel;  // transmitted fraction of the last step (1 when no boundary was left)
#ifdef SHARP_INTERFACES
  int medium[4];         // material slot of each corner (−1: air)
  int crossed;           // corners (bits 0–3) through the crossing in progress
  int reflected;         // corners (bits 0–3) totally reflected at the reflection in progress
  float reflectPending;  // fraction of the flux reflected at that crossing
  int bounce;            // reflections this wavefront came through
  int reflections;       // total internal reflections of its corners so far
  int event;             // this step's events for the analysis (SHARP_EVENT_*; 0 in a stored list)
#endif
};

#ifdef SHARP_INTERFACES
// Events of a step (update.frag → analysis.frag): the step was undone and the patch must split
// along u and/or v before it crosses; torn at the depth limit (it dies); 8 × the corners an opaque
// surface stopped.
const int SHARP_EVENT_SPLIT_U = 1;
const int SHARP_EVENT_SPLIT_V = 2;
const int SHARP_EVENT_TORN = 4;
const int SHARP_EVENT_BLOCKED = 8;
// With SHARP_EVENT_TORN: the mask of the corners that met the surface, times this (bits 6–9; the
// blocked count, 8 per corner, stays below it).
const int SHARP_EVENT_MET_UNIT = 64;
void unpackSharpMeta(vec4 m, inout Patch p) {
  float rest = floor(m.x / 64.0);
  p.depth = m.x - 64.0 * rest;
  p.bounce = int(rest) / 256;
  p.reflections = int(rest) - 256 * p.bounce;
  int media = int(m.y + 0.5);
  for (int c = 0; c < 4; ++c) p.medium[c] = ((media >> (3 * c)) & 7) - 1;
  p.crossed = (media >> 12) & 15;
  p.reflected = (media >> 16) & 15;
  p.reflectPending = m.z;
  float e = floor(m.w / 2.0);
  p.event = int(e);
  p.tFresnel = m.w - 2.0 * e;
  p.nIn = 0.0;
  p.cosIn = 0.0;
}
vec4 packSharpMeta(Patch p) {
  int media = 0;
  for (int c = 0; c < 4; ++c) media |= (p.medium[c] + 1) << (3 * c);
  media |= p.crossed << 12;
  media |= p.reflected << 16;
  return vec4(p.depth + 64.0 * float(min(p.reflections, 255) + 256 * p.bounce), float(media), p.reflectPending,
              p.tFresnel + 2.0 * float(p.event));
}
#define UNPACK_META(m, p) unpackSharpMeta(m, p)
#else
#define UNPACK_META(m, p) \
  { p.depth = m.x; p.nIn = m.y; p.cosIn = m.z; p.tFresnel = m.w; }
#endif


// The split length of patch p for the run's split length `base`: reflected wavefronts (bounce ≥ 1)
// split at kReflectedSplitFactor times it (wavefront.h).
const float kReflectedSplitFactor = 4.0;
float splitLengthOf(Patch p, float base) {
#ifdef SHARP_INTERFACES
  return p.bounce > 0 ? kReflectedSplitFactor * base : base;
#else
  return base;
#endif
}

// Morton (Z-order) index ↔ texel: x from the even bits, y from the odd bits (patch_textures.h).
int mortonCompact1By1(int v) {
  v &= 0x55555555;
  v = (v ^ (v >> 1)) & 0x33333333;
  v = (v ^ (v >> 2)) & 0x0f0f0f0f;
  v = (v ^ (v >> 4)) & 0x00ff00ff;
  v = (v ^ (v >> 8)) & 0x0000ffff;
  return v;
}
int mortonPart1By1(int v) {
  v &= 0x0000ffff;
  v = (v ^ (v << 8)) & 0x00ff00ff;
  v = (v ^ (v << 4)) & 0x0f0f0f0f;
  v = (v ^ (v << 2)) & 0x33333333;
  v = (v ^ (v << 1)) & 0x55555555;
  return v;
}
ivec2 mortonTexel(int index) { return ivec2(mortonCompact1By1(index), mortonCompact1By1(index >> 1)); }
int mortonIndex(ivec2 texel) { return mortonPart1By1(texel.x) | (mortonPart1By1(texel.y) << 1); }

#define FETCH_PATCH(S, texel, p)                                                   \
  {                                                                                \
    vec4 t0_ = texelFetch(S[0], texel, 0), t1_ = texelFetch(S[1], texel, 0);       \
    vec4 t2_ = texelFetch(S[2], texel, 0), t3_ = texelFetch(S[3], texel, 0);       \
    vec4 t4_ = texelFetch(S[4], texel, 0), t5_ = texelFetch(S[5], texel, 0);       \
    vec4 t6_ = texelFetch(S[6], texel, 0), t7_ = texelFetch(S[7], texel, 0);       \
    p.x[0] = t0_.xyz; p.x[1] = t1_.xyz; p.x[2] = t2_.xyz; p.x[3] = t3_.xyz;        \
    p.w[0] = vec3(t0_.w, t4_.xy); p.w[1] = vec3(t1_.w, t4_.zw);                    \
    p.w[2] = vec3(t2_.w, t5_.xy); p.w[3] = vec3(t3_.w, t5_.zw);                    \
    p.flux = t6_.xyz; p.area0 = t6_.w;                                             \
    UNPACK_META(t7_, p);                                                           \
  }

// Only the corner positions (P0..P3).
#define FETCH_CORNERS(S, texel, x0, x1, x2, x3)                                    \
  {                                                                                \
    x0 = texelFetch(S[0], texel, 0).xyz; x1 = texelFetch(S[1], texel, 0).xyz;       \
    x2 = texelFetch(S[2], texel, 0).xyz; x3 = texelFetch(S[3], texel, 0).xyz;       \
  }

// The eight texels of a patch, for the MRT outputs of update and compaction.
void packPatch(Patch p, out vec4 t[8]) {
  t[0] = vec4(p.x[0], p.w[0].x);
  t[1] = vec4(p.x[1], p.w[1].x);
  t[2] = vec4(p.x[2], p.w[2].x);
  t[3] = vec4(p.x[3], p.w[3].x);
  t[4] = vec4(p.w[0].yz, p.w[1].yz);
  t[5] = vec4(p.w[2].yz, p.w[3].yz);
  t[6] = vec4(p.flux, p.area0);
#ifdef SHARP_INTERFACES
  t[7] = packSharpMeta(p);
#else
  t[7] = vec4(p.depth, p.nIn, p.cosIn, p.tFresnel);
#endif
}

// Derived quantities (ALGORITHM.md "Patch state").
vec3 patchMidpoint(Patch p) { return 0.25 * (p.x[0] + p.x[1] + p.x[2] + p.x[3]); }
vec3 patchDirection(Patch p) { return normalize(p.w[0] + p.w[1] + p.w[2] + p.w[3]); }
// Area vector N = ½ (x2 − x0) × (x3 − x1), along the propagation for a well-oriented patch.
vec3 areaVector(vec3 x0, vec3 x1, vec3 x2, vec3 x3) { return 0.5 * cross(x2 - x0, x3 - x1); }
vec3 patchAreaVector(Patch p) { return areaVector(p.x[0], p.x[1], p.x[2], p.x[3]); }
float lum(vec3 c) { return (c.r + c.g + c.b) / 3.0; }
