// Free flight and straight steps in the update pass (ALGORITHM.md "Free flight", "Straight
// steps"): the GPU twin of QuietMap::quiet (lightsim/quiet_map.h), freeFlightTime,
// mergedStepsTime and sharpStepTime (cpu_simulator.cpp), line by line in float. Needs lightsim/grid.glsl and
// lightsim/patch.glsl (with SHARP_INTERFACES, lightsim/sharp.glsl).
//   FREE_FLIGHT   the quiet map's summed-area table is bound to uQuietSat
//   ABSORBER_MAP  the absorber map's (σa ≠ 0 voxels) to uAbsorberSat: straight steps only where
//                 nothing absorbs within their reach
// Both tables count noisy bricks of uQuietBrick³ voxels, (bricks + 1)³ entries per table
// (lightsim/quiet_texture.h). With volume deposits the GPU path flies only as far as the track
// deposit pass reaches.

uniform float uStepDt;        // a straight step's time (straight_step_voxels·h), or Δt when off
uniform float uReflectedStepDt;  // a reflected wavefront's (StepContext::reflected_step_dt)
uniform int uQuietBrick;      // voxels per brick edge
#ifdef FREE_FLIGHT
uniform usampler3D uQuietSat;
uniform float uFlightCap;     // the propagation box's diagonal (ctx.flight_cap)
uniform bool uKeepAtMaxDepth; // DepthLimit::Keep
// With volume deposits: the track deposit pass's bound on a patch-step's extent, in voxels of each
// axis (TrackDepositUniforms::maxExtentVoxels); 0: no bound (the receiver map only).
uniform float uFlightExtentVoxels;
#ifdef SHARP_INTERFACES
uniform bool uMergeSteps;     // SimulationOptions::merge_straight_steps
uniform vec3 uBoxMin;         // the propagation box (wavefront.h propagationBox)
uniform vec3 uBoxMax;
#endif
#endif
#ifdef ABSORBER_MAP
uniform usampler3D uAbsorberSat;
uniform float uStraightReach;  // straight_step_voxels·h / min(1, min n): how far a straight step goes
#endif

#if defined(FREE_FLIGHT) || defined(ABSORBER_MAP)
uint satAt(usampler3D sat, int i, int j, int k) { return texelFetch(sat, ivec3(i, j, k), 0).r; }

// QuietMap::quiet: whether every trilinear sample in the box [lo, hi] avoids the noisy bricks of
// the table `sat` (eight lookups). False for a box that is not finite.
bool boxQuiet(usampler3D sat, vec3 lo, vec3 hi) {
  vec3 qlo = gridUvw(lo) * vec3(uDims), qhi = gridUvw(hi) * vec3(uDims);
  if (any(isnan(qlo)) || any(isinf(qlo)) || any(isnan(qhi)) || any(isinf(qhi))) return false;
  // The taps of a sample at voxel coordinate q: floor(c) and floor(c) + 1, c = q − ½ clamped.
  vec3 top = vec3(uDims - 1);
  vec3 c0 = clamp(min(qlo, qhi) - 0.5, vec3(0.0), top), c1 = clamp(max(qlo, qhi) - 0.5, vec3(0.0), top);
  ivec3 v0 = ivec3(floor(c0));
  ivec3 v1 = min(uDims - 1, ivec3(floor(c1)) + 1);
  ivec3 b0 = v0 / uQuietBrick, b1 = v1 / uQuietBrick + 1;  // b1 exclusive
  uint count = satAt(sat, b1.x, b1.y, b1.z) - satAt(sat, b0.x, b1.y, b1.z) - satAt(sat, b1.x, b0.y, b1.z) -
               satAt(sat, b1.x, b1.y, b0.z) + satAt(sat, b0.x, b0.y, b1.z) + satAt(sat, b0.x, b1.y, b0.z) +
               satAt(sat, b1.x, b0.y, b0.z) - satAt(sat, b0.x, b0.y, b0.z);
  return count == 0u;
}
#endif

