#version 330 core
// The viewer's ray caster (thesis §5 image formation, §6.3 view renderer): one curved viewing ray
// per pixel, from the eye through every object it meets, then the ground plane or the
// environment. Along the ray, Eq. 5.10 with L_c = ω̂·L_s + δ·R·L_r + L_e:
//   L = Σ T(s)·L_c(s)·Δs + T(s_e)·L(x_e),
// T the product of Beer–Lambert attenuation exp(−∫σa ds) (per channel) and the Fresnel
// transmissions at the boundaries crossed. Objects are found along the ray, nearest box first: a
// ray leaving one object continues into the next one it meets (so one is seen through another).
// With DISPERSION, R, G and B follow their own rays at λ = 0.61, 0.55, 0.465 µm (thesis §3.2.7), or
// with DISPERSION_BANDS N spectral bands, each weighted by its share of R, G and B.
//
// Defines (viewer/raymarch_shader.h): OBJECT_COUNT, MAX_SEGMENTS, LIGHT_COUNT; GROUND, FRESNEL, ATTENUATION,
// EMISSION, SCATTERING, DISPERSION, NO_REFRACTION, RK4; OUTPUT_EXIT_POSITION, OUTPUT_EXIT_DIRECTION;
// the environment's ENV_*.
#include "common/constants.glsl"
#include "common/box.glsl"
#include "viewer/optics.glsl"
#include "viewer/environment.glsl"

uniform mat4 uInvViewProj;  // clip → world
uniform vec3 uEye;          // world

// Per object: placement, its volume box and the box of its non-trivial region (volume space).
uniform mat4 uObjWorldToVol[OBJECT_COUNT];   // M⁻¹ (§6.3.1)
uniform mat4 uObjVolToWorld[OBJECT_COUNT];   // M
uniform vec3 uObjBoundsMin[OBJECT_COUNT];
uniform vec3 uObjBoundsMax[OBJECT_COUNT];
uniform vec3 uObjActiveMin[OBJECT_COUNT];    // rays march only here (n = 1 and nothing else outside)
uniform vec3 uObjActiveMax[OBJECT_COUNT];
uniform vec3 uObjHalfVoxel[OBJECT_COUNT];    // half a voxel in texture coordinates
uniform vec3 uObjAbsorbingMin[OBJECT_COUNT]; // the box where σa > 0 (volume space; empty: min > max)
uniform vec3 uObjAbsorbingMax[OBJECT_COUNT];
uniform float uObjStep[OBJECT_COUNT];        // arc length per step, volume units
uniform int uObjMaxSteps[OBJECT_COUNT];
uniform float uObjBoundaryGrad[OBJECT_COUNT];  // |∇n| above which the ray is in a boundary layer
uniform vec3 uObjBrickSize[OBJECT_COUNT];    // a homogeneity brick's extent, volume units
uniform float uObjLengthScale[OBJECT_COUNT];  // world units per volume unit: the object's scale (σa, L_e per world unit)
// The object's receiver map of the ground (HAS_RECEIVER; core/receiver_map.h), volume space: the
// plane's point and in-plane axes, the map's corner (u, v) and extent, and the light it was baked
// with (w = 0: direction it travels, w = 1: position; its irradiance or intensity).
uniform vec3 uObjRecvPoint[OBJECT_COUNT];
uniform vec3 uObjRecvU[OBJECT_COUNT];
uniform vec3 uObjRecvV[OBJECT_COUNT];
uniform vec2 uObjRecvOrigin[OBJECT_COUNT];
uniform vec2 uObjRecvSize[OBJECT_COUNT];
uniform vec4 uObjRecvLightPos[OBJECT_COUNT];
uniform vec3 uObjRecvLightPower[OBJECT_COUNT];
uniform vec4 uObjRecvLightSpot[OBJECT_COUNT];        // a spot light's axis and cos θ_outer
uniform float uObjRecvLightSpotScale[OBJECT_COUNT];  // 1/(cos θ_inner − cos θ_outer); 0: not a spot

