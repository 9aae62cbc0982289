#include "lightsim/receiver.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/parallel.h"
#include "lightsim/wavefront.h"

namespace eik {

ReceiverMap receiverGeometry(const ReceiverSpec& spec, const LightSpec& light, const GridSpec& grid,
                             const glm::dvec3& box_lo, const glm::dvec3& box_hi) {
  return receiverGeometry(spec, std::vector<LightSpec>{light}, grid, box_lo, box_hi);
}

ReceiverMap receiverGeometry(const ReceiverSpec& spec, const std::vector<LightSpec>& lights, const GridSpec& grid,
                             const glm::dvec3& box_lo, const glm::dvec3& box_hi) {
  ReceiverMap map;
  map.name = spec.name;
  map.point = spec.point;
  map.normal = glm::normalize(spec.normal);
  receiverAxes(map.normal, map.u, map.v);
  glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const LightSpec& light : lights) {
    // The box's corners seen from the light, on the plane.
    glm::dvec2 shadow_lo(std::numeric_limits<double>::infinity()), shadow_hi(-std::numeric_limits<double>::infinity());
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 corner((k & 1) ? box_hi.x : box_lo.x, (k & 2) ? box_hi.y : box_lo.y, (k & 4) ? box_hi.z : box_lo.z);
      glm::dvec3 dir = light.type == LightSpec::Type::Directional ? glm::normalize(light.direction)
                                                                  : corner - light.position;
      const double facing = glm::dot(dir, map.normal);
      if (!(facing < 0.0))
        throw InputError("receiver", spec.name,
                         "the light does not reach the plane from its front side (the plane's normal must face the light)");
      const double height = glm::dot(corner - map.point, map.normal);
      // Corners below the plane project back up along the light; either way onto the plane.
      const glm::dvec3 on_plane = corner - (height / facing) * dir;
      const glm::dvec2 uv = map.planeCoordinates(on_plane);
      shadow_lo = glm::min(shadow_lo, uv);
      shadow_hi = glm::max(shadow_hi, uv);
    }
    // Light the object reflects or bends lands beyond its shadow: the map reaches one shadow-size
    // further on every side, within the plane's square; several lights, the union of theirs.
    const glm::dvec2 grow(std::max(shadow_hi.x - shadow_lo.x, shadow_hi.y - shadow_lo.y));
    lo = glm::min(lo, shadow_lo - grow);
    hi = glm::max(hi, shadow_hi + grow);
  }
  lo = glm::max(lo, glm::dvec2(-spec.half_extent));
  hi = glm::min(hi, glm::dvec2(spec.half_extent));
  if (!(lo.x < hi.x && lo.y < hi.y))
    throw InputError("receiver", spec.name, "the volume's box does not shade any part of the plane's square");
  map.pitch = spec.pitch_voxels * voxelEdge(grid);
  const double longest = std::max(hi.x - lo.x, hi.y - lo.y);
  if (longest / map.pitch > kMaxReceiverTexels) map.pitch = longest / kMaxReceiverTexels;
  map.texels = glm::ivec2(static_cast<int>(std::ceil((hi.x - lo.x) / map.pitch - 1e-9)),
                          static_cast<int>(std::ceil((hi.y - lo.y) / map.pitch - 1e-9)));
  map.texels = glm::max(map.texels, glm::ivec2(1));
  map.origin = lo;
  return map;
}

bool patchFootprint(const Patch& patch, const ReceiverMap& map, std::array<glm::dvec2, 4>& footprint) {
  for (int c = 0; c < 4; ++c) {
    const glm::dvec3 d = patch.w[c];
    const double facing = glm::dot(d, map.normal);
    const double height = glm::dot(patch.x[c] - map.point, map.normal);
    // Parallel to the plane, or above it heading away: the ray never meets it (back along the ray
    // is where it came from, not where it lands).
    if (facing == 0.0 || (facing > 0.0 && height > 0.0)) return false;
    footprint[static_cast<std::size_t>(c)] = map.planeCoordinates(patch.x[c] - (height / facing) * d);
  }
  return true;
}

namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Clips a convex polygon (at most 7 vertices after 4 half-planes of a triangle) against the
// half-plane `sign·(p[axis] − bound) ≤ 0`.
int clipAgainst(const glm::dvec2* in, int count, glm::dvec2* out, int axis, double bound, double sign) {
  int n = 0;
  for (int i = 0; i < count; ++i) {
    const glm::dvec2 a = in[i], b = in[(i + 1) % count];
    const double da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
    if (da <= 0.0) out[n++] = a;
    if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) out[n++] = a + (da / (da - db)) * (b - a);
  }
  return n;
}

