// ring_compare: the measuring tool of the side-by-side benchmark of exact optics, Eikonal and
// POV-Ray's photon map (scripts/bench_exact_optics.sh; the figures are in BENCHMARKS.md).
//
// The scene, the same for every renderer: a glass sphere R = 1, n = 1.5, centre (0, 1.5, 0), over
// the floor y = 0 (albedo 0.8), lit straight down by a sun of irradiance 1 W/m², nothing else. The
// paraxial focus f = nR/(2(n − 1)) = 1.5 from the centre lies on the floor: a caustic at (0, 0, 0),
// spherical aberration around it, the shadow's edge at r = 1. Every mode reduces one renderer's
// floor irradiance E (W/m², planar) to the same figures, written as JSON:
//   - the mean E over the rings r = 0–0.1, 0.1–0.2, 0.2–0.3, 0.3–0.4, 0.4–0.6, 0.6–0.9, 0.9–1.0,
//     1.0–1.1, 1.1–1.3 around the caustic's centre (those of lightsim/exact_optics_test.cpp), and
//     over the far ring 2.5–3.5 (direct light, plus what the sphere reflects there);
//   - the encircled flux Φ(r < 0.2) (the caustic's core) and Φ(r < 1) (all under the sphere), W;
//   - the shadow radius: where the radial profile first climbs past E = ½ going out from r = 0.9.
//
//   ring_compare trace -o exact.json [--rays N]        the exact tracer (tests/reference/exact_optics.h)
//   ring_compare trace --through-map BAKED.vol.json -o e.json   the same, binned into that map's texels
//   ring_compare map BAKED.vol.json -o eik.json         the receiver map lightsim baked (texel centres)
//   ring_compare image FLOOR.exr --camera E:T:FOV -o img.json [--albedo 0.8] [--pov]
//                                                        a rendered image of the floor
//   ring_compare compare exact.json A.json B.json ...   the Markdown table (ratios to exact)
//
// `map`, `image` and `trace` take --label TEXT and --time NAME=SECONDS (repeatable) that are carried
// into the JSON and shown by `compare` (`trace` records its own wall time when none is given).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "core/image_io.h"
#include "core/receiver_map.h"
#include "core/volume.h"
#include "tests/reference/exact_optics.h"
#include "tests/reference/map_binning.h"

namespace {

using nlohmann::json;

constexpr int kRings = 9;
constexpr double kEdges[kRings + 1] = {0.0, 0.1, 0.2, 0.3, 0.4, 0.6, 0.9, 1.0, 1.1, 1.3};
constexpr double kFar0 = 2.5, kFar1 = 3.5;  // the far ring: direct light (and reflections)
constexpr double kMaxRadius = 3.5;
const glm::dvec3 kSphereCenter{0.0, 1.5, 0.0};
constexpr double kSphereRadius = 1.0, kSphereIor = 1.5;

double annulusArea(double r0, double r1) { return std::numbers::pi * (r1 * r1 - r0 * r0); }

// A radial profile of the floor irradiance around (0, 0, 0): bins of width `width`, each holding
// Σ E·w and Σ w of the samples whose centre falls in it (w: the floor area the sample stands for).
struct Profile {
  double width = 0.0025;
  std::vector<double> ew, w;
  // Whether the samples tile the floor (the tracer's rings, the map's texels): then the flux through
  // a disc is Σ E·w. An image sees only part of each ring: the flux is Σ mean·annulus area.
  bool tiles = true;