uniform float uMinTransmittance;  // early termination
uniform float uMaxOpticalDepth;   // −ln(uMinTransmittance)
uniform float uPixelSpread;       // radians between neighbouring pixels' rays
uniform float uEnvLodBias;
uniform float uReflectionLod;     // mip level of reflection lookups
uniform vec3 uAmbientRadiance;    // the environment's diffuse radiance on an upward surface, per unit albedo

#if LIGHT_COUNT > 0
uniform vec4 uLightPos[LIGHT_COUNT];    // w = 0: direction the light travels; w = 1: position
uniform vec3 uLightPower[LIGHT_COUNT];  // irradiance (directional) or intensity (point, spot on its axis)
uniform vec4 uLightSpot[LIGHT_COUNT];   // a spot light's axis and cos θ_outer (core/scene.h spotCone)
uniform float uLightSpotScale[LIGHT_COUNT];  // 1/(cos θ_inner − cos θ_outer); 0: not a spot
#endif

#ifdef GROUND
uniform vec3 uGroundPoint;
uniform vec3 uGroundNormal;
uniform vec3 uGroundAxisU;        // unit, in the plane
uniform vec3 uGroundAxisV;
uniform float uGroundHalfExtent;
uniform vec3 uGroundAlbedo;
uniform vec3 uGroundAmbient;      // albedo × the environment's diffuse radiance on the ground
#ifdef GROUND_MAP
// The ground map (viewer/ground_map.h): every object's receiver map's change (rgb) summed on one
// lattice of the ground's plane (axes uGroundAxisU/V from uGroundPoint), a = 1 where a map reaches.
uniform sampler2D uGroundMap;
uniform vec2 uGroundMapOrigin;    // (u, v) of its corner
uniform vec2 uGroundMapSize;      // its extent in u and v
#endif
#endif

in vec2 vUv;
out vec4 outColor;

struct Ray {
  vec3 x;         // world position
  vec3 d;         // world direction, unit
  vec3 radiance;  // gathered so far
  vec3 T;         // transmittance so far (Beer–Lambert × Fresnel)
  bool done;      // ended on an opaque surface, the ground, or absorbed
  bool grounded;  // ended on the ground at x: trace adds groundWeight·groundRadiance(x) once,
  vec3 groundWeight;  // after the objects (one place in the program that shades the ground)
  bool entered;   // went through a volume
  bool dispersed; // went through a volume with a dispersion field (DISPERSION: its path depends on λ)
  vec3 exitX;     // world position where it last left a volume
  uint path;      // a hash of the objects it met and of each event on its way and the material it
                  // left it in: two wavelengths with the same hash took the same way (DISPERSION_BANDS)
};

// Irradiance from the scene's lights at x on a surface of normal N, nothing in the way.
// Planar irradiance at x on a surface of normal N from one light (w = 0: directional, its
// irradiance; w = 1: point, its intensity), unoccluded: E·cos θ, or I·cos θ/r².
// A light's irradiance at x on a surface of normal N; a spot light's (spotScale > 0) with glTF's
// cone, clamp((axis·d − cos θ_outer)·scale, 0, 1)² (core/scene.h spotAttenuation).
vec3 lightIrradiance(vec4 pos, vec3 power, vec4 spot, float spotScale, vec3 x, vec3 N) {
  if (pos.w == 0.0) return power * max(0.0, -dot(N, pos.xyz));
  vec3 L = pos.xyz - x;
  float r2 = max(dot(L, L), 1e-12);
  float cone = 1.0;
  if (spotScale > 0.0) {
    float t = clamp((dot(spot.xyz, -L * inversesqrt(r2)) - spot.w) * spotScale, 0.0, 1.0);
    cone = t * t;
  }
  return power * (cone * max(0.0, dot(N, L) * inversesqrt(r2)) / r2);
}