// Shoelace as a fan around the first vertex: relative coordinates keep the precision of a polygon
// far smaller than its distance from the origin (a footprint focused onto the plane).
double polygonArea(const glm::dvec2* p, int count) {
  double twice = 0.0;
  for (int i = 1; i + 1 < count; ++i) twice += cross2(p[i] - p[0], p[i + 1] - p[0]);
  return 0.5 * std::abs(twice);
}

// Adds density × area(polygon ∩ texel) to each texel of one row (`row`: its first texel) for a
// convex polygon lying within the row. The polygon's vertical extent h(x) is piecewise linear
// between its vertices' x (continuous and concave inside, as the polygon is convex), so its
// integral H(x) is piecewise quadratic and a texel's overlap is H(x₁) − H(x₀): exact, and a few
// operations a texel instead of a clip.
void depositRow(const ReceiverMap& map, const glm::dvec2* p, int n, const glm::dvec3& density, const TexelRows& out, int j) {
  // A convex polygon of at most 4 vertices clipped by two half-planes has at most 6.
  if (n < 3 || n > 8) return;
  double xs[8];
  for (int k = 0; k < n; ++k) xs[k] = p[k].x;
  std::sort(xs, xs + n);
  // The extent at each breakpoint: the chord of the vertical line x (with a vertical edge at the
  // polygon's left or right end, its whole length: the limit from inside).
  double hs[8];
  for (int k = 0; k < n; ++k) {
    const double x = xs[k];
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int e = 0; e < n; ++e) {
      const glm::dvec2 u = p[e], v = p[(e + 1) % n];
      if (x < std::min(u.x, v.x) || x > std::max(u.x, v.x)) continue;
      if (u.x == v.x) {
        lo = std::min(lo, std::min(u.y, v.y)), hi = std::max(hi, std::max(u.y, v.y));
      } else {
        const double y = u.y + (x - u.x) / (v.x - u.x) * (v.y - u.y);
        lo = std::min(lo, y), hi = std::max(hi, y);
      }
    }
    hs[k] = hi > lo ? hi - lo : 0.0;
  }
  // H at the breakpoints (trapezoids), and H(x) within a segment.
  double cumulative[8];
  cumulative[0] = 0.0;
  for (int k = 0; k + 1 < n; ++k) cumulative[k + 1] = cumulative[k] + 0.5 * (hs[k] + hs[k + 1]) * (xs[k + 1] - xs[k]);
  int segment = 0;
  auto integral = [&](double x) {  // H(x), for non-decreasing x from call to call
    while (segment + 2 < n && x > xs[segment + 1]) ++segment;
    const double width = xs[segment + 1] - xs[segment];
    if (!(width > 0.0)) return cumulative[segment + 1];
    const double t = std::clamp(x - xs[segment], 0.0, width);
    const double slope = (hs[segment + 1] - hs[segment]) / width;
    return cumulative[segment] + t * (hs[segment] + 0.5 * slope * t);
  };
  const double xmin = xs[0], xmax = xs[n - 1];
  const int i0 = std::max(0, static_cast<int>(std::floor((xmin - map.origin.x) / map.pitch)));
  const int i1 = std::min(map.texels.x - 1, static_cast<int>(std::floor((xmax - map.origin.x) / map.pitch)));
  if (i0 > i1) return;
  double left = integral(std::max(xmin, map.origin.x + i0 * map.pitch));
  for (int i = i0; i <= i1; ++i) {
    const double right = integral(std::min(xmax, map.origin.x + (i + 1) * map.pitch));
    const double overlap = right - left;
    if (overlap > 0.0) out.add(j, i, density * overlap);
    left = right;
  }
}

