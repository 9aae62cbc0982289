// Ray against an axis-aligned box, shared by the viewer's ray caster (viewer/raymarch.frag) and
// its bare benchmark march (viewer/bare_march.frag); a segment's share inside a box (the viewer and
// lightsim/sharp.glsl).

// Slab test against [bmin, bmax] for the ray o + t·d (d need not be unit: t is in units of |d|).
// False when the ray misses the box or the box lies behind the origin.
bool intersectBox(vec3 o, vec3 d, vec3 bmin, vec3 bmax, out float tNear, out float tFar) {
  vec3 inv = 1.0 / d;
  vec3 t0 = (bmin - o) * inv;
  vec3 t1 = (bmax - o) * inv;
  vec3 lo = min(t0, t1);
  vec3 hi = max(t0, t1);
  tNear = max(max(lo.x, lo.y), lo.z);
  tFar = min(min(hi.x, hi.y), hi.z);
  return tFar > max(tNear, 0.0);
}

// The share of the segment a → b inside [lo, hi] (slabs), in [0, 1] (core/interfaces.h boxShare):
// how much of a straight step in air lies in a box of smoke (AIR_BOX).
float boxShare(vec3 a, vec3 b, vec3 lo, vec3 hi) {
  vec3 d = b - a;
  vec3 inv = 1.0 / mix(vec3(1e-30), d, greaterThan(abs(d), vec3(1e-30)));
  vec3 t0 = (lo - a) * inv, t1 = (hi - a) * inv;
  vec3 tNear = min(t0, t1), tFar = max(t0, t1);
  float enter = clamp(max(max(tNear.x, tNear.y), tNear.z), 0.0, 1.0);
  float leave = clamp(min(min(tFar.x, tFar.y), tFar.z), 0.0, 1.0);
  return max(leave - enter, 0.0);
}