vec3 unoccludedIrradiance(vec3 x, vec3 N) {
  vec3 E = vec3(0.0);
#if LIGHT_COUNT > 0
  for (int i = 0; i < LIGHT_COUNT; ++i)
    E += lightIrradiance(uLightPos[i], uLightPower[i], uLightSpot[i], uLightSpotScale[i], x, N);
#endif
  return E;
}

#ifdef GROUND
bool onGround(vec3 xw) {
  vec3 q = xw - uGroundPoint;
  return abs(dot(q, uGroundAxisU)) <= uGroundHalfExtent && abs(dot(q, uGroundAxisV)) <= uGroundHalfExtent;
}

// Distance along the ray to the ground, seen from above; a huge number when it misses.
float groundDistance(vec3 x, vec3 d) {
  float height = dot(x - uGroundPoint, uGroundNormal);
  float dn = dot(d, uGroundNormal);
  if (height <= 0.0 || dn >= 0.0) return 1e30;
  float t = -height / dn;
  return onGround(x + t * d) ? t : 1e30;
}

vec3 groundRadiance(vec3 xw);  // after the objects: it asks each one for its baked irradiance
const float kGroundBlendVoxels = 3.0;  // the bake fades into the unoccluded light over this margin
#endif

// What ends a run of ordinary steps in an object's march: the ray met something costly to handle.
// The handlers run after the step loop, once per event. Inside it they were the tail of a step
// that most lanes had left by an early return, and llvmpipe (which skips an if-block no lane of
// its 8-wide vector takes) runs such a tail for every lane, masked: at every step of every ray.
const int EVENT_NONE = 0;      // out of steps, absorbed, or stopped
const int EVENT_GROUND = 1;    // the last step crossed the ground from above
const int EVENT_LEFT = 2;      // the ray is out of the active region (or the box)
const int EVENT_CROSSING = 3;  // the last step changed the material (HAS_INTERFACES)
const int EVENT_OPAQUE = 4;    // an opaque embedding is here (HAS_OPAQUE)
// Events one object's march handles at most (the scenes' rays meet at most about 30 per colour
// channel: surfaces crossed, total internal reflections, box faces; 2026-12 measurement).
const int kMaxEventsPerObject = 128;

// One bounce of reflection through the scene (REFLECT_OBJECTS; docs/physics.md "Reflections"):
// the first light an object's outside reflects towards the eye is not looked up in the ground and
// the environment where it happens (each object's branchRadiance) but recorded here, and traced after the
// primary ray as a ray of its own (shade), through the other objects and onto the ground. Every
// other branch, and every branch of that second ray, is looked up where it happens. GLSL has no
// recursion; the second trace is a second call of trace from main's level.
bool gRecordBranch = false;     // the primary ray's trace is on: record its first outside reflection
vec3 gBranchWeight = vec3(0.0);  // its weight (T·R·tint where it left); 0: none recorded
vec3 gBranchX = vec3(0.0);       // where it leaves (world) and where it goes (world, unit)
vec3 gBranchD = vec3(0.0, 1.0, 0.0);
int gBranchObject = -1;          // the object it leaves, which it does not meet again (convex)
Ray gBranchRay;                  // the reflection once traced (done from the start when none)
// The surface the last crossing or reflection met, coarsely: its normal's direction, each component
// in three levels (below −⅓, between, above ⅓; surfaceCode): normals 55° or more apart never share a
// code, so that a ray's way (Ray.path) tells an edge's two faces apart.
uint gSurfaceCode = 0u;
uint surfaceCode(vec3 normal) {
  uvec3 level = uvec3(sign(normal) * step(1.0 / 3.0, abs(normal)) + 1.0);
  return 1u + level.x + 3u * level.y + 9u * level.z;
}
// The first of two passes (DISPERSION_GREEN_PASS) leaves a ray that meets dispersive glass to the
// N bands' pass (DISPERSION_BANDS), which shades every channel of that pixel again: the ray stops
// there, and its reflection is not traced. With three bands green's ray is the green channel.
bool leftToTheBands(Ray r) {
#if defined(DISPERSION_GREEN_PASS) && defined(DISPERSION_BANDS)
  return r.dispersed;
#else
  return false;
#endif
}