// Adds flux × area(polygon ∩ texel)/area(polygon) to the texels of rows [row_begin, row_end) for a
// convex polygon of up to 4 vertices (a triangle, or a convex footprint whole), row by row.
void depositConvex(const ReceiverMap& map, const glm::dvec2* polygon, int count, double area, const glm::dvec3& flux,
                   const TexelRows& out) {
  const int row_begin = out.row_begin, row_end = out.row_end;
  if (!(area > 0.0)) {
    // A degenerate footprint (all corners on a line or a point): its flux goes to the texel of its centre.
    glm::dvec2 centre(0.0);
    for (int k = 0; k < count; ++k) centre += polygon[k] / static_cast<double>(count);
    const glm::dvec2 t = (centre - map.origin) / map.pitch;
    const int i = static_cast<int>(std::floor(t.x)), j = static_cast<int>(std::floor(t.y));
    if (i >= 0 && j >= std::max(0, row_begin) && i < map.texels.x && j < std::min(map.texels.y, row_end))
      out.add(j, i, flux);
    return;
  }
  double ylo = polygon[0].y, yhi = polygon[0].y;
  for (int k = 1; k < count; ++k) ylo = std::min(ylo, polygon[k].y), yhi = std::max(yhi, polygon[k].y);
  const int j0 = std::max(std::max(0, row_begin), static_cast<int>(std::floor((ylo - map.origin.y) / map.pitch)));
  const int j1 = std::min(std::min(map.texels.y, row_end) - 1, static_cast<int>(std::floor((yhi - map.origin.y) / map.pitch)));
  const glm::dvec3 density = flux / area;
  for (int j = j0; j <= j1; ++j) {
    // The polygon within this row of texels (clipped to the row): a convex polygon whose overlap
    // with each texel of the row is the integral of its vertical extent over the texel's columns.
    const double y0 = map.origin.y + j * map.pitch, y1 = y0 + map.pitch;
    glm::dvec2 buffer_a[8], buffer_b[8];
    for (int k = 0; k < count; ++k) buffer_a[k] = polygon[k];
    int n = clipAgainst(buffer_a, count, buffer_b, 1, y0, -1.0);
    n = clipAgainst(buffer_b, n, buffer_a, 1, y1, 1.0);
    if (n < 3) continue;
    depositRow(map, buffer_a, n, density, out, j);
  }
}

}  // namespace

DirectMapLight directMapLight(const ReceiverMap& map, const LightSpec& light, const std::vector<Patch>& followed) {
  const bool point = light.type != LightSpec::Type::Directional;  // a point or a spot light
  const glm::dvec3 L = point ? glm::dvec3(0.0) : glm::normalize(light.direction);
  // |L·n| for a directional light that reaches the front; a point light's height over the plane.
  const double facing = point ? glm::dot(light.position - map.point, map.normal) : -glm::dot(L, map.normal);
  if (!(facing > 0.0))
    throw InputError("receiver", "light", "direct light on the map needs a light that reaches its front");
  DirectMapLight direct;
  direct.map_ = map;
  direct.map_.irradiance.clear();
  direct.point_ = point;
  direct.light_ = light;
  // The light's flux over each texel: a point light's I·cos θ/d² = I·h/d³ at the texel's centre,
  // times its area (the texel's mean to (pitch/d)², under 10⁻⁴ at a quarter voxel's pitch).
  direct.full_ = light.power * (facing * map.pitch * map.pitch);
  const std::size_t count = followed.size();
  std::vector<std::array<glm::dvec2, 4>> footprints(count);
  std::vector<std::uint8_t> lands(count, 0);
  parallelFor(
      0, static_cast<std::int64_t>(count),
      [&](std::int64_t i) {
        const std::size_t k = static_cast<std::size_t>(i);
        lands[k] = patchFootprint(followed[k], map, footprints[k]) ? 1 : 0;
      },
      1024);
  // What the followed patches would put on the map going straight, by bands of texel rows in
  // parallel (each band adds the patches in order: the sums do not depend on the thread count); a
  // band is made at the first footprint that reaches it. The light's flux over a texel less
  // theirs is its direct light (≥ 0: the two agree to rounding where the patches cover the texel
  // wholly): DirectMapLight::flux.
  constexpr int kRows = DirectMapLight::kRows;
  static_assert(kRows == FootprintSums::kBandRows);
  const int bands = (map.texels.y + kRows - 1) / kRows;
  direct.grey_ = light.power.x == light.power.y && light.power.y == light.power.z;
  for (const Patch& p : followed) direct.grey_ = direct.grey_ && p.flux.x == p.flux.y && p.flux.y == p.flux.z;
  if (direct.grey_)
    direct.followed_grey_.resize(static_cast<std::size_t>(bands));
  else
    direct.followed_.resize(static_cast<std::size_t>(bands));
  const std::size_t band_texels = static_cast<std::size_t>(kRows) * static_cast<std::size_t>(map.texels.x);
  parallelFor(0, bands, [&](std::int64_t band) {
    const int r0 = static_cast<int>(band) * kRows, r1 = r0 + kRows;
    const double y0 = map.origin.y + r0 * map.pitch, y1 = map.origin.y + r1 * map.pitch;
    TexelRows rows{nullptr, map.texels.x, r0, r0, std::min(r1, map.texels.y)};
    for (std::size_t k = 0; k < count; ++k) {
      if (!lands[k]) continue;
      const std::array<glm::dvec2, 4>& f = footprints[k];
      const double lo = std::min(std::min(f[0].y, f[1].y), std::min(f[2].y, f[3].y));
      const double hi = std::max(std::max(f[0].y, f[1].y), std::max(f[2].y, f[3].y));
      if (hi < y0 || lo > y1) continue;
      if (!rows.data && !rows.grey) {  // the band's sums, made at its first footprint
        if (direct.grey_) {
          std::vector<double>& sums = direct.followed_grey_[static_cast<std::size_t>(band)];
          sums.assign(band_texels, 0.0);
          rows.grey = sums.data();
          rows.channels = 1;
        } else {
          std::vector<glm::dvec3>& sums = direct.followed_[static_cast<std::size_t>(band)];
          sums.assign(band_texels, glm::dvec3(0.0));
          rows.data = sums.data();
        }
      }
      depositFootprint(map, f, followed[k].flux, rows);
    }
  });
  return direct;
}