  explicit Profile(double bin_width) : width(bin_width) {
    const auto n = static_cast<std::size_t>(std::lround(kMaxRadius / width));
    ew.assign(n, 0.0);
    w.assign(n, 0.0);
  }
  void add(double r, double e, double area) {
    const auto i = static_cast<std::size_t>(r / width);
    if (i >= w.size()) return;
    ew[i] += e * area;
    w[i] += area;
  }
  std::size_t bin(double r) const { return static_cast<std::size_t>(std::lround(r / width)); }
  bool valid(std::size_t i) const { return w[i] > 0.0; }
  double mean(std::size_t i) const { return ew[i] / w[i]; }
  // The mean of bin i, linearly interpolated from the nearest filled bins when it holds no sample.
  double filled(std::size_t i) const {
    if (valid(i)) return mean(i);
    std::size_t lo = i, hi = i;
    while (lo > 0 && !valid(lo)) --lo;
    while (hi + 1 < w.size() && !valid(hi)) ++hi;
    if (!valid(lo) && !valid(hi)) return 0.0;
    if (!valid(lo)) return mean(hi);
    if (!valid(hi)) return mean(lo);
    const double t = static_cast<double>(i - lo) / static_cast<double>(hi - lo);
    return (1.0 - t) * mean(lo) + t * mean(hi);
  }
  // Area-weighted mean of E over r0 ≤ r < r1 (bin edges). The samples' own areas weight them; a
  // part of the ring with no sample is left out (an image sees only part of each ring).
  // `uncovered_e` ≥ 0: the part of the ring's true area that no sample covers gets that value
  // instead (the map: the viewer shades the floor beyond it with the direct light).
  double ring(double r0, double r1, double uncovered_e = -1.0) const {
    double sum_ew = 0.0, sum_w = 0.0;
    for (std::size_t i = bin(r0); i < bin(r1) && i < w.size(); ++i) sum_ew += ew[i], sum_w += w[i];
    if (uncovered_e >= 0.0) {
      const double missing = std::max(0.0, annulusArea(r0, r1) - sum_w);
      sum_ew += missing * uncovered_e;
      sum_w += missing;
    }
    return sum_w > 0.0 ? sum_ew / sum_w : std::nan("");
  }
  // Flux (W) through the disc r < radius.
  double encircled(double radius) const {
    double flux = 0.0;
    for (std::size_t i = 0; i < bin(radius) && i < w.size(); ++i)
      flux += tiles ? ew[i] : filled(i) * annulusArea(i * width, (i + 1) * width);
    return flux;
  }
  // The shadow's edge: going out from r = 0.9, the first place where E climbs past ½, linear
  // between the centres of consecutive filled bins (lightsim/exact_optics_test.cpp does the same).
  double shadowRadius() const {
    std::size_t prev = bin(0.9);
    while (prev < w.size() && !valid(prev)) ++prev;
    for (std::size_t i = prev + 1; i < w.size() && i * width < 1.3; ++i) {
      if (!valid(i)) continue;
      const double lo = mean(prev), hi = mean(i);
      if (lo < 0.5 && hi >= 0.5) {
        const double t = (0.5 - lo) / (hi - lo);
        return ((prev + 0.5) + t * static_cast<double>(i - prev)) * width;
      }
      prev = i;
    }
    return std::nan("");
  }
};

json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// The figures every mode writes.
json summarize(const Profile& p, double uncovered_e = -1.0) {
  json rings = json::array();
  for (int k = 0; k < kRings; ++k) rings.push_back(num(p.ring(kEdges[k], kEdges[k + 1], uncovered_e)));
  json j;
  j["rings"] = rings;
  j["far"] = num(p.ring(kFar0, kFar1, uncovered_e));
  j["encircled_02"] = num(p.encircled(0.2));
  j["encircled_1"] = num(p.encircled(1.0));
  j["shadow_radius"] = num(p.shadowRadius());
  j["bin_width"] = p.width;
  // The radial profile itself out to r = 1.5 (bin means; null where a bin holds no sample).
  json profile = json::array();
  for (std::size_t i = 0; i < p.bin(1.5); ++i) profile.push_back(p.valid(i) ? num(p.mean(i)) : json(nullptr));
  j["profile"] = profile;
  return j;
}

// --time NAME=SECONDS → [[NAME, SECONDS], ...] (kept in order).
json parseTimes(const std::vector<std::string>& items) {
  json times = json::array();
  for (const std::string& item : items) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("--time wants NAME=SECONDS, got " + item);
    times.push_back({item.substr(0, eq), std::stod(item.substr(eq + 1))});
  }
  return times;
}