// Adds `code` to the ray's way (Ray.path): read only by DISPERSION_BANDS, nothing elsewhere.
void recordWay(inout Ray r, uint code) {
#ifdef DISPERSION_BANDS
  r.path = r.path * 31u + code;
#endif
}
uniform int uTraceLegs;          // 2: the primary ray and its reflection (a uniform: a loop the
                                 // compiler cannot unroll into two copies of what it calls)

#ifdef DISPERSION_BANDS
// The viewer's spectral bands (RenderSettings::bands ≠ 3): the Cauchy term 1/λ² − 1/λ_d² and the
// R, G, B share of each.
uniform int uBandCount;
uniform float uBandCauchy[DISPERSION_BANDS];
uniform vec3 uBandRgb[DISPERSION_BANDS];
// 1: trace the spectrum's two end bands and interpolate the others' rays between them where the two
// took the same way (RenderSettings::interpolate_bands); 0: trace every band.
uniform int uInterpolateBands;
#endif

// Every object's march (march0, march1, ...): viewer/raymarch_shader.cpp puts one instance of
// viewer/object.glsl per object in place of the next line.
// @OBJECTS@

// Object k's march. A line marked EACH_OBJECT is repeated once per object (its index in place of
// each at-sign): GLSL 3.30 cannot pick an object's samplers by a variable index.
void marchObject(int k, inout Ray r, float cauchy) {
  if (k == @) march@(r, cauchy);  // @EACH_OBJECT@
}

#ifdef GROUND
// The baked irradiance of the first object whose volume holds the ground point xw, and its weight.
float bakedGroundIrradiance(vec3 xw, out vec3 E) {
  float weight;
  weight = bakedGroundIrradiance@(xw, E); if (weight > 0.0) return weight;  // @EACH_OBJECT@
  E = vec3(0.0);
  return 0.0;
}

// Lambertian ground: ρE/π (docs/physics.md "Receivers"), plus the environment. E is the scene's
// lights unoccluded, changed by every object whose receiver map covers the point (its map minus
// the direct light it was baked with: its shadow, its caustic, the light it reflects there). A
// volume without a receiver map gives its fluence-like baked irradiance where the ground lies in
// its box (the first release's approximation).
vec3 groundRadiance(vec3 xw) {
  vec3 E = unoccludedIrradiance(xw, uGroundNormal);
  bool mapped = false;
  vec3 change;
#ifdef GROUND_MAP
  // Two or more receiver maps: their sum, one lookup.
  vec3 q = xw - uGroundPoint;
  vec2 st = (vec2(dot(q, uGroundAxisU), dot(q, uGroundAxisV)) - uGroundMapOrigin) / uGroundMapSize;
  if (all(greaterThanEqual(st, vec2(0.0))) && all(lessThanEqual(st, vec2(1.0)))) {
    vec4 sum = texture(uGroundMap, st);
    E += sum.rgb;
    mapped = sum.a > 0.0;
  }
#else
  if (receiverChange@(xw, change)) { E += change; mapped = true; }  // @EACH_OBJECT@
#endif
  if (!mapped) {
    vec3 baked;
    float weight = bakedGroundIrradiance(xw, baked);
    if (weight > 0.0) E = mix(E, baked, weight);
  }
  return uGroundAlbedo * max(E, vec3(0.0)) * INV_PI + uGroundAmbient;
}
#endif

