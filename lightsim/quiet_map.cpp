#include "lightsim/quiet_map.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/parallel.h"

namespace eik {

namespace {

// What a voxel contributes to a sample: equal signatures give equal optics.
struct Signature {
  int signs = 0;       // bit k: slot distance k < 0 (sharp interfaces only)
  float n = 0.0f;      // n (compared only where it is used: smoothed volumes and graded slots)
  bool uses_n = true;
  glm::vec3 sigma{0.0f};
  bool noisy = false;  // noisy by itself
  bool operator==(const Signature& o) const {
    return signs == o.signs && uses_n == o.uses_n && (!uses_n || n == o.n) && sigma == o.sigma;
  }
};

}  // namespace

namespace {

QuietMap::FieldViews viewsOf(const GridSpec& grid, const std::vector<glm::vec4>& ior_grad,
                             const std::vector<glm::vec4>& distances, const std::vector<glm::vec3>& sigma_a) {
  QuietMap::FieldViews v;
  if (ior_grad.size() != grid.count()) return v;
  v.ior = &ior_grad[0].x;
  v.ior_stride = 4;
  v.grad = &ior_grad[0].y;
  v.grad_stride = 4;
  if (distances.size() == grid.count()) v.distances = &distances[0].x;
  if (sigma_a.size() == grid.count()) v.sigma_a = &sigma_a[0].x;
  return v;
}

}  // namespace

QuietMap::QuietMap(const GridSpec& grid, const std::vector<glm::vec4>& ior_grad, const std::vector<glm::vec4>& distances,
                   const InterfaceTable& table, const std::vector<glm::vec3>& sigma_a)
    : QuietMap(grid, viewsOf(grid, ior_grad, distances, sigma_a), table) {}

QuietMap::QuietMap(const GridSpec& grid, const FieldViews& fields, const InterfaceTable& table) : grid_(grid) {
  const glm::ivec3 d = grid.dims;
  const bool sharp = !table.empty() && fields.distances;
  // n and ∇n are looked at in graded materials only (and everywhere without sharp interfaces).
  const bool graded_slot = std::any_of(table.slots.begin(), table.slots.end(), [](const InterfaceSlot& s) { return s.graded; });
  const bool needs_n = !sharp || graded_slot;
  if (d.x <= 0 || d.y <= 0 || d.z <= 0 || (needs_n && (!fields.ior || !fields.grad))) return;
  chooseBricks(sharp ? 100 : 160);
  const int slots = sharp ? static_cast<int>(table.slots.size()) : 0;
  auto signature = [&](std::size_t v) {
    Signature s;
    bool graded = true;  // the n and ∇n fields are what a sample returns
    if (sharp && fields.slot_signs) {
      const int bits = fields.slot_signs[v];
      s.signs = bits & 15;
      s.noisy = (bits >> 4) != 0;
      graded = s.signs != 0 && table.slots[static_cast<std::size_t>(std::countr_zero(static_cast<unsigned>(s.signs)))].graded;
    } else if (sharp) {
      const float* dist = fields.distances + v * fields.distances_stride;
      int material = -1;
      for (int k = 0; k < slots; ++k) {
        if (dist[k] == 0.0f) s.noisy = true;
        if (dist[k] < 0.0f) {
          s.signs |= 1 << k;
          if (material < 0) material = k;
        }
      }
      graded = material >= 0 && table.slots[static_cast<std::size_t>(material)].graded;
    }
    s.uses_n = graded;
    if (graded) {
      s.n = fields.ior[v * fields.ior_stride];
      const float* g = fields.grad + v * fields.grad_stride;
      if (g[0] != 0.0f || g[1] != 0.0f || g[2] != 0.0f) s.noisy = true;
    }
    if (fields.sigma_a) {
      const float* sa = fields.sigma_a + v * fields.sigma_stride;
      s.sigma = glm::vec3(sa[0], sa[1], sa[2]);
    }
    return s;
  };
  std::vector<std::uint8_t> flag(static_cast<std::size_t>(bricks_.x) * bricks_.y * bricks_.z, 0);
  auto brick = [&](int x, int y, int z) -> std::uint8_t& { return brickFlag(flag, x, y, z); };
  if (sharp && fields.slot_signs && !fields.sigma_a && !graded_slot) {
    // Sharp constant-n materials without σa: a voxel's signature is its signs alone, noisy where a
    // distance is 0 (what `signature` gives, from one byte a voxel).
    const std::uint8_t* signs = fields.slot_signs;
    parallelFor(0, bricks_.z, [&](std::int64_t layer) {
      const int z0 = static_cast<int>(layer) * brick_, z1 = std::min(d.z, z0 + brick_);
      const std::size_t sy = static_cast<std::size_t>(d.x), sz = sy * static_cast<std::size_t>(d.y);
      for (int z = z0; z < z1; ++z)
        for (int y = 0; y < d.y; ++y) {
          const std::size_t row = grid.index(0, y, z);
          for (int x = 0; x < d.x; ++x) {
            const std::size_t i = row + static_cast<std::size_t>(x);
            const int s = signs[i] & 15;
            bool noisy = (signs[i] >> 4) != 0;
            if (x + 1 < d.x && (signs[i + 1] & 15) != s) noisy = true, brick(x + 1, y, z) = 1;
            if (y + 1 < d.y && (signs[i + sy] & 15) != s) noisy = true, brick(x, y + 1, z) = 1;
            if (z + 1 < d.z && (signs[i + sz] & 15) != s) {
              noisy = true;
              if (z + 1 < z1) brick(x, y, z + 1) = 1;  // in this layer
            }
            if (z == z0 && z > 0 && (signs[i - sz] & 15) != s) noisy = true;
            if (noisy) brick(x, y, z) = 1;
          }
        }
    });
    buildTable(flag);
    return;
  }
  // By layers of bricks in parallel, each layer writing only its own bricks: a pair of voxels that
  // differ across two layers is flagged by each layer on its side (the upper one compares its
  // lowest voxels with those below).
  parallelFor(0, bricks_.z, [&](std::int64_t layer) {
    const int z0 = static_cast<int>(layer) * brick_, z1 = std::min(d.z, z0 + brick_);
    for (int z = z0; z < z1; ++z)
      for (int y = 0; y < d.y; ++y)
        for (int x = 0; x < d.x; ++x) {
          const Signature s = signature(grid.index(x, y, z));
          if (s.noisy) brick(x, y, z) = 1;
          const int nx[3] = {x + 1, x, x}, ny[3] = {y, y + 1, y}, nz[3] = {z, z, z + 1};
          for (int a = 0; a < 3; ++a) {
            if (nx[a] >= d.x || ny[a] >= d.y || nz[a] >= d.z) continue;
            if (!(signature(grid.index(nx[a], ny[a], nz[a])) == s)) {
              brick(x, y, z) = 1;
              if (nz[a] < z1) brick(nx[a], ny[a], nz[a]) = 1;  // in this layer
            }
          }
          if (z == z0 && z > 0 && !(signature(grid.index(x, y, z - 1)) == s)) brick(x, y, z) = 1;
        }
  });
  buildTable(flag);
}

QuietMap::QuietMap(const GridSpec& grid, const std::vector<std::uint8_t>& flagged_voxels) : grid_(grid) {
  const glm::ivec3 d = grid.dims;
  if (d.x <= 0 || d.y <= 0 || d.z <= 0 || flagged_voxels.size() != grid.count()) return;
  chooseBricks(160);
  std::vector<std::uint8_t> flag(static_cast<std::size_t>(bricks_.x) * bricks_.y * bricks_.z, 0);
  for (int z = 0; z < d.z; ++z)
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x)
        if (flagged_voxels[grid.index(x, y, z)]) brickFlag(flag, x, y, z) = 1;
  buildTable(flag);
}