void writeJson(const std::string& path, const json& j) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << j.dump(2) << "\n";
}

json readJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  return json::parse(in);
}

// ---------------------------------------------------------------------------------------------
// trace: the exact answer. A beam of irradiance 1 straight down filling a disc of radius 3.6 around
// the sphere's axis (so the floor out to r = 3.5 gets all its light), traced with exact Fresnel and
// every bounce (tests/reference/exact_optics.h); rings of width 0.0025 on the floor.

// Builds the texel-centre profile of a map (as `map` below measures a baked one).
Profile mapProfile(const eik::ReceiverMap& map, const std::vector<double>& irradiance, double* covered_to) {
  Profile p(0.0025);
  const double a = map.pitch * map.pitch;
  *covered_to = 1e9;  // the largest radius the map covers all round
  for (int j = 0; j < map.texels.y; ++j)
    for (int i = 0; i < map.texels.x; ++i) {
      const glm::dvec3 c = map.texelCenter(i, j);
      p.add(std::hypot(c.x, c.z), irradiance[static_cast<std::size_t>(j) * map.texels.x + i], a);
      if (i == 0 || j == 0 || i + 1 == map.texels.x || j + 1 == map.texels.y)
        *covered_to = std::min(*covered_to, std::hypot(c.x, c.z));
    }
  return p;
}

// `through_map` (a baked volume): the exact answer as that volume's receiver map sees it — the
// tracer's flux binned into the same texels, each texel's mean irradiance binned by its centre. At
// the shadow's edge (r = 1, where E jumps twentyfold) a texel-centre ring mixes in the neighbouring
// ring's light whatever the bake: this row shows how much, so the bake's rows can be read against it.
json modeTrace(std::uint64_t rays, std::uint64_t seed, int threads, const std::string& through_map) {
  eik::reference::DirectionalBeam beam;
  beam.direction = {0.0, -1.0, 0.0};
  beam.beam_center = kSphereCenter;
  beam.beam_radius = kMaxRadius + 0.1;
  beam.irradiance = 1.0;
  eik::reference::Receiver receiver;  // the plane y = 0 facing up, centred on (0, 0, 0)
  receiver.ring_width = 0.0025;
  receiver.max_radius = kMaxRadius;
  eik::ReceiverMap map;
  if (!through_map.empty()) {
    const eik::Volume volume = eik::readVolume(through_map);
    if (volume.receivers.empty()) throw std::runtime_error(through_map + ": no receiver map");
    map = volume.receivers.front();
    if (map.texels.x != map.texels.y) throw std::runtime_error(through_map + ": the tracer's map must be square");
    eik::reference::binLikeMap(map, receiver);
  }
  eik::reference::TraceOptions options;
  options.rays = rays;
  options.seed = seed;
  options.threads = threads;
  const eik::reference::ReceiverTally tally =
      eik::reference::trace({eik::reference::Solid::sphere(kSphereCenter, kSphereRadius, kSphereIor)}, beam,
                            receiver, options);
  Profile p(tally.ring_width);
  for (std::size_t i = 0; i < tally.ring_flux.size() && i < p.w.size(); ++i) {
    const double area = annulusArea(i * tally.ring_width, (i + 1) * tally.ring_width);
    p.ew[i] = tally.ring_flux[i];  // Σ E·w is the flux through the ring
    p.w[i] = area;
  }
  if (!through_map.empty()) {
    std::vector<double> e(tally.map_flux.size());
    for (std::size_t t = 0; t < e.size(); ++t) e[t] = tally.map_flux[t] / (map.pitch * map.pitch);
    double covered_to = 0.0;
    json j = summarize(mapProfile(map, e, &covered_to), 1.0);
    j["kind"] = "map";
    j["texels"] = {map.texels.x, map.texels.y};
    j["pitch"] = map.pitch;
    j["map_covers_radius"] = covered_to;
    j["rays"] = rays;
    return j;
  }
  json j = summarize(p);
  j["kind"] = "exact";
  j["rays"] = rays;
  j["flux_dropped"] = tally.flux_dropped;
  j["flux_escaped"] = tally.flux_escaped;
  j["flux_emitted"] = tally.flux_emitted;
  return j;
}