// Follows the ray through the objects it meets, nearest box first, and onto the ground; it starts
// outside object `skip`'s reach (−1: none), as a ray leaving a convex object does. With
// REFLECT_OBJECTS the reflection the ray recorded goes on in its place once it is through, in the
// same loop (one copy of every march in the program), and ends in gBranchRay.
void trace(inout Ray r, float cauchy, int skip) {
  int last = skip;
#ifdef REFLECT_OBJECTS
  Ray primary = r;
  bool second = false;
  gBranchRay = r;
  gBranchRay.done = true;
#endif
  for (int segment = 0; segment < MAX_SEGMENTS; ++segment) {
    float tBest = 1e30;
    int next = -1;
    for (int j = 0; j < OBJECT_COUNT; ++j) {
      if (j == last) continue;  // a straight ray does not come back into a box it left
      vec3 o = (uObjWorldToVol[j] * vec4(r.x, 1.0)).xyz;
      vec3 dv = mat3(uObjWorldToVol[j]) * r.d;  // not normalised: t stays in world units
      float t0, t1;
      if (intersectBox(o, dv, uObjActiveMin[j], uObjActiveMax[j], t0, t1) && max(t0, 0.0) < tBest) {
        tBest = max(t0, 0.0);
        next = j;
      }
    }
#ifdef GROUND
    float tGround = groundDistance(r.x, r.d);
    if (tGround < tBest) {
      r.x += tGround * r.d;
      r.grounded = true;
      r.groundWeight = r.T;
      r.done = true;
    }
#endif
    bool ended = r.done || next < 0;
    if (!ended) {
      recordWay(r, uint(next + 1));
      r.x += tBest * r.d;
      marchObject(next, r, cauchy);
      ended = r.done;
      last = next;
    }
#ifdef REFLECT_OBJECTS
    if (ended && !second && gRecordBranch && dot(gBranchWeight, vec3(1.0)) > 0.0 && !leftToTheBands(r)) {
      // Through: the reflection goes on from where it left, the primary ray waits.
      primary = r;
      second = true;
      gRecordBranch = false;
      r.x = gBranchX;
      r.d = gBranchD;
      r.radiance = vec3(0.0);
      r.T = vec3(1.0);
      r.done = false;
      r.grounded = false;
      r.groundWeight = vec3(0.0);
      last = gBranchObject;
      continue;
    }
#endif
    if (ended) break;
  }
#ifdef REFLECT_OBJECTS
  if (second) {
    gBranchRay = r;
    r = primary;
  }
#endif
#ifdef GROUND
  // The ground's shading, in one place for every way the ray can end on it (llvmpipe's cost grew
  // with each place it was written out: 25 % of the museum's frame): for the ray, and for its
  // reflection (REFLECT_OBJECTS) in a second turn of a loop the compiler cannot unroll.
#ifdef REFLECT_OBJECTS
  for (int leg = 0; leg < uTraceLegs; ++leg) {
    if (!(leg == 0 ? r.grounded : gBranchRay.grounded)) continue;
    vec3 L = (leg == 0 ? r.groundWeight : gBranchRay.groundWeight) * groundRadiance(leg == 0 ? r.x : gBranchRay.x);
    if (leg == 0) r.radiance += L;
    else gBranchRay.radiance += L;
  }
#else
  if (r.grounded) r.radiance += r.groundWeight * groundRadiance(r.x);
#endif
#endif
}

Ray primaryRay() {
  vec4 far = uInvViewProj * vec4(vUv * 2.0 - 1.0, 1.0, 1.0);
  Ray r;
  r.x = uEye;
  r.d = normalize(far.xyz / far.w - uEye);
  r.radiance = vec3(0.0);
  r.T = vec3(1.0);
  r.done = false;
  r.grounded = false;
  r.groundWeight = vec3(0.0);
  r.entered = false;
  r.dispersed = false;
  r.exitX = uEye;
  r.path = 0u;
  return r;
}

