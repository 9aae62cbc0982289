// Ray against an axis-aligned box, shared by the viewer's ray caster (viewer/raymarch.frag) and
// its bare benchmark march (viewer/bare_march.frag).

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