void QuietMap::chooseBricks(int per_voxel_up_to) {
  const glm::ivec3 d = grid_.dims;
  const int longest = std::max(d.x, std::max(d.y, d.z));
  brick_ = longest <= per_voxel_up_to ? 1 : longest <= 512 ? 2 : 4;
  brick_shift_ = brick_ == 1 ? 0 : brick_ == 2 ? 1 : 2;
  inv_voxel_size_ = 1.0 / grid_.voxelSize();
  bricks_ = (d + (brick_ - 1)) / brick_;
}

std::vector<std::uint8_t>::reference QuietMap::brickFlag(std::vector<std::uint8_t>& flags, int x, int y, int z) const {
  return flags[static_cast<std::size_t>(x / brick_) +
               static_cast<std::size_t>(bricks_.x) *
                   (static_cast<std::size_t>(y / brick_) + static_cast<std::size_t>(bricks_.y) * static_cast<std::size_t>(z / brick_))];
}

void QuietMap::buildClearance() {
  // Each brick's chessboard distance to the nearest noisy brick is the least r whose cube of bricks
  // within r of it (clipped to the grid) holds a noisy one, which the summed-area table tells in
  // eight lookups. Along a row the distance changes by at most 1 from one brick to the next, so
  // after a binary search at the row's first brick each brick takes one to three cubes. Rows in
  // parallel (the raster passes of a distance transform are serial: 8 ms at 68³ against 1-2).
  const int nx = bricks_.x, ny = bricks_.y, nz = bricks_.z;
  clearance_.assign(static_cast<std::size_t>(nx) * ny * nz, 255);
  if (noisy_ == 0) return;
  auto noisyWithin = [&](int x, int y, int z, int r) {
    const int x0 = std::max(0, x - r), y0 = std::max(0, y - r), z0 = std::max(0, z - r);
    const int x1 = std::min(nx, x + r + 1), y1 = std::min(ny, y + r + 1), z1 = std::min(nz, z + r + 1);
    const std::uint32_t count = sat(x1, y1, z1) - sat(x0, y1, z1) - sat(x1, y0, z1) - sat(x1, y1, z0) +
                                sat(x0, y0, z1) + sat(x0, y1, z0) + sat(x1, y0, z0) - sat(x0, y0, z0);
    return count != 0;
  };
  parallelFor(
      0, static_cast<std::int64_t>(ny) * nz,
      [&](std::int64_t line) {
        const int y = static_cast<int>(line % ny), z = static_cast<int>(line / ny);
        std::uint8_t* row = clearance_.data() + static_cast<std::size_t>(line) * static_cast<std::size_t>(nx);
        // The first brick: the least r ≤ 254 with a noisy brick within it, else 255 (the cap).
        int c = 255;
        if (noisyWithin(0, y, z, 254)) {
          int lo = 0, hi = 254;
          while (lo < hi) {
            const int mid = (lo + hi) / 2;
            if (noisyWithin(0, y, z, mid))
              hi = mid;
            else
              lo = mid + 1;
          }
          c = lo;
        }
        row[0] = static_cast<std::uint8_t>(c);
        for (int x = 1; x < nx; ++x) {
          if (c > 0 && noisyWithin(x, y, z, c - 1))
            c = c - 1;
          else if (!noisyWithin(x, y, z, c))
            c = std::min(c + 1, 255);
          row[x] = static_cast<std::uint8_t>(c);
        }
      },
      8);
}