// The environment's mip level for the ray's footprint: refracted rays diverge, so their pixel
// covers more of the map (dFdx/dFdy of the exit direction; call in uniform control flow).
float exitLod(Ray r) {
  float spread = max(length(dFdx(r.d)), length(dFdy(r.d)));
  return envLod(max(spread, uPixelSpread)) + uEnvLodBias;
}

// The ray's radiance with the environment in its exit direction at level `lod`.
vec3 finishAt(Ray r, float lod) {
  if (r.done) return r.radiance;
  return r.radiance + r.T * environmentRadiance(r.d, lod);
}

vec3 finish(Ray r) { return finishAt(r, exitLod(r)); }

// A primary ray traced at one wavelength (its Cauchy term) and, with REFLECT_OBJECTS, the one
// reflection it recorded, traced after it; finishShaded adds them (in uniform control flow: finish
// takes derivatives).
struct Shaded {
  Ray r;
  Ray branch;  // done from the start when no reflection was recorded
  vec3 weight;
};

Shaded traceShaded(float cauchy) {
  Shaded s;
  s.r = primaryRay();
#ifdef REFLECT_OBJECTS
  gRecordBranch = true;
  gBranchWeight = vec3(0.0);
  gBranchObject = -1;
#endif
  trace(s.r, cauchy, -1);
#ifdef REFLECT_OBJECTS
  gRecordBranch = false;
  s.branch = gBranchRay;
  s.weight = gBranchWeight;
#else
  s.branch = s.r;
  s.branch.done = true;
  s.weight = vec3(0.0);
#endif
  return s;
}

// The reflection a primary ray recorded (REFLECT_OBJECTS), traced, with its environment at the
// reflection lookups' level (its footprint is the surface's curvature's, which derivatives across
// pixels of different branches do not give).
vec3 branchColor(Shaded s) {
#ifdef REFLECT_OBJECTS
  vec3 branch = s.branch.radiance;
  if (!s.branch.done) branch += s.branch.T * environmentRadiance(s.branch.d, uReflectionLod);
  return s.weight * branch;
#else
  return vec3(0.0);
#endif
}

vec3 finishShaded(Shaded s) { return finish(s.r) + branchColor(s); }

#ifdef DISPERSION_BANDS
// Whether two wavelengths' traces took the same way: through the same objects, with the same
// events in the same order, each leaving the ray in the same material, and ending alike (on the
// ground, in the environment, or stopped), their recorded reflections too. Along such a way the
// ray is a smooth function of n(λ), so the bands between them are interpolated (spectralBand).
bool samePath(Shaded a, Shaded b) {
  return a.r.path == b.r.path && a.r.done == b.r.done && a.r.grounded == b.r.grounded &&
         a.branch.path == b.branch.path && a.branch.done == b.branch.done;
}

// What a ray gathered on its way, without the ground it ended on (trace adds that last).
vec3 gatheredOnTheWay(Ray r) {
#ifdef GROUND
  if (r.grounded) return r.radiance - r.groundWeight * groundRadiance(r.x);
#endif
  return r.radiance;
}

// Band b's place between the spectrum's violet end (band 0: 0) and its red end (1), in its Cauchy
// term 1/λ² − 1/λ_d², in which n is linear.
float bandFraction(int b) {
  float span = uBandCauchy[uBandCount - 1] - uBandCauchy[0];
  return span != 0.0 ? (uBandCauchy[b] - uBandCauchy[0]) / span : 0.0;
}