#ifdef FREE_FLIGHT
// Whether the patch swept from time t0 to t1 is quiet: it lies in the box of its corners at t0
// and t1, each on its straight ray x_c + t·v_c.
bool flightQuiet(Patch p, vec3 v[4], float t0, float t1) {
  vec3 lo = vec3(3.4e38), hi = vec3(-3.4e38);
  for (int c = 0; c < 4; ++c) {
    vec3 start = p.x[c] + t0 * v[c], end = p.x[c] + t1 * v[c];
    lo = min(lo, min(start, end));
    hi = max(hi, max(start, end));
  }
  return boxQuiet(uQuietSat, lo, hi);
}

// Whether the whole flight from 0 to t stays within the track deposit pass's bound: the box of the
// corners at 0 and t (all of the flight: each corner moves on a line), clamped to the grid as the
// pass clamps it (track_deposit.vert), at most uFlightExtentVoxels voxels along every axis.
bool flightFits(Patch p, vec3 v[4], float t) {
  if (!(uFlightExtentVoxels > 0.0)) return true;
  vec3 lo = vec3(3.4e38), hi = vec3(-3.4e38);
  for (int c = 0; c < 4; ++c) {
    vec3 end = p.x[c] + t * v[c];
    lo = min(lo, min(p.x[c], end));
    hi = max(hi, max(p.x[c], end));
  }
  vec3 voxelSize = (uBoundsMax - uBoundsMin) / vec3(uDims);
  vec3 top = vec3(uDims) + 2.0;
  vec3 vlo = clamp((lo - uBoundsMin) / voxelSize, vec3(-4.0), top);
  vec3 vhi = clamp((hi - uBoundsMin) / voxelSize, vec3(-4.0), top);
  return all(lessThanEqual(vhi - vlo, vec3(uFlightExtentVoxels)));
}

#ifdef SHARP_INTERFACES
// mergedStepsTime (cpu_simulator.cpp): where the quiet map lets no flight start and straight steps
// apply, the next straight steps whose ends keep every corner in its own material, taken as one
// (k ≥ 2 of them, at most 64; the ends asked one by one except along quiet pieces, none past the
// step whose midpoint leaves the box); 0: an ordinary step. With volume deposits, no more of them
// than the track deposit pass reaches (flightFits).
float mergedStepsTime(Patch p, vec3 v[4], float tMax, bool splitDue) {
#ifdef ABSORBER_MAP
  return 0.0;  // σa a field: straight steps only where nothing absorbs near (sharpStepTime)
#else
  if (!uMergeSteps || !(uStepDt > uDt) || p.reflected != 0 || splitDue) return 0.0;
  float stepTime = p.bounce > 0 ? uReflectedStepDt : uStepDt;
  int most = int(min(64.0, floor(tMax / stepTime)));
  if (most < 2) return 0.0;
  // A long step's chord is looked at in pieces (findInterfaceOnChord): so are its ends here.
  int pieces[4];
  for (int c = 0; c < 4; ++c) pieces[c] = chordPieces(stepTime * length(v[c]));
  int k = 0;
  bool met = false;
  while (k < most && !met) {
    if (k == 1 || (k > 0 && k % 4 == 0)) {
      int quiet = 0;
      for (int piece = 1; k + piece <= most && flightQuiet(p, v, float(k) * stepTime, float(k + piece) * stepTime);
           piece *= 2)
        quiet = piece;
      if (quiet > 0) {
        k += quiet;
        continue;
      }
    }
    float t = float(k + 1) * stepTime;
    vec3 mid = vec3(0.0);
    for (int c = 0; c < 4; ++c) {
      for (int j = 1; j < pieces[c]; ++j)
        if (materialAt(p.x[c] + (float(k) + float(j) / float(pieces[c])) * stepTime * v[c]) != p.medium[c]) met = true;
      vec3 end = p.x[c] + t * v[c];
      if (materialAt(end) != p.medium[c]) met = true;
      mid += 0.25 * end;
    }
    if (met) break;
    ++k;
    if (!insideBox(mid, uBoxMin, uBoxMax)) break;
  }
  while (k >= 2 && !flightFits(p, v, float(k) * stepTime)) --k;
  return k >= 2 ? float(k) * stepTime : 0.0;
#endif
}
#endif