// ---------------------------------------------------------------------------------------------
// map: the receiver map lightsim baked onto the ground (core/receiver_map.h): each texel's planar
// irradiance (red channel; the scene is grey) stands for its texel's area, binned by its centre,
// like lightsim/exact_optics_test.cpp's ringsOf. Where a ring reaches beyond the map the viewer
// shades the floor with the direct light (docs/physics.md "Receivers"): `direct` W/m² there.

json modeMap(const std::string& volume_path, double direct) {
  const eik::Volume volume = eik::readVolume(volume_path);
  if (volume.receivers.empty()) throw std::runtime_error(volume_path + ": no receiver map");
  const eik::ReceiverMap& map = volume.receivers.front();
  std::vector<double> e(map.texelCount());
  for (std::size_t t = 0; t < e.size(); ++t) e[t] = map.rgb(t).x;
  double covered_to = 0.0;
  json j = summarize(mapProfile(map, e, &covered_to), direct);
  j["kind"] = "map";
  j["texels"] = {map.texels.x, map.texels.y};
  j["pitch"] = map.pitch;
  j["map_covers_radius"] = covered_to;
  j["grid_dims"] = {volume.grid.dims.x, volume.grid.dims.y, volume.grid.dims.z};
  return j;
}

// ---------------------------------------------------------------------------------------------
// image: a render of the floor from a known pinhole camera. Each pixel's ray is rebuilt exactly as
// the viewer builds it (viewer/camera.cpp: glm::lookAt and glm::perspective, near 0.01, far 1000;
// shaders/viewer/raymarch.frag primaryRay: clip (uv·2 − 1, 1, 1) through the inverse view-projection;
// rows top to bottom after the read-back's flip, so uv = ((x + ½)/W, 1 − (y + ½)/H)) and carried
// to the floor plane y = 0. A pixel is kept when that floor point lies on the ground square and the
// straight segment from the eye to it misses the sphere grown to `hide_radius` (so neither the
// sphere nor its refraction/reflection is in the sample). Its radiance L gives E = π·L/ρ for a
// Lambertian floor (the viewer; docs/scene-format.md), or E = L/ρ with --pov (POV-Ray's diffuse
// finish: colour = pigment·diffuse·light·cos θ, no 1/π). Each pixel stands for its footprint on
// the floor (the area between its edges' floor points).

struct PinholeCamera {
  glm::dvec3 eye, target;
  double fov_y_deg;
};

PinholeCamera parseCameraText(const std::string& text) {
  // "EX,EY,EZ:TX,TY,TZ:FOVY_DEG", the viewer's --camera.
  PinholeCamera c{};
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf:%lf,%lf,%lf:%lf", &c.eye.x, &c.eye.y, &c.eye.z, &c.target.x,
                  &c.target.y, &c.target.z, &c.fov_y_deg) != 7)
    throw std::invalid_argument("--camera wants EX,EY,EZ:TX,TY,TZ:FOVY_DEG, got " + text);
  return c;
}

bool segmentHitsSphere(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double r) {
  const glm::dvec3 d = b - a, m = a - c;
  const double A = glm::dot(d, d), B = glm::dot(m, d), C = glm::dot(m, m) - r * r;
  const double disc = B * B - A * C;
  if (disc < 0.0) return false;
  const double s = std::sqrt(disc), t0 = (-B - s) / A, t1 = (-B + s) / A;
  return t1 > 0.0 && t0 < 1.0;
}

