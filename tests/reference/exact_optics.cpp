#include "tests/reference/exact_optics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <thread>

namespace eik::reference {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// splitmix64: a counter-based generator, so ray i gets the same numbers whatever the threads.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

class RayRandom {
 public:
  RayRandom(std::uint64_t seed, std::uint64_t ray) : state_(mix(seed ^ mix(ray))) {}
  double uniform() {  // [0, 1)
    state_ = mix(state_);
    return static_cast<double>(state_ >> 11) * 0x1.0p-53;
  }

 private:
  std::uint64_t state_;
};

double fract(double x) { return x - std::floor(x); }

// Point i of the R2 low-discrepancy sequence (Roberts 2018) shifted by (s0, s1): stratifies the
// beam far better than independent samples.
glm::dvec2 r2Point(std::uint64_t i, double s0, double s1) {
  constexpr double g = 1.32471795724474602596;  // the plastic number
  return {fract(s0 + static_cast<double>(i) / g), fract(s1 + static_cast<double>(i) / (g * g))};
}

// Shirley–Chiu concentric map of the unit square onto the unit disc (area preserving).
glm::dvec2 concentricDisc(glm::dvec2 u) {
  const double a = 2.0 * u.x - 1.0, b = 2.0 * u.y - 1.0;
  if (a == 0.0 && b == 0.0) return {0.0, 0.0};
  double r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = std::numbers::pi / 4.0 * (b / a);
  } else {
    r = b;
    phi = std::numbers::pi / 2.0 - std::numbers::pi / 4.0 * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

void orthonormalBasis(glm::dvec3 n, glm::dvec3& u, glm::dvec3& v) {
  const glm::dvec3 helper = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  u = glm::normalize(glm::cross(helper, n));
  v = glm::cross(n, u);
}

struct Tally {
  std::vector<double> rings, map, fluence;
  double received = 0.0, escaped = 0.0, dropped = 0.0, absorbed = 0.0;
};

// The fluence of one straight piece of path, origin + t·dir (dir unit) for t0 ≤ t ≤ t1, carrying
// flux·e^(−σ (t − t0)): clipped to the grid's box, then cut at the cells' faces (a 3D DDA), each
// part's ∫ flux e^(−σ (t − t0)) dt added to its cell over the cell's volume.
void tallyFluence(const FluenceGrid& grid, glm::dvec3 origin, glm::dvec3 dir, double t0, double t1, double flux,
                  double sigma, bool in_solid, std::vector<double>& fluence) {
  if (grid.dims.x <= 0 || !(t1 > t0) || (grid.solids_only && !in_solid)) return;
  const glm::dvec3 cell = (grid.hi - grid.lo) / glm::dvec3(grid.dims);
  // The hats of the outermost cells reach half a cell beyond the grid.
  const glm::dvec3 lo = grid.hat ? grid.lo - 0.5 * cell : grid.lo, hi = grid.hat ? grid.hi + 0.5 * cell : grid.hi;
  double a = t0, b = std::isfinite(t1) ? t1 : 1e30;
  for (int k = 0; k < 3; ++k) {
    if (dir[k] == 0.0) {
      if (origin[k] < lo[k] || origin[k] > hi[k]) return;
      continue;
    }
    double ta = (lo[k] - origin[k]) / dir[k], tb = (hi[k] - origin[k]) / dir[k];
    if (ta > tb) std::swap(ta, tb);
    a = std::max(a, ta);
    b = std::min(b, tb);
  }
  if (!(b > a)) return;
  const double volume = cell.x * cell.y * cell.z;
  if (grid.hat) {
    const glm::dvec3 span = (b - a) * dir / cell;
    const int samples = std::max(1, static_cast<int>(std::ceil(8.0 * (std::fabs(span.x) + std::fabs(span.y) + std::fabs(span.z)))));
    const double ds = (b - a) / samples;
    for (int i = 0; i < samples; ++i) {
      const double t = a + (i + 0.5) * ds;
      const double weight = flux * (sigma > 0.0 ? std::exp(-sigma * (t - t0)) : 1.0) * ds / volume;
      const glm::dvec3 f = (origin + t * dir - grid.lo) / cell - 0.5;  // cell centres at integers
      const glm::dvec3 base = glm::floor(f), frac = f - base;
      for (int corner = 0; corner < 8; ++corner) {
        const glm::ivec3 o(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const glm::ivec3 c = glm::ivec3(base) + o;
        if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= grid.dims.x || c.y >= grid.dims.y || c.z >= grid.dims.z) continue;
        const double w = (o.x ? frac.x : 1.0 - frac.x) * (o.y ? frac.y : 1.0 - frac.y) * (o.z ? frac.z : 1.0 - frac.z);
        fluence[static_cast<std::size_t>(c.x + grid.dims.x * (c.y + grid.dims.y * c.z))] += weight * w;
      }
    }
    return;
  }
  glm::ivec3 c, step;
  glm::dvec3 next, every;
  const glm::dvec3 pa = origin + a * dir;
  for (int k = 0; k < 3; ++k) {
    // The cell the piece starts in (just past its entry point along dir).
    const double f = (pa[k] - grid.lo[k]) / cell[k];
    int ck = static_cast<int>(std::floor(f));
    if (dir[k] < 0.0 && f == std::floor(f)) ck -= 1;
    c[k] = std::clamp(ck, 0, grid.dims[k] - 1);
    if (dir[k] > 0.0) {
      step[k] = 1;
      every[k] = cell[k] / dir[k];
      next[k] = (grid.lo[k] + (c[k] + 1) * cell[k] - origin[k]) / dir[k];
    } else if (dir[k] < 0.0) {
      step[k] = -1;
      every[k] = -cell[k] / dir[k];
      next[k] = (grid.lo[k] + c[k] * cell[k] - origin[k]) / dir[k];
    } else {
      step[k] = 0;
      every[k] = kInfinity;
      next[k] = kInfinity;
    }
  }
  double t = a;
  while (t < b) {
    const int k = next.x <= next.y ? (next.x <= next.z ? 0 : 2) : (next.y <= next.z ? 1 : 2);
    const double te = std::min(b, next[k]);
    if (te > t) {
      const double length = te - t;
      const double part = sigma > 0.0 ? std::exp(-sigma * (t - t0)) * -std::expm1(-sigma * length) / sigma : length;
      fluence[static_cast<std::size_t>(c.x + grid.dims.x * (c.y + grid.dims.y * c.z))] += flux * part / volume;
    }
    t = te;
    c[k] += step[k];
    next[k] += every[k];
    if (c[k] < 0 || c[k] >= grid.dims[k]) break;
  }
}

void tallyOnReceiver(const Receiver& receiver, glm::dvec3 p, double flux, Tally& tally) {
  tally.received += flux;
  const glm::dvec3 offset = p - receiver.center;
  const glm::dvec3 in_plane = offset - glm::dot(offset, receiver.normal) * receiver.normal;
  const double r = glm::length(in_plane);
  const auto ring = static_cast<std::size_t>(r / receiver.ring_width);
  if (ring < tally.rings.size()) tally.rings[ring] += flux;
  if (receiver.map_texels > 0) {
    const glm::dvec2 corner = receiver.map_origin_given ? receiver.map_origin
                                                        : glm::dvec2(-0.5 * receiver.map_texels * receiver.map_pitch);
    const double fu = (glm::dot(offset, receiver.map_u) - corner.x) / receiver.map_pitch;
    const double fv = (glm::dot(offset, receiver.map_v) - corner.y) / receiver.map_pitch;
    if (fu >= 0.0 && fv >= 0.0 && fu < receiver.map_texels && fv < receiver.map_texels) {
      const auto iu = static_cast<std::size_t>(fu), iv = static_cast<std::size_t>(fv);
      tally.map[iv * static_cast<std::size_t>(receiver.map_texels) + iu] += flux;
    }
  }
}

// Follows one ray from the light until the receiver absorbs it, it escapes or it is dropped.
void tracePath(const std::vector<Solid>& solids, const Receiver& receiver, const FluenceGrid& grid, glm::dvec3 origin,
               glm::dvec3 dir, double flux, int max_interactions, RayRandom& random, Tally& tally) {
  constexpr double kEpsilon = 1e-9;
  int inside = -1;  // index of the solid the ray is in, -1 in air
  for (int interaction = 0; interaction <= max_interactions; ++interaction) {
    Hit nearest;
    nearest.t = kInfinity;
    int nearest_solid = -1;
    if (inside >= 0) {
      if (solids[static_cast<std::size_t>(inside)].intersect(origin, dir, kEpsilon, nearest)) nearest_solid = inside;
    } else {
      for (std::size_t k = 0; k < solids.size(); ++k) {
        Hit hit;
        if (solids[k].intersect(origin, dir, kEpsilon, hit) && hit.t < nearest.t) {
          nearest = hit;
          nearest_solid = static_cast<int>(k);
        }
      }
      const double facing = glm::dot(dir, receiver.normal);
      if (facing < 0.0) {
        const double t_plane = glm::dot(receiver.point - origin, receiver.normal) / facing;
        if (t_plane > 0.0 && t_plane < nearest.t) {
          tallyFluence(grid, origin, dir, 0.0, t_plane, flux, 0.0, false, tally.fluence);
          tallyOnReceiver(receiver, origin + t_plane * dir, flux, tally);
          return;
        }
      }
    }
    if (nearest_solid < 0) {
      // Inside a solid with no exit can only be rounding at a grazing hit: count it as escaped.
      if (inside < 0) tallyFluence(grid, origin, dir, 0.0, kInfinity, flux, 0.0, false, tally.fluence);
      tally.escaped += flux;
      return;
    }
    // The piece up to the surface, absorbed on the way inside a solid.
    const double sigma = inside >= 0 ? solids[static_cast<std::size_t>(inside)].sigma_a : 0.0;
    tallyFluence(grid, origin, dir, 0.0, nearest.t, flux, sigma, inside >= 0, tally.fluence);
    if (sigma > 0.0) {
      const double kept = std::exp(-sigma * nearest.t);
      tally.absorbed += flux * (1.0 - kept);
      flux *= kept;
    }
    const Solid& solid = solids[static_cast<std::size_t>(nearest_solid)];
    const glm::dvec3 p = origin + nearest.t * dir;
    const bool entering = inside < 0;
    const glm::dvec3 facing_normal = entering ? nearest.normal : -nearest.normal;  // against the ray
    const double n1 = entering ? 1.0 : solid.ior, n2 = entering ? solid.ior : 1.0;
    const double cos_i = std::min(1.0, -glm::dot(dir, facing_normal));
    const double reflectance = fresnelReflectance(n1, n2, cos_i);
    if (random.uniform() < reflectance) {
      dir = glm::normalize(dir + 2.0 * cos_i * facing_normal);
    } else {
      const double eta = n1 / n2;
      const double cos_t = std::sqrt(std::max(0.0, 1.0 - eta * eta * (1.0 - cos_i * cos_i)));
      dir = glm::normalize(eta * dir + (eta * cos_i - cos_t) * facing_normal);
      inside = entering ? nearest_solid : -1;
    }
    origin = p;
  }
  tally.dropped += flux;
}

}  // namespace

double fresnelReflectance(double n1, double n2, double cos_i) {
  cos_i = std::clamp(cos_i, 0.0, 1.0);
  const double sin_t = n1 / n2 * std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i));
  if (sin_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
  const double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
  const double rp = (n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i);
  return 0.5 * (rs * rs + rp * rp);
}

