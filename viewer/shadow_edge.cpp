// Sharp shadow edges on the ground (see shadow_edge.h).
#include "viewer/shadow_edge.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <type_traits>

#include "core/half_float.h"
#include "core/interfaces.h"
#include "core/parallel.h"

namespace eik {
namespace {

// The union of the slots' solids as a signed distance: the least of the slots' trilinear distances
// (voxel centres, clamped at the grid's faces as the textures are).
struct UnionDistance {
  const GridSpec& grid;
  const Field& field;
  int slots;

  double at(const glm::dvec3& x) const {
    const glm::dvec3 g = grid.toVoxel(x) - 0.5;
    const glm::ivec3 hi = grid.dims - 1;
    const glm::dvec3 f0 = glm::floor(g);
    const glm::dvec3 f = g - f0;
    const glm::ivec3 i0 = glm::clamp(glm::ivec3(f0), glm::ivec3(0), hi);
    const glm::ivec3 i1 = glm::clamp(glm::ivec3(f0) + 1, glm::ivec3(0), hi);
    // The eight taps' offsets in floats from the first (the field's layout: x fastest, then y, z).
    const std::size_t components = static_cast<std::size_t>(field.components);
    const std::size_t sx = static_cast<std::size_t>(grid.dims.x), sxy = sx * static_cast<std::size_t>(grid.dims.y);
    const std::size_t dx = static_cast<std::size_t>(i1.x - i0.x) * components;
    const std::size_t dy = static_cast<std::size_t>(i1.y - i0.y) * sx * components;
    const std::size_t dz = static_cast<std::size_t>(i1.z - i0.z) * sxy * components;
    const float* base = field.voxel(grid.index(i0.x, i0.y, i0.z));
    double best = 1e30;
    for (int k = 0; k < slots; ++k) {
      const float* p = base + k;
      auto d = [&](std::size_t offset) { return static_cast<double>(p[offset]); };
      const double c00 = d(0) * (1 - f.x) + d(dx) * f.x;
      const double c10 = d(dy) * (1 - f.x) + d(dx + dy) * f.x;
      const double c01 = d(dz) * (1 - f.x) + d(dx + dz) * f.x;
      const double c11 = d(dy + dz) * (1 - f.x) + d(dx + dy + dz) * f.x;
      const double v = (c00 * (1 - f.y) + c10 * f.y) * (1 - f.z) + (c01 * (1 - f.y) + c11 * f.y) * f.z;
      best = std::min(best, v);
    }
    return best;
  }
};

// [t0, t1] of the ray p + t·d (t ≥ 0) inside the box; false when it misses.
bool clipToBox(const glm::dvec3& p, const glm::dvec3& d, const glm::dvec3& lo, const glm::dvec3& hi, double& t0,
               double& t1) {
  t0 = 0.0;
  t1 = 1e30;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-15) {
      if (p[a] < lo[a] || p[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - p[a]) / d[a], tb = (hi[a] - p[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

// The box of the voxel centres whose least slot distance is under the band; false when none is.
// Each row is scanned from its ends for its first and last such voxel (most rows have none).
bool nearSurfaces(const GridSpec& grid, const Field& field, int slots, double band, glm::dvec3& lo, glm::dvec3& hi) {
  const glm::ivec3 dims = grid.dims;
  std::vector<glm::ivec3> slabLo(static_cast<std::size_t>(dims.z), glm::ivec3(INT32_MAX)),
      slabHi(static_cast<std::size_t>(dims.z), glm::ivec3(-1));
  const auto limit = static_cast<float>(band * (1.0 - 1e-6));
  const std::size_t components = static_cast<std::size_t>(field.components);
  parallelFor(0, dims.z, [&](std::int64_t z) {
    glm::ivec3& l = slabLo[static_cast<std::size_t>(z)];
    glm::ivec3& u = slabHi[static_cast<std::size_t>(z)];
    for (int y = 0; y < dims.y; ++y) {
      const float* row = field.voxel(grid.index(0, y, static_cast<int>(z)));
      auto near = [&](int x) {
        const float* d = row + static_cast<std::size_t>(x) * components;
        bool any = false;
        for (int k = 0; k < slots; ++k) any = any || d[k] < limit;
        return any;
      };
      int first = 0;
      while (first < dims.x && !near(first)) ++first;
      if (first == dims.x) continue;
      int last = dims.x - 1;
      while (!near(last)) --last;
      l = glm::min(l, glm::ivec3(first, y, static_cast<int>(z)));
      u = glm::max(u, glm::ivec3(last, y, static_cast<int>(z)));
    }
  });
  glm::ivec3 l(INT32_MAX), u(-1);
  for (std::size_t z = 0; z < slabLo.size(); ++z) {
    l = glm::min(l, slabLo[z]);
    u = glm::max(u, slabHi[z]);
  }
  if (u.x < 0) return false;
  lo = grid.center(l.x, l.y, l.z);
  hi = grid.center(u.x, u.y, u.z);
  return true;
}

// Where the union's distance is the band throughout, in bricks of kBrick³ voxels: each brick's
// Chebyshev distance, in bricks, from the nearest brick that is not (0: the brick itself is near a
// surface, or may be; at most 255). A brick is far when every voxel its points' trilinear taps
// read (its own and the next layer up each axis, clamped at the grid's faces) holds the band (or
// more) in every slot: the trilinear distance anywhere in it is then the band. From a point in a
// brick at distance k ≥ 2, the next (k − 1)·kBrick voxels in any direction stay in far bricks, so
// the march may skip them: the least distance along them is the band it starts from.
class FarBricks {
 public:
  static constexpr int kBrick = 4;

  FarBricks(const GridSpec& grid, const Field& field, int slots, double band) : grid_(grid) {
    dims_ = (grid.dims + kBrick - 1) / kBrick;
    const std::size_t count = static_cast<std::size_t>(dims_.x) * static_cast<std::size_t>(dims_.y) * static_cast<std::size_t>(dims_.z);
    steps_.assign(count, 0);
    const auto limit = static_cast<float>(band * (1.0 - 1e-6));
    const std::size_t components = static_cast<std::size_t>(field.components);
    // Far bricks: 255 (not yet a distance), near ones 0.
    parallelFor(0, dims_.z, [&](std::int64_t bz) {
      for (int by = 0; by < dims_.y; ++by)
        for (int bx = 0; bx < dims_.x; ++bx) {
          const glm::ivec3 b(bx, by, static_cast<int>(bz));
          const glm::ivec3 v0 = b * kBrick, v1 = glm::min(v0 + kBrick, grid.dims - 1);
          bool far = true;
          for (int z = v0.z; z <= v1.z && far; ++z)
            for (int y = v0.y; y <= v1.y && far; ++y) {
              const float* d = field.voxel(grid.index(v0.x, y, z));
              const std::size_t n = static_cast<std::size_t>(v1.x - v0.x + 1) * components;
              for (std::size_t i = 0; i < n; i += components)
                for (int k = 0; k < slots; ++k) far = far && d[i + static_cast<std::size_t>(k)] >= limit;
            }
          steps_[index(b)] = far ? 255 : 0;
        }
    });
    // The Chebyshev distance transform: two raster passes of the 3×3×3 neighbourhood (forward
    // over the 13 neighbours before a brick, backward over the 13 after it) are exact for it.
    auto pass = [&](int sign) {
      const glm::ivec3 start = sign > 0 ? glm::ivec3(0) : dims_ - 1;
      for (int z = start.z; z >= 0 && z < dims_.z; z += sign)
        for (int y = start.y; y >= 0 && y < dims_.y; y += sign)
          for (int x = start.x; x >= 0 && x < dims_.x; x += sign) {
            std::uint8_t& s = steps_[index({x, y, z})];
            if (s == 0) continue;
            int best = s;
            for (int dz = -1; dz <= 0; ++dz)
              for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                  if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;  // not before the brick
                  const glm::ivec3 n(x + sign * dx, y + sign * dy, z + sign * dz);
                  if (glm::any(glm::lessThan(n, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(n, dims_))) continue;
                  best = std::min(best, steps_[index(n)] + 1);
                }
            s = static_cast<std::uint8_t>(std::min(best, 255));
          }
    };
    pass(+1);
    pass(-1);
  }

  // The distance of the brick holding the trilinear lookup's first tap at x (volume space).
  int at(const glm::dvec3& x) const {
    const glm::ivec3 v = glm::clamp(glm::ivec3(glm::floor(grid_.toVoxel(x) - 0.5)), glm::ivec3(0), grid_.dims - 1);
    return steps_[index(v / kBrick)];
  }

 private:
  std::size_t index(const glm::ivec3& b) const {
    return (static_cast<std::size_t>(b.z) * static_cast<std::size_t>(dims_.y) + static_cast<std::size_t>(b.y)) *
               static_cast<std::size_t>(dims_.x) +
           static_cast<std::size_t>(b.x);
  }

  const GridSpec& grid_;
  glm::ivec3 dims_;
  std::vector<std::uint8_t> steps_;
};

}  // namespace

std::vector<float> shadowClearance(const Volume& volume, const ReceiverMap& map, const glm::dvec3& direction) {
  const Field* field = volume.find("interfaces");
  const InterfaceTable table = interfaceTable(volume);
  if (!field || table.empty() || glm::dot(direction, direction) <= 0.0) return {};
  const GridSpec& grid = volume.grid;
  const UnionDistance sdf{grid, *field, static_cast<int>(table.slots.size())};
  const glm::dvec3 voxel = grid.voxelSize();
  const double h = std::min({voxel.x, voxel.y, voxel.z});
  const double band = table.band > 0.0 ? table.band : kInterfaceBandVoxels * h;
  // The march: steps of the distance itself where it is larger (nothing nearer can be skipped: a
  // distance field changes by at most the step), a voxel near and inside the surfaces, and it
  // stops three voxels inside (only the sign and the edge's neighbourhood matter). Where the least
  // distance was found, a parabola through that sample and its two neighbours puts the minimum
  // between them and the distance there is looked up (a grazing ray's distance is a parabola in t
  // near its minimum, s²/(2R) off for a surface of radius of curvature R: the fine steps alone find
  // it within h²/(8R), the parabola's vertex far closer, as fine as steps of a tenth of a voxel).
  // Through bricks far from every surface (FarBricks) it skips ahead.
  const double fine = h, deep = -3.0 * h;
  const glm::dvec3 toLight = -glm::normalize(direction);
  // Only the box of the voxels nearer than the band to a surface (grown by a voxel) is marched:
  // elsewhere the distance is the band.
  glm::dvec3 lo, hi;
  if (!nearSurfaces(grid, *field, sdf.slots, band, lo, hi)) return std::vector<float>(map.texelCount(), static_cast<float>(band));
  lo -= glm::dvec3(h);
  hi += glm::dvec3(h);
  const FarBricks far(grid, *field, sdf.slots, band);
  const double skip_unit = FarBricks::kBrick * h;
  auto march = [&](int i, int j) {
    const glm::dvec3 p = map.texelCenter(i, j);
    double t0 = 0.0, t1 = 0.0;
    if (!clipToBox(p, toLight, lo, hi, t0, t1)) return band;
    double best = band, t_best = 0.0;
    double t_prev = 0.0, d_prev = band;            // the sample before the current one
    double t_left = 0.0, d_left = band;            // the one before the best…
    double t_right = 0.0, d_right = band;          // …and the one after it (t_right < t_best: none yet)
    bool after_best = false, sampled = false;
    for (double t = t0; t <= t1;) {
      const glm::dvec3 x = p + t * toLight;
      const int k = far.at(x);
      if (k >= 2) {
        t += (k - 1) * skip_unit;
        continue;
      }
      const double d = sdf.at(x);
      if (after_best) {
        t_right = t;
        d_right = d;
        after_best = false;
      }
      if (d < best) {
        best = d;
        t_best = t;
        t_left = sampled ? t_prev : t;
        d_left = sampled ? d_prev : d;
        t_right = t;  // none after it yet
        after_best = true;
      }
      if (best < deep) return best;
      t_prev = t;
      d_prev = d;
      sampled = true;
      t += std::max(d, fine);
    }
    // The parabola through (t_left, d_left), (t_best, best), (t_right, d_right), when the best has
    // a sample on each side and is below both.
    if (best < band && t_left < t_best && t_right > t_best && best <= d_left && best <= d_right) {
      const double a = t_best - t_left, b = t_right - t_best;
      const double ga = (d_left - best) / a, gb = (d_right - best) / b;  // slopes down to, up from the best
      // d ≈ best + β·s + γ·s², s = t − t_best: ga = γ·a − β, gb = γ·b + β.
      const double gamma = (ga + gb) / (a + b);
      const double beta = 0.5 * (gb - ga - gamma * (b - a));
      if (gamma > 0.0) {
        const double tv = t_best - beta / (2.0 * gamma);
        if (tv > t_left && tv < t_right) best = std::min(best, sdf.at(p + tv * toLight));
      }
    }
    return best;
  };
  // Coarse to fine: c at every kBlock-th texel first, then each block refined as a quadtree. A
  // block whose four corners have one sign and |c| over half its diagonal (with a margin) keeps
  // that sign throughout (c changes by at most the distance moved: the distance field is
  // 1-Lipschitz, so is its least value along a shifted ray) and gets the corners' bilinear c (only
  // its sign is read there); the others are split in four (c marched at their five new points)
  // down to 2×2 texels, which are marched texel by texel. The margin of two texels keeps every texel
  // next to the edge, whose c the shader interpolates across it, marched.
  constexpr int kBlock = 8;
  const int nx = map.texels.x, ny = map.texels.y;
  const int bx = (nx + kBlock - 1) / kBlock, by = (ny + kBlock - 1) / kBlock;
  std::vector<double> coarse(static_cast<std::size_t>(bx + 1) * static_cast<std::size_t>(by + 1));
  parallelFor(
      0, by + 1,
      [&](std::int64_t cj) {
        for (int ci = 0; ci <= bx; ++ci)
          coarse[static_cast<std::size_t>(cj) * static_cast<std::size_t>(bx + 1) + static_cast<std::size_t>(ci)] =
              march(std::min(ci * kBlock, nx - 1), std::min(static_cast<int>(cj) * kBlock, ny - 1));
      },
      4);
  std::vector<float> clearance(map.texelCount(), static_cast<float>(band));
  auto put = [&](int i, int j, double c) {
    clearance[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i)] = static_cast<float>(c);
  };
  // The block of texels [i0, i0 + size) × [j0, j0 + size) within the map, its corners' c at the
  // texels (i0, j0), (i1, j0), (i0, j1), (i1, j1) with i1 = min(i0 + size, nx − 1) (the next
  // block's first texel, or the map's last).
  auto refine = [&](auto&& self, int i0, int j0, int size, double c00, double c10, double c01, double c11) -> void {
    const int i1 = std::min(i0 + size, nx - 1), j1 = std::min(j0 + size, ny - 1);
    const int iend = std::min(i0 + size, nx), jend = std::min(j0 + size, ny);
    // Every texel of the block lies within half its diagonal of a corner (0.75 > √2/2).
    const double sure = (0.75 * size + 2.0) * map.pitch;
    const bool lit = c00 > sure && c10 > sure && c01 > sure && c11 > sure;
    const bool dark = c00 < -sure && c10 < -sure && c01 < -sure && c11 < -sure;
    if (lit || dark) {
      for (int j = j0; j < jend; ++j)
        for (int i = i0; i < iend; ++i) {
          const double fx = i1 > i0 ? double(i - i0) / (i1 - i0) : 0.0, fy = j1 > j0 ? double(j - j0) / (j1 - j0) : 0.0;
          put(i, j, (1 - fx) * (1 - fy) * c00 + fx * (1 - fy) * c10 + (1 - fx) * fy * c01 + fx * fy * c11);
        }
      return;
    }
    const int half = size / 2;
    if (size <= 2 || i0 + size > nx - 1 || j0 + size > ny - 1) {  // small, or at the map's far side
      for (int j = j0; j < jend; ++j)
        for (int i = i0; i < iend; ++i) put(i, j, march(i, j));
      return;
    }
    const int im = i0 + half, jm = j0 + half;
    const double cm0 = march(im, j0), c0m = march(i0, jm), cmm = march(im, jm), c1m = march(i1, jm), cm1 = march(im, j1);
    self(self, i0, j0, half, c00, cm0, c0m, cmm);
    self(self, im, j0, half, cm0, c10, cmm, c1m);
    self(self, i0, jm, half, c0m, cmm, c01, cm1);
    self(self, im, jm, half, cmm, c1m, cm1, c11);
  };
  parallelFor(
      0, static_cast<std::int64_t>(bx) * by,
      [&](std::int64_t b) {
        const int bi = static_cast<int>(b % bx), bj = static_cast<int>(b / bx);
        const double* row0 = &coarse[static_cast<std::size_t>(bj) * static_cast<std::size_t>(bx + 1)];
        const double* row1 = row0 + (bx + 1);
        refine(refine, bi * kBlock, bj * kBlock, kBlock, row0[bi], row0[bi + 1], row1[bi], row1[bi + 1]);
      },
      4);
  return clearance;
}

namespace {

// receiverTexels, each texel's RGBA stored as `Out` (float, or half bits through toHalf); with
// `grey`, only its R and A (receiverTexelsGrey).
template <typename Out>
std::vector<Out> texelsOf(const ReceiverLayer& layer, const std::vector<float>& clearance, bool grey = false) {
  const ReceiverMap& map = *layer.map;
  const std::size_t n = map.texelCount();
  const std::size_t channels = grey ? 2 : 4;
  const bool edges = clearance.size() == n;
  const int nx = map.texels.x, ny = map.texels.y;
  auto c = [&](int i, int j) {
    return static_cast<double>(clearance[static_cast<std::size_t>(std::clamp(j, 0, ny - 1)) * static_cast<std::size_t>(nx) +
                                         static_cast<std::size_t>(std::clamp(i, 0, nx - 1))]);
  };
  // The lit fraction of texel (i, j): 0 or 1 unless the bilinear c changes sign within it, i.e.
  // the texel or a neighbour has the other sign (none can within 2 pitches: they lie within 1.5);
  // then 8×8 points of the texel, each at offset (a, b) ∈ (−½, ½)² from its centre, of the bilinear
  // c between the centres around it, as the texture unit interpolates it.
  auto litFraction = [&](int i, int j) {
    const double c0 = c(i, j);
    const double whole = c0 >= 0.0 ? 1.0 : 0.0;
    if (std::abs(c0) > 2.0 * map.pitch) return whole;
    bool mixed = false;
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) mixed = mixed || ((c(i + di, j + dj) >= 0.0) != (c0 >= 0.0));
    if (!mixed) return whole;
    int lit = 0;
    for (int sb = 0; sb < 8; ++sb) {
      for (int sa = 0; sa < 8; ++sa) {
        const double a = (sa + 0.5) / 8.0 - 0.5, b = (sb + 0.5) / 8.0 - 0.5;
        const int ia = a < 0.0 ? i - 1 : i, jb = b < 0.0 ? j - 1 : j;
        const double fx = a < 0.0 ? 1.0 + a : a, fy = b < 0.0 ? 1.0 + b : b;
        const double v = (1 - fx) * (1 - fy) * c(ia, jb) + fx * (1 - fy) * c(ia + 1, jb) +
                         (1 - fx) * fy * c(ia, jb + 1) + fx * fy * c(ia + 1, jb + 1);
        lit += v >= 0.0;
      }
    }
    return lit / 64.0;
  };
  const glm::dvec3 normal = glm::cross(map.u, map.v);
  std::vector<Out> rgba(channels * n);
  parallelFor(
      0, ny,
      [&](std::int64_t row) {
        const int j = static_cast<int>(row);
        const std::size_t first = static_cast<std::size_t>(j) * static_cast<std::size_t>(nx);
        // The row as floats (into the output, or a buffer the halves are made from at once).
        thread_local std::vector<float> buffer;
        float* out_row = nullptr;
        if constexpr (std::is_same_v<Out, float>) {
          if (grey) throw std::logic_error("receiverTexels: grey texels are halves only");
          out_row = &rgba[4 * first];
        } else {
          buffer.resize(4 * static_cast<std::size_t>(nx));
          out_row = buffer.data();
        }
        for (int i = 0; i < nx; ++i) {
          const std::size_t t = first + static_cast<std::size_t>(i);
          float* out = out_row + 4 * static_cast<std::size_t>(i);
          const glm::vec3 e = map.rgb(t);
          for (int k = 0; k < 3; ++k) out[k] = e[k];
          out[3] = edges ? clearance[t] : 1.0f;
          if (!layer.other_lights.empty()) {
            const glm::dvec3 others = otherLightsIrradiance(layer, map.texelCenter(i, j), normal);
            for (int k = 0; k < 3; ++k) out[k] -= static_cast<float>(others[k]);
          }
          const double shaded = edges ? 1.0 - litFraction(i, j) : 0.0;
          if (shaded > 0.0) {
            const glm::dvec3 D = bakedDirectIrradiance(layer, map.texelCenter(i, j), normal);
            for (int k = 0; k < 3; ++k) out[k] += static_cast<float>(D[k] * shaded);
          }
        }
        if constexpr (!std::is_same_v<Out, float>) {
          if (grey)  // R and A of each texel, packed in place (G and B equal R: greyReceiverTexels)
            for (std::size_t i = 0; i < static_cast<std::size_t>(nx); ++i) {
              buffer[2 * i] = buffer[4 * i];
              buffer[2 * i + 1] = buffer[4 * i + 3];
            }
          const std::size_t count = channels * static_cast<std::size_t>(nx);
          toHalf(std::span<const float>(buffer.data(), count), std::span<std::uint16_t>(&rgba[channels * first], count));
        }
      },
      16);
  return rgba;
}

}  // namespace

std::vector<float> receiverTexels(const ReceiverLayer& layer, const std::vector<float>& clearance) {
  return texelsOf<float>(layer, clearance);
}

std::vector<std::uint16_t> receiverTexelsHalf(const ReceiverLayer& layer, const std::vector<float>& clearance) {
  return texelsOf<std::uint16_t>(layer, clearance, greyReceiverTexels(layer));
}

bool greyReceiverTexels(const ReceiverLayer& layer) {
  auto grey = [](const glm::dvec3& p) { return p.x == p.y && p.y == p.z; };
  if (!layer.map || layer.map->components != 1 || !grey(layer.light_power)) return false;
  for (const ReceiverLayer::Light& light : layer.other_lights)
    if (!grey(light.power)) return false;
  return true;
}

}  // namespace eik