json modeImage(const std::string& path, const std::string& camera_text, double albedo, bool pov, double ground_half,
               double hide_radius, double bin_width) {
  const eik::Image image = eik::readImage(path);
  const PinholeCamera cam = parseCameraText(camera_text);
  const double aspect = static_cast<double>(image.width) / image.height;
  const glm::dmat4 view = glm::lookAt(cam.eye, cam.target, glm::dvec3(0.0, 1.0, 0.0));
  const glm::dmat4 proj = glm::perspective(glm::radians(cam.fov_y_deg), aspect, 0.01, 1000.0);
  const glm::dmat4 inv = glm::inverse(proj * view);
  // The floor point seen through image position (x, y) in pixels (y down); false above the horizon.
  auto floorPoint = [&](double x, double y, glm::dvec3& p) {
    const glm::dvec2 uv(x / image.width, 1.0 - y / image.height);
    const glm::dvec4 far = inv * glm::dvec4(uv * 2.0 - 1.0, 1.0, 1.0);
    const glm::dvec3 d = glm::normalize(glm::dvec3(far) / far.w - cam.eye);
    if (d.y >= 0.0) return false;
    p = cam.eye + (-cam.eye.y / d.y) * d;
    return true;
  };
  const double scale = (pov ? 1.0 : std::numbers::pi) / albedo;
  Profile p(bin_width);
  p.tiles = false;
  std::size_t kept = 0, hidden = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      glm::dvec3 c, l, r, t, b;
      if (!floorPoint(x + 0.5, y + 0.5, c) || !floorPoint(x, y + 0.5, l) || !floorPoint(x + 1.0, y + 0.5, r) ||
          !floorPoint(x + 0.5, y, t) || !floorPoint(x + 0.5, y + 1.0, b))
        continue;
      if (std::abs(c.x) > ground_half || std::abs(c.z) > ground_half) continue;
      if (segmentHitsSphere(cam.eye, c, kSphereCenter, hide_radius)) {
        ++hidden;
        continue;
      }
      const float* px = image.at(x, y);
      const double L = image.channels >= 3 ? (px[0] + px[1] + px[2]) / 3.0 : px[0];
      const double footprint = glm::length(glm::cross(r - l, b - t));
      p.add(std::hypot(c.x, c.z), scale * L, footprint);
      ++kept;
    }
  json j = summarize(p);
  j["kind"] = "image";
  j["pixels_used"] = kept;
  j["pixels_hidden_by_sphere"] = hidden;
  j["camera"] = camera_text;
  j["size"] = {image.width, image.height};
  // How much of each ring the image sees (the sphere hides the floor behind it).
  json seen = json::array();
  for (int k = 0; k < kRings; ++k) {
    double area = 0.0;
    for (std::size_t i = p.bin(kEdges[k]); i < p.bin(kEdges[k + 1]); ++i) area += p.w[i];
    seen.push_back(area / annulusArea(kEdges[k], kEdges[k + 1]));
  }
  j["ring_fraction_seen"] = seen;
  return j;
}

// ---------------------------------------------------------------------------------------------
// compare: one Markdown row per JSON file, the first being the exact reference (absolute values);
// the others as ratios to it, with the mean |ratio − 1| over the rings 0.1–1.3 (the issue's
// measure, as lightsim/exact_optics_test.cpp), the worst of those rings, the encircled flux's
// deviation and the shadow radius.

std::string fmtTimes(const json& j) {
  if (!j.contains("times") || j["times"].empty()) return "—";
  std::string s;
  double total = 0.0;
  for (const json& t : j["times"]) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s%s %.1f", s.empty() ? "" : " + ", t[0].get<std::string>().c_str(),
                  t[1].get<double>());
    s += buf;
    total += t[1].get<double>();
  }
  if (j["times"].size() > 1) {
    char buf[48];
    std::snprintf(buf, sizeof buf, " = %.1f", total);
    s += buf;
  }
  return s + " s";
}

double value(const json& v) { return v.is_null() ? std::nan("") : v.get<double>(); }

std::string pct(double ratio) {
  if (!std::isfinite(ratio)) return "—";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.1f %%", 100.0 * (ratio - 1.0));
  return buf;
}

