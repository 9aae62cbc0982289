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
  std::vector<double> rings, map;
  double received = 0.0, escaped = 0.0, dropped = 0.0;
};

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
void tracePath(const std::vector<Solid>& solids, const Receiver& receiver, glm::dvec3 origin, glm::dvec3 dir,
               double flux, int max_interactions, RayRandom& random, Tally& tally) {
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
          tallyOnReceiver(receiver, origin + t_plane * dir, flux, tally);
          return;
        }
      }
    }
    if (nearest_solid < 0) {
      // Inside a solid with no exit can only be rounding at a grazing hit: count it as escaped.
      tally.escaped += flux;
      return;
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
  for (Tally& t : tallies) {
    t.rings.assign(rings, 0.0);
    t.map.assign(texels, 0.0);
  }
  auto work = [&](int thread) {
    Tally& tally = tallies[static_cast<std::size_t>(thread)];
    for (std::uint64_t i = static_cast<std::uint64_t>(thread); i < options.rays; i += static_cast<std::uint64_t>(threads)) {
      const glm::dvec2 disc = concentricDisc(r2Point(i, s0, s1)) * beam.beam_radius;
      const glm::dvec3 origin = beam.beam_center + disc.x * u + disc.y * v - back * d;
      RayRandom random(options.seed, i);
      tracePath(solids, receiver, origin, d, flux_per_ray, options.max_interactions, random, tally);
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
  for (const Tally& t : tallies) {
    for (std::size_t i = 0; i < rings; ++i) result.ring_flux[i] += t.rings[i];
    for (std::size_t i = 0; i < texels; ++i) result.map_flux[i] += t.map[i];
    result.flux_received += t.received;
    result.flux_escaped += t.escaped;
    result.flux_dropped += t.dropped;
  }
  return result;
}

}  // namespace eik::reference