Solid Solid::sphere(glm::dvec3 center, double radius, double ior) {
  Solid s;
  s.ior = ior;
  s.is_sphere = true;
  s.center = center;
  s.radius = radius;
  return s;
}

Solid Solid::halfSpaces(std::vector<glm::dvec4> planes, double ior) {
  Solid s;
  s.ior = ior;
  s.is_sphere = false;
  for (glm::dvec4& p : planes) {
    const double length = glm::length(glm::dvec3(p));
    p /= length;
  }
  s.planes = std::move(planes);
  return s;
}

Solid Solid::box(glm::dvec3 lo, glm::dvec3 hi, double ior) {
  return halfSpaces({{1, 0, 0, hi.x}, {-1, 0, 0, -lo.x}, {0, 1, 0, hi.y}, {0, -1, 0, -lo.y}, {0, 0, 1, hi.z},
                     {0, 0, -1, -lo.z}},
                    ior);
}

Solid Solid::prism(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, double z0, double z1, double ior) {
  std::vector<glm::dvec4> planes{{0, 0, 1, z1}, {0, 0, -1, -z0}};
  const glm::dvec2 centroid = (a + b + c) / 3.0;
  const glm::dvec2 corners[3] = {a, b, c};
  for (int i = 0; i < 3; ++i) {
    const glm::dvec2 p = corners[i], q = corners[(i + 1) % 3];
    glm::dvec2 n(q.y - p.y, p.x - q.x);
    if (glm::dot(n, centroid - p) > 0.0) n = -n;  // outward
    n = glm::normalize(n);
    planes.push_back({n.x, n.y, 0.0, glm::dot(n, p)});
  }
  return halfSpaces(std::move(planes), ior);
}