void modeCompare(const std::vector<std::string>& files) {
  const json exact = readJson(files.at(0));
  std::printf("| configuration | time | ");
  for (int k = 0; k < kRings; ++k) std::printf("%g–%g | ", kEdges[k], kEdges[k + 1]);
  std::printf("%g–%g | mean dev 0.1–1.3 | worst ring | Φ(r<0.2) | Φ(r<1) | shadow r |\n", kFar0, kFar1);
  std::printf("| --- | --- |");
  for (int k = 0; k < kRings + 6; ++k) std::printf(" --- |");
  std::printf("\n");
  // The exact row: absolute irradiance (W/m²), flux (W), radius.
  std::printf("| %s | %s | ", exact.value("label", std::string("exact")).c_str(), fmtTimes(exact).c_str());
  for (int k = 0; k < kRings; ++k) std::printf("%.4f | ", value(exact["rings"][k]));
  std::printf("%.4f | — | — | %.4f W | %.4f W | %.4f |\n", value(exact["far"]), value(exact["encircled_02"]),
              value(exact["encircled_1"]), value(exact["shadow_radius"]));
  // The tracer's own noise: every path carries the same flux (Russian roulette keeps it whole), so
  // ring k holds N_k = Φ_k/Φ_ray paths and its mean E a relative standard error of about 1/√N_k
  // (10⁶ rays, the --quick runs: 1.6 % in the ring 0.6–0.9, 3.8 % in 0.9–1; 2·10⁷: 0.4 and 0.8 %). A deviation of
  // the rows below smaller than this is not resolved.
  if (exact.value("kind", std::string()) == "exact" && exact.contains("flux_emitted") && exact.contains("rays") &&
      value(exact["rays"]) > 0.0) {
    const double flux_per_ray = value(exact["flux_emitted"]) / value(exact["rays"]);
    auto sigma = [&](double e, double r0, double r1) {
      const double paths = e * annulusArea(r0, r1) / flux_per_ray;
      return paths > 0.0 ? 1.0 / std::sqrt(paths) : std::numeric_limits<double>::infinity();
    };
    std::printf("| its own noise (1σ, relative) | — | ");
    double mean = 0.0;
    for (int k = 0; k < kRings; ++k) {
      const double s = sigma(value(exact["rings"][k]), kEdges[k], kEdges[k + 1]);
      std::printf("±%.1f %% | ", 100.0 * s);
      if (k > 0) mean += s / (kRings - 1);
    }
    std::printf("±%.1f %% | ±%.1f %% | — | — | — | — |\n", 100.0 * sigma(value(exact["far"]), kFar0, kFar1), 100.0 * mean);
  }
  for (std::size_t f = 1; f < files.size(); ++f) {
    const json j = readJson(files[f]);
    std::printf("| %s | %s | ", j.value("label", files[f]).c_str(), fmtTimes(j).c_str());
    double mean = 0.0, worst = 0.0;
    int worst_k = -1, counted = 0;
    for (int k = 0; k < kRings; ++k) {
      const double ratio = value(j["rings"][k]) / value(exact["rings"][k]);
      std::printf("%.3f | ", ratio);
      if (k == 0 || !std::isfinite(ratio)) continue;
      const double dev = std::abs(ratio - 1.0);
      mean += dev;
      ++counted;
      if (dev > worst) worst = dev, worst_k = k;
    }
    mean /= std::max(counted, 1);
    std::printf("%.3f | %.1f %% | ", value(j["far"]) / value(exact["far"]), 100.0 * mean);
    if (worst_k >= 0)
      std::printf("%s (%g–%g) | ", pct(value(j["rings"][worst_k]) / value(exact["rings"][worst_k])).c_str(),
                  kEdges[worst_k], kEdges[worst_k + 1]);
    else
      std::printf("— | ");
    std::printf("%s | %s | %.4f |\n", pct(value(j["encircled_02"]) / value(exact["encircled_02"])).c_str(),
                pct(value(j["encircled_1"]) / value(exact["encircled_1"])).c_str(), value(j["shadow_radius"]));
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ring_compare: floor-irradiance rings of the glass sphere over a floor, exact optics against "
               "Eikonal and POV-Ray (scripts/bench_exact_optics.sh)",
               "ring_compare"};
  app.require_subcommand(1);
  std::string output, label, input, camera;
  std::vector<std::string> times, files;
  double rays = 2e7, albedo = 0.8, direct = 1.0, ground_half = 4.0, hide_radius = 1.05, bin = 0.005;
  std::uint64_t seed = 1;
  int threads = 0;
  bool pov = false;

  auto common = [&](CLI::App* sub) {
    sub->add_option("-o,--output", output, "the JSON to write")->required();
    sub->add_option("--label", label, "the row's name in the table");
    sub->add_option("--time", times, "NAME=SECONDS, shown in the table (repeatable)");
  };
  CLI::App* trace = app.add_subcommand("trace", "run the exact tracer (tests/reference/exact_optics.h)");
  common(trace);
  trace->add_option("--rays", rays, "rays over the beam's disc of radius 3.6 (default 2e7)");
  trace->add_option("--seed", seed, "random seed (default 1)");
  trace->add_option("--threads", threads, "threads (default 0: all)");
  std::string through_map;
  trace->add_option("--through-map", through_map,
                    "BAKED.vol.json: bin the rays into its receiver map's texels and measure them as `map` does");
  CLI::App* map = app.add_subcommand("map", "rings of the receiver map of a baked volume");
  common(map);
  map->add_option("volume", input, "BAKED.vol.json")->required();
  map->add_option("--direct", direct, "E beyond the map (the direct light, default 1)");
  CLI::App* image = app.add_subcommand("image", "rings of a rendered image of the floor");
  common(image);
  image->add_option("image", input, "FLOOR.exr (linear) or a PNG")->required();
  image->add_option("--camera", camera, "EX,EY,EZ:TX,TY,TZ:FOVY_DEG (the viewer's; up = +y)")->required();
  image->add_option("--albedo", albedo, "floor albedo (default 0.8)");
  image->add_flag("--pov", pov, "POV-Ray's diffuse finish: pixel = albedo·E (no 1/π)");
  image->add_option("--ground-half", ground_half, "half extent of the ground square (default 4)");
  image->add_option("--hide-radius", hide_radius, "skip pixels whose ray passes this near the centre (1.05)");
  image->add_option("--bin", bin, "radial bin width of the profile (default 0.005)");
  CLI::App* compare = app.add_subcommand("compare", "print the Markdown table: exact first, then the others");
  compare->add_option("files", files, "exact.json A.json ...")->required()->expected(2, 1000);
  CLI11_PARSE(app, argc, argv);

  try {
    if (compare->parsed()) {
      modeCompare(files);
      return 0;
    }
    json j;
    const auto start = std::chrono::steady_clock::now();
    if (trace->parsed()) {
      j = modeTrace(static_cast<std::uint64_t>(rays), seed, threads, through_map);
      // The tracer's own wall time, unless the caller gives times.
      if (times.empty())
        times.push_back("trace=" + std::to_string(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
    }
    if (map->parsed()) j = modeMap(input, direct);
    if (image->parsed()) j = modeImage(input, camera, albedo, pov, ground_half, hide_radius, bin);
    j["label"] = label.empty() ? j["kind"].get<std::string>() : label;
    j["times"] = parseTimes(times);
    writeJson(output, j);
    std::printf("%s: rings", j["label"].get<std::string>().c_str());
    for (const json& r : j["rings"]) std::printf(" %.4f", value(r));
    std::printf(", far %.4f, Φ(r<0.2) %.4f, Φ(r<1) %.4f, shadow r %.4f\n", value(j["far"]), value(j["encircled_02"]),
                value(j["encircled_1"]), value(j["shadow_radius"]));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ring_compare: %s\n", e.what());
    return 2;
  }
  return 0;
}