// The band at fraction t of the Cauchy term's way from the spectrum's violet end (a) to its red end
// (b), both traced along one way (samePath): its ray's end, direction and transmittance
// interpolated linearly in the Cauchy term (n is linear in it, and the ray is smooth in n), then
// ended where it ends, on the ground's map or in the environment, as a traced ray is. What the ray
// gathered on the way (reflections looked up inside the glass, emission, scattering) and the
// reflection it recorded are interpolated as colours.
vec3 spectralBand(Shaded a, Shaded b, vec3 gatheredA, vec3 gatheredB, vec3 branchA, vec3 branchB, float lodA,
                  float lodB, float t) {
  Ray r = a.r;
  r.x = mix(a.r.x, b.r.x, t);
  r.d = normalize(mix(a.r.d, b.r.d, t));
  r.T = mix(a.r.T, b.r.T, t);
  r.radiance = mix(gatheredA, gatheredB, t);
#ifdef GROUND
  r.groundWeight = mix(a.r.groundWeight, b.r.groundWeight, t);
  if (r.grounded) r.radiance += r.groundWeight * groundRadiance(r.x);
#endif
  return finishAt(r, mix(lodA, lodB, t)) + mix(branchA, branchB, t);
}

// Bands i0 … i1 between a (traced at band i0) and b (traced at band ib ≥ i1), weighted by their
// shares of R, G and B; each band's ray interpolated (spectralBand), its environment's level of
// detail between the two's.
vec3 spectralRun(Shaded a, Shaded b, int i0, int i1, int ib, float lodA, float lodB) {
  vec3 gatheredA = gatheredOnTheWay(a.r), gatheredB = gatheredOnTheWay(b.r);
  vec3 branchA = branchColor(a), branchB = branchColor(b);  // once, not once a band
  float c0 = uBandCauchy[i0], span = uBandCauchy[ib] - c0;
  vec3 color = vec3(0.0);
  for (int band = i0; band <= i1; ++band)
    color += uBandRgb[band] * spectralBand(a, b, gatheredA, gatheredB, branchA, branchB, lodA, lodB,
                                           span != 0.0 ? (uBandCauchy[band] - c0) / span : 0.0);
  return color;
}

// Bands i0 … i1 between a (band i0) and b (band ib) where the two took different ways and the
// bands between were not traced: blends of the two's colours.
vec3 spectralBlend(Shaded a, Shaded b, int i0, int i1, int ib, float lodA, float lodB) {
  vec3 colorA = finishAt(a.r, lodA) + branchColor(a), colorB = finishAt(b.r, lodB) + branchColor(b);
  float c0 = uBandCauchy[i0], span = uBandCauchy[ib] - c0;
  vec3 color = vec3(0.0);
  for (int band = i0; band <= i1; ++band)
    color += uBandRgb[band] * mix(colorA, colorB, span != 0.0 ? (uBandCauchy[band] - c0) / span : 0.0);
  return color;
}
#endif