bool Solid::contains(glm::dvec3 p) const {
  if (is_sphere) return glm::dot(p - center, p - center) < radius * radius;
  for (const glm::dvec4& plane : planes)
    if (glm::dot(glm::dvec3(plane), p) > plane.w) return false;
  return true;
}

bool Solid::intersect(glm::dvec3 origin, glm::dvec3 dir, double t_min, Hit& hit) const {
  if (is_sphere) {
    const glm::dvec3 oc = origin - center;
    const double b = glm::dot(oc, dir);
    const double c = glm::dot(oc, oc) - radius * radius;
    const double disc = b * b - c;
    if (disc < 0.0) return false;
    const double root = std::sqrt(disc);
    // Numerically stable pair of roots.
    const double q = b > 0.0 ? -(b + root) : -(b - root);
    double t0 = q, t1 = q != 0.0 ? c / q : 0.0;
    if (t0 > t1) std::swap(t0, t1);
    const double t = t0 > t_min ? t0 : t1;
    if (!(t > t_min)) return false;
    hit.t = t;
    hit.normal = glm::normalize(origin + t * dir - center);
    return true;
  }
  double t_enter = -kInfinity, t_exit = kInfinity;
  glm::dvec3 n_enter{0.0}, n_exit{0.0};
  for (const glm::dvec4& plane : planes) {
    const glm::dvec3 n(plane);
    const double denom = glm::dot(n, dir);
    const double dist = plane.w - glm::dot(n, origin);  // > 0: origin on the inner side
    if (denom == 0.0) {
      if (dist < 0.0) return false;
      continue;
    }
    const double t = dist / denom;
    if (denom < 0.0) {
      if (t > t_enter) t_enter = t, n_enter = n;
    } else {
      if (t < t_exit) t_exit = t, n_exit = n;
    }
  }
  if (t_enter > t_exit) return false;
  if (t_enter > t_min) {
    hit.t = t_enter;
    hit.normal = n_enter;
    return true;
  }
  if (t_exit > t_min && t_exit < kInfinity) {
    hit.t = t_exit;
    hit.normal = n_exit;
    return true;
  }
  return false;
}