std::vector<glm::dvec3> DirectMapLight::texels() const {
  std::vector<glm::dvec3> out(map_.texelCount());
  parallelFor(0, map_.texels.y, [&](std::int64_t j) {
    for (int i = 0; i < map_.texels.x; ++i)
      out[static_cast<std::size_t>(j) * static_cast<std::size_t>(map_.texels.x) + static_cast<std::size_t>(i)] =
          flux(i, static_cast<int>(j));
  });
  return out;
}

int DirectMapLight::heldBands() const {
  if (grey_)
    return static_cast<int>(
        std::count_if(followed_grey_.begin(), followed_grey_.end(), [](const auto& b) { return !b.empty(); }));
  return static_cast<int>(std::count_if(followed_.begin(), followed_.end(), [](const auto& b) { return !b.empty(); }));
}

FootprintSums::FootprintSums(const ReceiverMap& map, bool grey) : map_(map), channels_(grey ? 1 : 3) {
  map_.irradiance.clear();
  for (int k = 1; k <= kFootprintLevels; ++k) {
    ReceiverMap level = map_;
    level.pitch = map.pitch * static_cast<double>(1 << k);
    level.texels = (map.texels + glm::ivec2((1 << k) - 1)) / (1 << k);
    coarse_.push_back(std::move(level));
  }
  fine_.assign(static_cast<std::size_t>(channels_) * map_.texelCount(), 0.0f);
  if (grey)
    grey_bands_.assign(kFootprintLevels + 1, std::vector<std::vector<double>>(static_cast<std::size_t>(bands())));
  else
    bands_.assign(kFootprintLevels + 1, std::vector<std::vector<glm::dvec3>>(static_cast<std::size_t>(bands())));
}

int FootprintSums::level(const std::array<glm::dvec2, 4>& f) const {
  const glm::dvec2 lo = glm::min(glm::min(f[0], f[1]), glm::min(f[2], f[3]));
  const glm::dvec2 hi = glm::max(glm::max(f[0], f[1]), glm::max(f[2], f[3]));
  double texels = (hi.x - lo.x) * (hi.y - lo.y) / (map_.pitch * map_.pitch);
  int k = 0;
  while (k < kFootprintLevels && !(texels <= kFineFootprintTexels)) {  // NaN: the coarsest
    texels *= 0.25;
    ++k;
  }
  return k;
}