void main() {
#if defined(OUTPUT_EXIT_POSITION) || defined(OUTPUT_EXIT_DIRECTION)
  Ray r = primaryRay();
  trace(r, 0.0, -1);
#ifdef OUTPUT_EXIT_POSITION
  outColor = vec4(r.exitX, r.entered ? 1.0 : 0.0);
#else
  outColor = vec4(r.d, r.entered ? 1.0 : 0.0);
#endif
#elif defined(DISPERSION)
  // Cauchy terms 1/λ² − 1/λ_d² (µm⁻²) of the three channels, λ_d = 0.5876 µm (docs/volume-format.md).
  // Green's ray first; red's and blue's only where it went through a dispersive volume, since
  // elsewhere all three take the same path and green's RGB is each channel's own.
  const vec3 lambda = vec3(0.61, 0.55, 0.465);
  vec3 cauchy = 1.0 / (lambda * lambda) - vec3(1.0 / (0.5876 * 0.5876));
#if defined(DISPERSION_GREEN_PASS)
  // Two passes (SceneRenderer::draw): green here, and in the depth buffer where it met dispersive
  // glass (0) or not (1); red and blue, or the N bands (green's ray then stopped at the glass:
  // leftToTheBands), follow in a pass the depth test confines there.
  Shaded green = traceShaded(cauchy[1]);
  gl_FragDepth = green.r.dispersed ? 0.0 : 1.0;
  outColor = vec4(finishShaded(green), 1.0);
#elif defined(DISPERSION_RED_BLUE_PASS) && defined(DISPERSION_BANDS)
  // N spectral bands as lightsim --bands bakes them (core/spectrum.h spectralBands), each at its own
  // n(λ_b) and weighted by its share of R, G and B (the shares sum to 1 per channel), in every
  // channel (SceneRenderer::draw unmasks green for this pass). Not every band is traced
  // (docs/physics.md "Dispersion in spectral bands"): the spectrum's two ends are, and where they
  // took one way through the glass (samePath) the bands between are interpolated (spectralRun).
  // Where they did not (a ray that meets one face of an edge in violet and the other in red), the
  // band where violet's way ends is found by bisection, one trace a halving, and each side is
  // interpolated; a red side that changes way again (a ray grazing an edge) is blended as colours
  // (spectralBlend). 2 traces, at most 2 + log₂ N. With uInterpolateBands 0 every band is traced.
  // One loop on a uniform bound, with one call of the trace: one copy of it in the program. Every
  // lane runs the first two turns, so the environment's levels of detail are taken there, from the
  // ends' directions, for all bands.
  vec3 color = vec3(0.0);
  Shaded violet, red, onViolets, offViolets;  // the ends; the last band known on violet's way
  int iOn = 0, iOff = uBandCount - 1;         // (iOn) and the first known off it (iOff)
  float lodViolet = 0.0, lodRed = 0.0;
  bool interpolating = uInterpolateBands != 0 && uBandCount >= 4;
  bool searched = false;
  for (int turn = 0; turn < uBandCount && !searched; ++turn) {
    int band = !interpolating ? turn : (turn == 0 ? 0 : (turn == 1 ? uBandCount - 1 : (iOn + iOff) / 2));
    Shaded s = traceShaded(uBandCauchy[band]);
    if (!interpolating) {
      color += uBandRgb[band] * finishShaded(s);
      continue;
    }
    if (turn == 0) {
      violet = onViolets = s;
      lodViolet = exitLod(s.r);
      continue;
    }
    if (turn == 1) {
      red = offViolets = s;
      lodRed = exitLod(s.r);
    } else if (samePath(violet, s)) {
      onViolets = s;
      iOn = band;
    } else {
      offViolets = s;
      iOff = band;
    }
    searched = samePath(violet, red) || iOff - iOn <= 1;
  }
  if (interpolating) {
    if (samePath(violet, red)) {
      color = spectralRun(violet, red, 0, uBandCount - 1, uBandCount - 1, lodViolet, lodRed);
    } else {
      float lodOn = mix(lodViolet, lodRed, bandFraction(iOn)), lodOff = mix(lodViolet, lodRed, bandFraction(iOff));
      color = spectralRun(violet, onViolets, 0, iOn, iOn, lodViolet, lodOn);
      color += samePath(offViolets, red) ? spectralRun(offViolets, red, iOff, uBandCount - 1, uBandCount - 1, lodOff, lodRed)
                                         : spectralBlend(offViolets, red, iOff, uBandCount - 1, uBandCount - 1, lodOff, lodRed);
    }
  }
  outColor = vec4(color, 1.0);
#elif defined(DISPERSION_RED_BLUE_PASS)
  Shaded red = traceShaded(cauchy[0]);
  Shaded blue = traceShaded(cauchy[2]);
  outColor = vec4(finishShaded(red).r, 0.0, finishShaded(blue).b, 1.0);  // green's channel is masked off
#else
  Shaded green = traceShaded(cauchy[1]);
  Shaded red = green, blue = green;
  if (green.r.dispersed) {
    red = traceShaded(cauchy[0]);
    blue = traceShaded(cauchy[2]);
  }
  outColor = vec4(finishShaded(red).r, finishShaded(green).g, finishShaded(blue).b, 1.0);  // uniform control flow
#endif
#else
  outColor = vec4(finishShaded(traceShaded(0.0)), 1.0);
#endif
}