double ReceiverTally::ringIrradiance(double r0, double r1) const {
  const auto i0 = static_cast<std::size_t>(std::lround(r0 / ring_width));
  const auto i1 = static_cast<std::size_t>(std::lround(r1 / ring_width));
  double flux = 0.0;
  for (std::size_t i = i0; i < i1 && i < ring_flux.size(); ++i) flux += ring_flux[i];
  const double a0 = static_cast<double>(i0) * ring_width, a1 = static_cast<double>(i1) * ring_width;
  return flux / (std::numbers::pi * (a1 * a1 - a0 * a0));
}

double ReceiverTally::encircledFlux(double radius) const {
  const auto n = static_cast<std::size_t>(std::lround(radius / ring_width));
  double flux = 0.0;
  for (std::size_t i = 0; i < n && i < ring_flux.size(); ++i) flux += ring_flux[i];
  return flux;
}

ReceiverTally trace(const std::vector<Solid>& solids, const DirectionalBeam& beam, const Receiver& receiver,
                    const TraceOptions& options) {
  const glm::dvec3 d = glm::normalize(beam.direction);
  glm::dvec3 u, v;
  orthonormalBasis(d, u, v);
  const double beam_area = std::numbers::pi * beam.beam_radius * beam.beam_radius;
  const double flux_per_ray = beam.irradiance * beam_area / static_cast<double>(options.rays);
  // Start far enough back that every solid is ahead of the beam's plane.
  double back = beam.beam_radius;
  for (const Solid& s : solids) {
    if (s.is_sphere) back = std::max(back, glm::length(s.center - beam.beam_center) + s.radius);
    for (const glm::dvec4& p : s.planes) back = std::max(back, std::abs(p.w) + glm::length(beam.beam_center));
  }
  back += 1.0;
  RayRandom shift(options.seed, ~0ull);
  const double s0 = shift.uniform(), s1 = shift.uniform();

  const std::size_t rings = static_cast<std::size_t>(std::ceil(receiver.max_radius / receiver.ring_width));
  const std::size_t texels =
      receiver.map_texels > 0 ? static_cast<std::size_t>(receiver.map_texels) * static_cast<std::size_t>(receiver.map_texels)
                              : 0;
  int threads = options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::max(1, threads);
  std::vector<Tally> tallies(static_cast<std::size_t>(threads));
  const std::size_t cells = options.fluence.dims.x > 0 ? static_cast<std::size_t>(options.fluence.dims.x) *
                                                              static_cast<std::size_t>(options.fluence.dims.y) *
                                                              static_cast<std::size_t>(options.fluence.dims.z)
                                                        : 0;
  for (Tally& t : tallies) {
    t.rings.assign(rings, 0.0);
    t.map.assign(texels, 0.0);
    t.fluence.assign(cells, 0.0);
  }
  auto work = [&](int thread) {
    Tally& tally = tallies[static_cast<std::size_t>(thread)];
    for (std::uint64_t i = static_cast<std::uint64_t>(thread); i < options.rays; i += static_cast<std::uint64_t>(threads)) {
      const glm::dvec2 disc = concentricDisc(r2Point(i, s0, s1)) * beam.beam_radius;
      const glm::dvec3 origin = beam.beam_center + disc.x * u + disc.y * v - back * d;
      RayRandom random(options.seed, i);
      tracePath(solids, receiver, options.fluence, origin, d, flux_per_ray, options.max_interactions, random, tally);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (std::thread& t : pool) t.join();

  ReceiverTally result;
  result.ring_width = receiver.ring_width;
  result.ring_flux.assign(rings, 0.0);
  result.map_flux.assign(texels, 0.0);
  result.map_pitch = receiver.map_pitch;
  result.map_texels = receiver.map_texels;
  result.rays = options.rays;
  result.flux_emitted = flux_per_ray * static_cast<double>(options.rays);
  result.fluence.assign(cells, 0.0);
  for (const Tally& t : tallies) {
    for (std::size_t i = 0; i < cells; ++i) result.fluence[i] += t.fluence[i];
    result.flux_absorbed += t.absorbed;
    for (std::size_t i = 0; i < rings; ++i) result.ring_flux[i] += t.rings[i];
    for (std::size_t i = 0; i < texels; ++i) result.map_flux[i] += t.map[i];
    result.flux_received += t.received;
    result.flux_escaped += t.escaped;
    result.flux_dropped += t.dropped;
  }
  return result;
}

}  // namespace eik::reference