void FootprintSums::deposit(const std::array<glm::dvec2, 4>& footprint, const glm::dvec3& flux, int band) {
  const int k = level(footprint);
  const int rows = kBandRows >> k;
  const ReceiverMap& level_map = k == 0 ? map_ : coarse_[static_cast<std::size_t>(k - 1)];
  const int first = band * rows;
  if (k == 0) {
    depositFootprint(map_, footprint, flux,
                     TexelRows{nullptr, map_.texels.x, 0, first, first + rows, fine_.data(), channels_});
    return;
  }
  const std::size_t texels = static_cast<std::size_t>(rows) * static_cast<std::size_t>(level_map.texels.x);
  if (channels_ == 1) {
    std::vector<double>& block = grey_bands_[static_cast<std::size_t>(k)][static_cast<std::size_t>(band)];
    if (block.empty()) block.assign(texels, 0.0);
    depositFootprint(level_map, footprint, flux,
                     TexelRows{nullptr, level_map.texels.x, first, first, first + rows, nullptr, 1, block.data()});
    return;
  }
  std::vector<glm::dvec3>& block = bands_[static_cast<std::size_t>(k)][static_cast<std::size_t>(band)];
  if (block.empty()) block.assign(texels, glm::dvec3(0.0));
  depositFootprint(level_map, footprint, flux, TexelRows{block.data(), level_map.texels.x, first, first, first + rows});
}

FootprintSums::RowSums FootprintSums::rowSums(int j) const {
  const int band = j / kBandRows;
  RowSums r;
  r.fine = fine_.data() + static_cast<std::size_t>(channels_) * static_cast<std::size_t>(j) * static_cast<std::size_t>(map_.texels.x);
  r.channels = channels_;
  for (int k = 1; k <= kFootprintLevels; ++k) {
    // A band of the map is a whole band of every level (kBandRows is a multiple of 2^k).
    const int rows = kBandRows >> k;
    const std::size_t offset = static_cast<std::size_t>((j >> k) - band * rows) *
                               static_cast<std::size_t>(coarse_[static_cast<std::size_t>(k - 1)].texels.x);
    if (channels_ == 1) {
      const std::vector<double>& block = grey_bands_[static_cast<std::size_t>(k)][static_cast<std::size_t>(band)];
      if (!block.empty()) r.grey_level[k] = block.data() + offset;  // (empty: its sums are 0 there)
      continue;
    }
    const std::vector<glm::dvec3>& block = bands_[static_cast<std::size_t>(k)][static_cast<std::size_t>(band)];
    if (block.empty()) continue;  // its sums are 0 there
    r.level[k] = block.data() + offset;
  }
  return r;
}

glm::dvec3 FootprintSums::RowSums::flux(int i) const {
  // The texel's own flux, then each coarser level's share over it, k = 1, 2, ... in order (the same
  // sums whatever the thread count).
  const float* texel = fine + static_cast<std::size_t>(channels) * static_cast<std::size_t>(i);
  glm::dvec3 f = channels == 1 ? glm::dvec3(texel[0]) : glm::dvec3(texel[0], texel[1], texel[2]);
  for (int k = 1; k <= kFootprintLevels; ++k)
    if (level[k]) f += level[k][i >> k] * (1.0 / static_cast<double>(1 << (2 * k)));
    else if (grey_level[k]) f += glm::dvec3(grey_level[k][i >> k] * (1.0 / static_cast<double>(1 << (2 * k))));
  return f;
}

std::vector<glm::dvec3> FootprintSums::resolve() const {
  std::vector<glm::dvec3> out(map_.texelCount());
  parallelFor(
      0, map_.texels.y,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        const RowSums sums = rowSums(j);
        glm::dvec3* row = out.data() + static_cast<std::size_t>(j) * static_cast<std::size_t>(map_.texels.x);
        for (int i = 0; i < map_.texels.x; ++i) row[i] = sums.flux(i);
      },
      16);
  return out;
}

void FootprintSums::irradiance(const DirectMapLight* extra, double inv_area, std::vector<float>& out) {
  parallelFor(
      0, map_.texels.y,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        const RowSums sums = rowSums(j);
        const std::size_t channels = static_cast<std::size_t>(channels_);
        float* row = fine_.data() + channels * static_cast<std::size_t>(j) * static_cast<std::size_t>(map_.texels.x);
        for (int i = 0; i < map_.texels.x; ++i) {
          glm::dvec3 flux = sums.flux(i);  // (texel i's sums read before they are written over)
          if (extra) flux += extra->flux(i, j);
          for (std::size_t c = 0; c < channels; ++c)
            row[channels * static_cast<std::size_t>(i) + c] = static_cast<float>(flux[static_cast<int>(c)] * inv_area);
        }
      },
      16);
  out = std::move(fine_);
  fine_.clear();
}

