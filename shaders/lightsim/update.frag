#version 330 core
// ALGORITHM.md steps 1–3 for one patch (one texel of the list; the viewport covers the live
// patches' Morton box, patches ≥ liveCount() are skipped). Reads the list uPatch, writes the new state
// to the eight MRT attachments of the other list.
//   1. Update (thesis §6.2.2): per corner, the time-parameterised ray equation (Eq. 4.12/4.13)
//      x' = w/n², w' = ∇n/n, stepped with Euler (Eq. 6.1/6.2), RK2 (midpoint) or RK4
//      (INTEGRATOR_EULER / _RK2 / _RK4), then w renormalised to n at the new position.
//   2. Absorption: Φ ← Φ·exp(−σa(m_old)·Δs_m), Δs_m = Δt / n(m_old) (Eq. 4.11), Δt the step's time.
//      MATERIAL_ABSORPTION (σa per material, sharp interfaces): Φ ← Φ·exp(−¼ Σ_c ∫σa ds) along the
//      corners' paths, each piece with its material's σa (sharp.glsl advanceCornerSharp).
//   3. Fresnel boundary tracking (docs/physics.md): enter a layer when |∇n(m_new)|·h > g_on, leave it
//      when < g_off and keep the transmitted fraction 1 − R (boundaryReflectance, fresnel.glsl).
// SHARP_INTERFACES (ALGORITHM.md "Sharp interfaces"; the CPU twin's stepPatch): each corner
// crosses the interfaces on its chord with Snell's law and the exact Fresnel R (sharp.glsl); the
// patch keeps Π (1 − R_c)^¼ of its flux. A step that would tear the patch — stretched past
// kTearFactor split lengths, or a first touch whose other corners will not meet the same surface
// (willTear) — is undone and the event tells the analysis to split the patch as it was
// (SHARP_EVENT_SPLIT_U/V), or, at the depth limit, that it dies (SHARP_EVENT_TORN, with the corners
// that met the surface: SHARP_EVENT_MET_UNIT times their mask).
// FREE_FLIGHT / ABSORBER_MAP (flight.glsl): a patch in quiet space crosses it in one straight step;
// with sharp interfaces an ordinary step is a straight step (uStepDt) where they apply.
#include "common/volume.glsl"
#include "lightsim/grid.glsl"
#include "lightsim/patch.glsl"
#include "lightsim/live_count.glsl"
#include "lightsim/fresnel.glsl"

uniform sampler2D uPatch[8];
uniform float uDt;             // Δt = step_voxels·h
uniform float uBoundaryOn;     // g_on  (|∇n|·h entering a layer)
uniform float uBoundaryOff;    // g_off (|∇n|·h leaving it)
uniform float uSplitLength;    // split_voxels · h · (1 + margin): tears, flights
uniform float uMaxDepth;       // max_depth

#ifdef SHARP_INTERFACES
#include "lightsim/sharp.glsl"
uniform bool uAxisSplit;     // SplitRule::Axis
uniform bool uRetakeAtInterfaces;  // StepUniforms::retakeAtInterfaces
const float kTearFactor = 2.0;  // cpu_simulator.cpp
#endif
#include "lightsim/flight.glsl"

layout(location = 0) out vec4 oP0;
layout(location = 1) out vec4 oP1;
layout(location = 2) out vec4 oP2;
layout(location = 3) out vec4 oP3;
layout(location = 4) out vec4 oW01;
layout(location = 5) out vec4 oW23;
layout(location = 6) out vec4 oFlux;
layout(location = 7) out vec4 oMeta;

// Right-hand side of Eq. 4.12/4.13: dx/dt = w/n², dw/dt = ∇n/n.
void rayRhs(vec3 x, vec3 w, out vec3 dx, out vec3 dw) {
  float n = sampleIor(x);
  dx = w / (n * n);
  dw = sampleIorGrad(x) / n;
}

// Step 1 for one corner.
void stepCorner(inout vec3 x, inout vec3 w) {
  vec3 k1x, k1w;
  rayRhs(x, w, k1x, k1w);
#if defined(INTEGRATOR_RK4)
  vec3 k2x, k2w, k3x, k3w, k4x, k4w;
  rayRhs(x + 0.5 * uDt * k1x, w + 0.5 * uDt * k1w, k2x, k2w);
  rayRhs(x + 0.5 * uDt * k2x, w + 0.5 * uDt * k2w, k3x, k3w);
  rayRhs(x + uDt * k3x, w + uDt * k3w, k4x, k4w);
  vec3 xn = x + (uDt / 6.0) * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
  vec3 wn = w + (uDt / 6.0) * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
#elif defined(INTEGRATOR_RK2)
  vec3 k2x, k2w;
  rayRhs(x + 0.5 * uDt * k1x, w + 0.5 * uDt * k1w, k2x, k2w);  // midpoint
  vec3 xn = x + uDt * k2x;
  vec3 wn = w + uDt * k2w;
#else
  vec3 xn = x + uDt * k1x;  // Eq. 6.1: x ← x + Δt·w/n²
  vec3 wn = w + uDt * k1w;  // Eq. 6.2: w ← w + Δt·∇n/n
#endif
  x = xn;
  w = normalize(wn) * sampleIor(xn);  // |w| = n(x_new)
}