void QuietMap::buildTable(const std::vector<std::uint8_t>& flag) {
  const std::size_t sx = static_cast<std::size_t>(bricks_.x) + 1, sy = static_cast<std::size_t>(bricks_.y) + 1;
  sat_.assign(sx * sy * (static_cast<std::size_t>(bricks_.z) + 1), 0);
  for (int k = 1; k <= bricks_.z; ++k)
    for (int j = 1; j <= bricks_.y; ++j)
      for (int i = 1; i <= bricks_.x; ++i) {
        const std::uint32_t f =
            flag[static_cast<std::size_t>(i - 1) +
                 static_cast<std::size_t>(bricks_.x) * (static_cast<std::size_t>(j - 1) + static_cast<std::size_t>(bricks_.y) * (k - 1))];
        noisy_ += f;
        auto at = [&](int a, int b, int c) -> std::uint32_t& {
          return sat_[static_cast<std::size_t>(a) + sx * (static_cast<std::size_t>(b) + sy * static_cast<std::size_t>(c))];
        };
        at(i, j, k) = f + at(i - 1, j, k) + at(i, j - 1, k) + at(i, j, k - 1) - at(i - 1, j - 1, k) - at(i - 1, j, k - 1) -
                      at(i, j - 1, k - 1) + at(i - 1, j - 1, k - 1);
      }
  buildClearance();
}

bool QuietMap::quiet(const glm::dvec3& lo, const glm::dvec3& hi) const {
  if (sat_.empty()) return false;
  int b0[3], b1[3];
  const glm::dvec3 qlo = (lo - grid_.bounds_min) * inv_voxel_size_, qhi = (hi - grid_.bounds_min) * inv_voxel_size_;  // toVoxel
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(qlo[a]) || !std::isfinite(qhi[a])) return false;
    // The taps of a sample at voxel coordinate q (centres at i + ½): floor(c) and floor(c) + 1 with
    // c = q − ½ clamped to [0, dims − 1] (trilinearTaps).
    const double top = grid_.dims[a] - 1;
    const double c0 = std::clamp(std::min(qlo[a], qhi[a]) - 0.5, 0.0, top);
    const double c1 = std::clamp(std::max(qlo[a], qhi[a]) - 0.5, 0.0, top);
    const int v0 = static_cast<int>(std::floor(c0));
    const int v1 = std::min(grid_.dims[a] - 1, static_cast<int>(std::floor(c1)) + 1);
    b0[a] = v0 >> brick_shift_;  // v / brick_ (v ≥ 0)
    b1[a] = (v1 >> brick_shift_) + 1;  // exclusive
  }
  // The middle brick's clearance: no noisy brick within it of the middle brick (chessboard), and
  // the box reaches `reach` bricks from it; a noisy middle brick is in the box.
  int mid[3], reach = 0;
  for (int a = 0; a < 3; ++a) {
    mid[a] = (b0[a] + b1[a] - 1) / 2;
    reach = std::max(reach, std::max(mid[a] - b0[a], b1[a] - 1 - mid[a]));
  }
  const int clear = clearance_[static_cast<std::size_t>(mid[0]) +
                               static_cast<std::size_t>(bricks_.x) *
                                   (static_cast<std::size_t>(mid[1]) + static_cast<std::size_t>(bricks_.y) * static_cast<std::size_t>(mid[2]))];
  if (clear > reach) return true;
  if (clear == 0) return false;
  const std::uint32_t count = sat(b1[0], b1[1], b1[2]) - sat(b0[0], b1[1], b1[2]) - sat(b1[0], b0[1], b1[2]) -
                              sat(b1[0], b1[1], b0[2]) + sat(b0[0], b0[1], b1[2]) + sat(b0[0], b1[1], b0[2]) +
                              sat(b1[0], b0[1], b0[2]) - sat(b0[0], b0[1], b0[2]);
  return count == 0;
}

}  // namespace eik