double triangleSquareOverlap(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& lo,
                             const glm::dvec2& hi) {
  glm::dvec2 buffer_a[8] = {a, b, c}, buffer_b[8];
  int n = 3;
  n = clipAgainst(buffer_a, n, buffer_b, 0, lo.x, -1.0);
  n = clipAgainst(buffer_b, n, buffer_a, 0, hi.x, 1.0);
  n = clipAgainst(buffer_a, n, buffer_b, 1, lo.y, -1.0);
  n = clipAgainst(buffer_b, n, buffer_a, 1, hi.y, 1.0);
  return n >= 3 ? polygonArea(buffer_a, n) : 0.0;
}

void depositFootprint(const ReceiverMap& map, const std::array<glm::dvec2, 4>& f, const glm::dvec3& flux,
                      std::vector<glm::dvec3>& texel_flux, int row_begin, int row_end) {
  depositFootprint(map, f, flux, TexelRows{texel_flux.data(), map.texels.x, 0, row_begin, row_end});
}

void depositFootprint(const ReceiverMap& map, const std::array<glm::dvec2, 4>& f, const glm::dvec3& flux,
                      const TexelRows& out) {
  const int row_begin = out.row_begin, row_end = out.row_end;
  // An axis-aligned rectangle (a patch straight down onto a level floor, as most of them are
  // outside the volume): its two triangles have equal shares and one density, so each texel gets
  // the density times the product of its overlaps along u and v.
  const bool rect_u = f[0].y == f[1].y && f[1].x == f[2].x && f[2].y == f[3].y && f[3].x == f[0].x;
  const bool rect_v = f[0].x == f[1].x && f[1].y == f[2].y && f[2].x == f[3].x && f[3].y == f[0].y;
  if (rect_u || rect_v) {
    const glm::dvec2 lo = glm::min(f[0], f[2]), hi = glm::max(f[0], f[2]);
    const double area = (hi.x - lo.x) * (hi.y - lo.y);
    if (area > 0.0) {
      const glm::dvec3 density = flux / area;
      const glm::dvec2 tlo = (lo - map.origin) / map.pitch, thi = (hi - map.origin) / map.pitch;
      const int i0 = std::max(0, static_cast<int>(std::floor(std::max(tlo.x, -1.0))));
      const int i1 = std::min(map.texels.x - 1, static_cast<int>(std::floor(std::min(thi.x, static_cast<double>(map.texels.x)))));
      const int j0 = std::max(std::max(0, row_begin), static_cast<int>(std::floor(std::max(tlo.y, -1.0))));
      const int j1 = std::min(std::min(map.texels.y, row_end) - 1,
                              static_cast<int>(std::floor(std::min(thi.y, static_cast<double>(map.texels.y)))));
      for (int j = j0; j <= j1; ++j) {
        const double y0 = map.origin.y + j * map.pitch;
        const double oy = std::min(hi.y, y0 + map.pitch) - std::max(lo.y, y0);
        if (!(oy > 0.0)) continue;
        for (int i = i0; i <= i1; ++i) {
          const double x0 = map.origin.x + i * map.pitch;
          const double ox = std::min(hi.x, x0 + map.pitch) - std::max(lo.x, x0);
          if (ox > 0.0) out.add(j, i, density * (ox * oy));
        }
      }
      return;
    }
  }
  const double a1 = 0.5 * std::abs(cross2(f[1] - f[0], f[2] - f[0]));
  const double a2 = 0.5 * std::abs(cross2(f[2] - f[0], f[3] - f[0]));
  const double total = a1 + a2;
  // A convex footprint (its four turns of one sign) whole: its triangles' shares by area give both
  // one density, flux/total, so the quadrilateral gets the same overlaps in half the clipping.
  double turns[4];
  for (int k = 0; k < 4; ++k) turns[k] = cross2(f[(k + 1) % 4] - f[k], f[(k + 2) % 4] - f[(k + 1) % 4]);
  const bool convex = (turns[0] > 0.0 && turns[1] > 0.0 && turns[2] > 0.0 && turns[3] > 0.0) ||
                      (turns[0] < 0.0 && turns[1] < 0.0 && turns[2] < 0.0 && turns[3] < 0.0);
  if (convex) {
    depositConvex(map, f.data(), 4, total, flux, out);
    return;
  }
  const double share = total > 0.0 ? a1 / total : 0.5;
  const glm::dvec2 t1[3] = {f[0], f[1], f[2]}, t2[3] = {f[0], f[2], f[3]};
  depositConvex(map, t1, 3, a1, flux * share, out);
  depositConvex(map, t2, 3, a2, flux * (1.0 - share), out);
}

}  // namespace eik