void writePatch(Patch p) {
  vec4 t[8];
  packPatch(p, t);
  oP0 = t[0]; oP1 = t[1]; oP2 = t[2]; oP3 = t[3];
  oW01 = t[4]; oW23 = t[5]; oFlux = t[6]; oMeta = t[7];
}

#ifdef SHARP_INTERFACES
// The split axes of a patch whose edges exceed `threshold` (wavefront.h splitAxes): bit 0 u, bit 1 v.
int splitAxesOf(Patch p, float threshold) {
  float uEdge = max(distance(p.x[0], p.x[1]), distance(p.x[3], p.x[2]));
  float vEdge = max(distance(p.x[1], p.x[2]), distance(p.x[0], p.x[3]));
  if (uAxisSplit) return (uEdge > threshold ? 1 : 0) | (vEdge > threshold ? 2 : 0);
  return max(uEdge, vEdge) > threshold ? 3 : 0;
}
float longestEdge(Patch p) {
  float e = 0.0;
  for (int c = 0; c < 4; ++c) e = max(e, distance(p.x[(c + 1) % 4], p.x[c]));
  return e;
}
// willTear (cpu_simulator.cpp): some corners met an interface, the others (not in `metMask`) must
// each find the same surface ahead on their straight rays within `reach`, or the patch tears.
bool willTear(Patch p, int metMask, float reach) {
  int slot = -1;
  for (int c = 0; c < 4; ++c) {
    if (((metMask >> c) & 1) != 0) continue;
    float f;
    int k, entered;
    vec3 d = normalize(p.w[c]);
    if (!findInterfaceOnChord(p.x[c], p.x[c] + reach * d, p.medium[c], f, k, entered)) return true;
    if (slot >= 0 && k != slot) return true;
    slot = k;
  }
  return false;
}

void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy);
  if (mortonIndex(texel) >= liveCount()) discard;
  Patch p;
  FETCH_PATCH(uPatch, texel, p);
  p.event = 0;
  Patch before = p;
  vec3 mOld = patchMidpoint(p);

  // Step 1 with sharp interfaces: a free flight across quiet space (straight rays, no interface in
  // the swept box), or an ordinary step of Δt (a straight step where they apply) in which every
  // corner crosses the interfaces on its way.
  float transmittance = 1.0;
  vec3 opticalDepth = vec3(0.0);  // ¼ Σ_c ∫σa ds (MATERIAL_ABSORPTION)
  int metMask = 0, transmittedMask = 0, reflectedMask = 0, blocked = 0, reflections = 0;
  float flight = 0.0;
#ifdef FREE_FLIGHT
  flight = freeFlightTime(p);