// freeFlightTime (cpu_simulator.cpp): the time of one straight step for the whole patch, or 0 for
// an ordinary step. Every corner moves on its straight ray, so the swept patch lies in the box of
// its corners at 0 and t, checked piece by piece ([good, t] of the doubling and of the bisection);
// t is doubled from 2Δt while the path is quiet, then refined by three bisections, bounded so that no edge grows past the split length (or its length now, if longer;
// at the depth limit, as far as a kept patch goes), by uFlightCap and, with volume deposits, by
// the track deposit pass's extent (flightFits; the twin's flights are not bounded so).
float freeFlightTime(Patch p) {
#ifdef SHARP_INTERFACES
  if (!oneMedium(p) || p.crossed != 0 || p.reflectPending != 0.0) return 0.0;
#else
  if (p.nIn != 0.0) return 0.0;  // inside a boundary layer: its Fresnel exit is decided step by step
#endif
  vec3 v[4];
  float n[4];
  for (int c = 0; c < 4; ++c) {
#ifdef SHARP_INTERFACES
    vec4 s = materialOptics(p.medium[c], p.x[c]);
#else
    vec4 s = vec4(sampleIor(p.x[c]), sampleIorGrad(p.x[c]));
#endif
    if (s.y != 0.0 || s.z != 0.0 || s.w != 0.0 || !(s.x > 0.0)) return 0.0;
    n[c] = s.x;
    v[c] = p.w[c] / (s.x * s.x);  // dx/dt, Eq. 6.1
  }
  bool kept = uKeepAtMaxDepth && p.depth >= uMaxDepth;
  float splitLength = splitLengthOf(p, uSplitLength);
  float tMax = 3.4e38;
  for (int c = 0; c < 4; ++c) {
    tMax = min(tMax, uFlightCap * n[c]);  // a path of length ℓ takes time ℓ·n
    int d = (c + 1) % 4;
    // The edge e(t) = e₀ + t·Δv stays within L up to the larger root of |Δv|²t² + 2(e₀·Δv)t + |e₀|² − L².
    vec3 e0 = p.x[d] - p.x[c];
    vec3 dv = v[d] - v[c];
    float a = dot(dv, dv);
    if (!(a > 0.0)) continue;
    float edge2 = dot(e0, e0);
    float limit = kept ? 4.0 * uSplitLength : max(splitLength, sqrt(edge2));  // kMaxUnsplitEdge
    float b = dot(e0, dv);
    float disc = max(0.0, b * b - a * (edge2 - limit * limit));
    tMax = min(tMax, (-b + sqrt(disc)) / a);
  }
  if (!(tMax >= 2.0 * uDt)) return 0.0;
  float good = 0.0, bad = 0.0;
  for (float t = 2.0 * uDt;; t *= 2.0) {
    float tt = min(t, tMax);
    if (!flightQuiet(p, v, good, tt) || !flightFits(p, v, tt)) {
      bad = tt;
      break;
    }
    good = tt;
    if (tt >= tMax) break;
  }
#ifdef SHARP_INTERFACES
  if (good == 0.0) {
    // A patch longer than the split length (it crossed an interface unsplit) splits at its next look.
    float longest = 0.0;
    for (int c = 0; c < 4; ++c) longest = max(longest, distance(p.x[(c + 1) % 4], p.x[c]));
    return mergedStepsTime(p, v, tMax, !kept && longest > splitLength);
  }
#else
  if (good == 0.0) return 0.0;
#endif
  if (bad > 0.0)
    for (int i = 0; i < 3; ++i) {
      float mid = 0.5 * (good + bad);
      if (flightQuiet(p, v, good, mid) && flightFits(p, v, mid)) good = mid;
      else bad = mid;
    }
  return good;
}
#endif

// sharpStepTime (cpu_simulator.cpp): a straight step where nothing absorbs within its reach of
// the corners (with absorption; with σa per material anywhere: no absorber map then, and a
// reflected wavefront's straight steps are longer), else Δt. uStepDt is Δt when straight steps
// are off.
float sharpStepTime(Patch p) {
  if (!(uStepDt > uDt)) return uDt;
#ifdef ABSORBER_MAP
  vec3 lo = p.x[0], hi = p.x[0];
  for (int c = 1; c < 4; ++c) lo = min(lo, p.x[c]), hi = max(hi, p.x[c]);
  return boxQuiet(uAbsorberSat, lo - uStraightReach, hi + uStraightReach) ? uStepDt : uDt;
#elif defined(SHARP_INTERFACES)
  return p.bounce > 0 ? uReflectedStepDt : uStepDt;
#else
  return uStepDt;
#endif
}