#endif
  float stepTime = flight;  // the step's time: the flight's, a straight step's or Δt
  if (flight > 0.0) {
    for (int c = 0; c < 4; ++c) {
      float n = materialOptics(p.medium[c], p.x[c]).x;
      vec3 from = p.x[c];
      p.x[c] += flight * p.w[c] / (n * n);  // Eq. 6.1, exact for a straight ray
#ifdef MATERIAL_ABSORPTION
      opticalDepth += 0.25 * pieceOpticalDepth(p.medium[c], from, p.x[c], flight / n);
#endif
    }
  } else {
    stepTime = sharpStepTime(p);
    // With volume deposits a straight step in which a corner met an interface is retaken as a step
    // of Δt: its track deposit follows the chord, the ray only where no corner met one.
    for (int attempt = 0; attempt < 2; ++attempt) {
      for (int c = 0; c < 4; ++c) {
        CornerCrossings cc = advanceCornerSharp(p.x[c], p.w[c], p.medium[c], stepTime);
        if (cc.transmitted > 0 || cc.reflected > 0 || cc.blocked) metMask |= 1 << c;
        reflections += cc.reflected;
        if (cc.reflected > 0) reflectedMask |= 1 << c;
        blocked += cc.blocked ? 1 : 0;
        if (cc.transmitted > 0) transmittedMask |= 1 << c;
        transmittance *= pow(cc.transmittance, 0.25);
        opticalDepth += 0.25 * cc.opticalDepth;
      }
      if (!uRetakeAtInterfaces || metMask == 0 || !(stepTime > uDt) || p.bounce > 0) break;  // not a reflected one's
      p = before;
      stepTime = uDt;
      transmittance = 1.0;
      opticalDepth = vec3(0.0);
      metMask = transmittedMask = reflectedMask = blocked = reflections = 0;
    }
  }
  p.reflections += reflections;
  if (metMask != 0 && oneMedium(before)) {
    float splitLength = splitLengthOf(before, uSplitLength);
    bool stretched = splitAxesOf(p, kTearFactor * splitLength) != 0;
    // Corners totally reflected at this surface in earlier steps have met it already.
    int met = metMask | before.reflected;
    bool firstTouch = met != 15;
    bool tears = stretched || (firstTouch && willTear(p, met, 4.0 * max(longestEdge(p), uVoxelEdge)));
    if (tears && p.depth >= uMaxDepth) {
      // Dies before it deposits anything, but for the light its corners carry past the object
      // (the analysis, passingShare): which corners met the surface, in the event's bits 6–9.
      before.event = SHARP_EVENT_TORN + SHARP_EVENT_MET_UNIT * met;
      writePatch(before);
      return;
    }
    if (tears) {
      int axes = splitAxesOf(p, splitLength);
      if (axes == 0) axes = splitAxesOf(before, 0.0);  // a tear ahead: halve it
      before.event = axes;
      writePatch(before);
      return;
    }
  }

  // Step 2: absorption at the old midpoint over the step, n of its material there; with σa per
  // material, along the corners' paths piece by piece (Beer–Lambert).
#ifdef MATERIAL_ABSORPTION
  p.flux *= exp(-opticalDepth);
#else
  p.flux *= sharpAbsorptionFactor(mOld, stepTime);
#endif

  // Step 3: Fresnel at the interfaces the corners crossed; the reflected fraction is remembered
  // until every corner is through (the analysis may then follow the reflected wavefront).
  p.tFresnel = transmittance;
  if (transmittance < 1.0) {
    p.flux *= transmittance;
    p.reflectPending = 1.0 - (1.0 - p.reflectPending) * transmittance;
  }
  // A total reflection is through once all four corners have reflected (or the patch flies: no
  // surface is near).
  p.reflected |= reflectedMask;
  if (p.reflected == 15 || flight > 0.0) p.reflected = 0;
  p.crossed |= transmittedMask;
  p.event = SHARP_EVENT_BLOCKED * blocked;
  writePatch(p);
}
#else
void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy);
  if (mortonIndex(texel) >= liveCount()) discard;
  Patch p;
  FETCH_PATCH(uPatch, texel, p);

  vec3 mOld = patchMidpoint(p);
  vec3 dOld = patchDirection(p);

  // Step 1: a free flight across quiet space, or Eq. 6.1/6.2 (or RK2/RK4) per corner.
  float flight = 0.0;
#ifdef FREE_FLIGHT
  flight = freeFlightTime(p);
#endif
  if (flight > 0.0) {
    for (int c = 0; c < 4; ++c) {
      float n = sampleIor(p.x[c]);
      p.x[c] += flight * p.w[c] / (n * n);  // Eq. 6.1, exact for a straight ray
    }
  } else {
    for (int c = 0; c < 4; ++c) stepCorner(p.x[c], p.w[c]);
  }

  // Step 2: absorption at the old midpoint over the step.
  p.flux *= absorptionFactor(mOld, flight > 0.0 ? flight : uDt);

  // Step 3: Fresnel boundary tracking.
  vec3 mNew = patchMidpoint(p);
  vec3 grad = sampleIorGrad(mNew);
  float g = length(grad) * uVoxelEdge;  // index change per voxel
  p.tFresnel = 1.0;
  if (p.nIn == 0.0) {
    if (g > uBoundaryOn) {
      p.nIn = sampleIor(mOld);
      p.cosIn = abs(dot(dOld, grad / length(grad)));
    }
  } else if (g < uBoundaryOff) {
    float gradLength = length(grad);
    float cosOut = gradLength > 0.0 ? abs(dot(patchDirection(p), grad / gradLength)) : -1.0;
    float r = boundaryReflectance(p.nIn, p.cosIn, sampleIor(mNew), cosOut, uBoundaryOff);
    p.flux *= 1.0 - r;
    p.tFresnel = 1.0 - r;
    p.nIn = 0.0;
  }
  writePatch(p);
}
#endif
