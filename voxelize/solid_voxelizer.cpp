#include "voxelize/solid_voxelizer.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/parallel.h"
#include "voxelize/winding_number.h"

namespace eik {
namespace {

using Int128 = __int128;

// ---------------------------------------------------------------------------------------------
// Fixed-point lattice for exact 2-D orientation tests: voxel coordinates × 2^20, |coord| ≤ 2^40
// voxels, so edge-function products stay below 2^123 and fit in __int128.
constexpr double kFixedScale = 1048576.0;  // 2^20
constexpr std::int64_t kFixedOne = std::int64_t(1) << 20;
constexpr double kMaxVoxelCoord = 1099511627776.0;  // 2^40

std::int64_t toFixed(double voxel) {
  return std::llround(std::clamp(voxel, -kMaxVoxelCoord, kMaxVoxelCoord) * kFixedScale);
}

// The sweep plane of each ray axis: rays run along w, columns are indexed by (u, v). The (u, v)
// pairs are chosen so a row of columns (fixed v) writes runs that are contiguous in memory; for
// the y axis (x, z, y) is left-handed, which `handedness` corrects in the crossing sign.
struct AxisFrame {
  int w, u, v;
  int handedness;
};
constexpr AxisFrame kFrames[3] = {{0, 1, 2, +1}, {1, 0, 2, -1}, {2, 0, 1, +1}};

// A triangle projected onto an axis frame. Edge i is the edge opposite corner i, running from
// corner i+1 to corner i+2; its edge function E_i(p) = (P_{i+2} − P_{i+1}) × (p − P_{i+1}) is the
// (doubled, signed) barycentric weight of corner i.
struct ProjectedTriangle {
  std::int64_t u[3], v[3];    // corners, fixed point
  std::int64_t du[3], dv[3];  // edge vectors P_{i+2} − P_{i+1}
  double w[3];                // depths along the ray axis, voxel units
  std::int64_t umin, umax, vmin, vmax;
  double inv_area2;           // 1 / Σ E_i
  std::int8_t tie[3];         // Simulation of Simplicity: sign of E_i(p + (ε, ε²)) when E_i(p) = 0
  std::int8_t orient;         // sign of the projected area
  std::int8_t crossing;       // winding change of a ray crossing it: +1 entering, −1 leaving
};

// Sign of E(p + (ε, ε²)) for E(p) = 0 and edge vector (du, dv): du·ε² − dv·ε.
std::int8_t tieSign(std::int64_t du, std::int64_t dv) {
  if (dv != 0) return dv > 0 ? -1 : 1;
  return du > 0 ? 1 : -1;
}

struct Crossing {
  double w;
  int change;
};

// Per-voxel vote between the axes' estimates c[a] (weight[a] valid sub-rays; 0 = none). Returns the
// coverage, or −1 when the voxel has to be decided by the winding number: fewer than two axes with
// valid rays, or valid axes that disagree by more than `tolerance` (with `majority`, a lone outlier
// among three is outvoted instead).
float voteAxes(const double c[3], const int weight[3], double tolerance, bool majority) {
  // Fast path for the vast majority of voxels: all three axes valid and in full agreement.
  if (weight[0] > 0 && weight[1] > 0 && weight[2] > 0 && c[0] == c[1] && c[1] == c[2])
    return static_cast<float>(c[0]);
  int axes[3];
  int n = 0;
  for (int a = 0; a < 3; ++a)
    if (weight[a] > 0) axes[n++] = a;
  if (n < 2) return -1.0f;
  auto mean = [&](int first, int count) {
    double sum = 0.0, total = 0.0;
    for (int i = first; i < first + count; ++i) {
      sum += weight[axes[i]] * c[axes[i]];
      total += weight[axes[i]];
    }
    return static_cast<float>(sum / total);
  };
  if (c[axes[1]] < c[axes[0]]) std::swap(axes[0], axes[1]);
  if (n == 3) {
    if (c[axes[2]] < c[axes[1]]) std::swap(axes[1], axes[2]);
    if (c[axes[1]] < c[axes[0]]) std::swap(axes[0], axes[1]);
  }
  const double lo = c[axes[0]], hi = c[axes[n - 1]];
  if (hi - lo <= tolerance) return mean(0, n);
  if (!majority || n < 3) return -1.0f;
  const double mid = c[axes[1]];
  if (mid - lo <= hi - mid) return mid - lo <= tolerance ? mean(0, 2) : -1.0f;
  return hi - mid <= tolerance ? mean(1, 2) : -1.0f;
}

class SolidVoxelizer {
 public:
  SolidVoxelizer(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                 const ProgressFn& progress, MeshVoxelizeStats& stats)
      : mesh_(mesh), grid_(grid), options_(options), progress_(progress), stats_(stats),
        S_(std::clamp(options.supersample, 1, 16)) {
    for (int s = 0; s < S_; ++s) offsets_[static_cast<std::size_t>(s)] = std::llround((s + 0.5) / S_ * kFixedScale);
    voxel_coords_.resize(mesh.positions.size());
    const glm::dvec3 h = grid.voxelSize();
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
      voxel_coords_[i] = (mesh.positions[i] - grid.bounds_min) / h;
    for (int a = 0; a < 3; ++a) total_rows_ += grid.dims[kFrames[a].v];
  }

  Region run() {
    const std::size_t n = grid_.count();
    Region region;
    region.coverage.assign(n, 0.0f);
    axis_estimate_[0].assign(n, 0);
    axis_estimate_[1].assign(n, 0);
    touched_.assign(n, 0);
    for (int a = 0; a < 3; ++a) {
      const AxisFrame& f = kFrames[a];
      valid_[a].assign(static_cast<std::size_t>(grid_.dims[f.u]) * static_cast<std::size_t>(grid_.dims[f.v]), 0);
    }
    undecided_rows_.assign(static_cast<std::size_t>(grid_.dims[kFrames[2].v]), {});
    for (int a = 0; a < 3; ++a) sweepAxis(a, region.coverage);
    axis_estimate_[0] = {};
    axis_estimate_[1] = {};
    resolveByWindingNumber(region.coverage);
    return region;
  }

 private:
  void project(int axis) {
    const AxisFrame& f = kFrames[axis];
    const int nu = grid_.dims[f.u], nv = grid_.dims[f.v];
    triangles_.clear();
    triangles_.reserve(mesh_.triangles.size());
    for (const glm::uvec3& tri : mesh_.triangles) {
      ProjectedTriangle t{};
      for (int c = 0; c < 3; ++c) {
        const glm::dvec3& p = voxel_coords_[tri[c]];
        t.u[c] = toFixed(p[f.u]);
        t.v[c] = toFixed(p[f.v]);
        t.w[c] = p[f.w];
      }
      Int128 area2 = 0;
      for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3, k = (i + 2) % 3;
        t.du[i] = t.u[k] - t.u[j];
        t.dv[i] = t.v[k] - t.v[j];
        t.tie[i] = (t.du[i] == 0 && t.dv[i] == 0) ? 0 : tieSign(t.du[i], t.dv[i]);
      }
      // Σ E_i(p) is the same for every p: the doubled signed area.
      area2 = Int128(t.u[1] - t.u[0]) * (t.v[2] - t.v[0]) - Int128(t.v[1] - t.v[0]) * (t.u[2] - t.u[0]);
      if (area2 == 0) continue;  // edge-on: never crossed (its neighbours are, exactly once)
      t.orient = area2 > 0 ? 1 : -1;
      t.crossing = static_cast<std::int8_t>(-t.orient * f.handedness);
      t.inv_area2 = 1.0 / static_cast<double>(area2);
      t.umin = std::min({t.u[0], t.u[1], t.u[2]});
      t.umax = std::max({t.u[0], t.u[1], t.u[2]});
      t.vmin = std::min({t.v[0], t.v[1], t.v[2]});
      t.vmax = std::max({t.v[0], t.v[1], t.v[2]});
      if (t.umax < 0 || t.vmax < 0 || t.umin >= nu * kFixedOne || t.vmin >= nv * kFixedOne) continue;
      triangles_.push_back(t);
    }
    // Bin by column (projected bounding box), CSR.
    const std::size_t columns = static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv);
    column_start_.assign(columns + 1, 0);
    auto range = [&](const ProjectedTriangle& t, int& u0, int& u1, int& v0, int& v1) {
      u0 = static_cast<int>(std::clamp<std::int64_t>(t.umin >> 20, 0, nu - 1));
      u1 = static_cast<int>(std::clamp<std::int64_t>(t.umax >> 20, 0, nu - 1));
      v0 = static_cast<int>(std::clamp<std::int64_t>(t.vmin >> 20, 0, nv - 1));
      v1 = static_cast<int>(std::clamp<std::int64_t>(t.vmax >> 20, 0, nv - 1));
    };
    for (const ProjectedTriangle& t : triangles_) {
      int u0, u1, v0, v1;
      range(t, u0, u1, v0, v1);
      for (int v = v0; v <= v1; ++v)
        for (int u = u0; u <= u1; ++u) ++column_start_[static_cast<std::size_t>(u) + static_cast<std::size_t>(nu) * v + 1];
    }
    for (std::size_t c = 0; c < columns; ++c) column_start_[c + 1] += column_start_[c];
    column_triangles_.resize(column_start_[columns]);
    std::vector<std::size_t> fill(column_start_.begin(), column_start_.end() - 1);
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
      int u0, u1, v0, v1;
      range(triangles_[i], u0, u1, v0, v1);
      for (int v = v0; v <= v1; ++v)
        for (int u = u0; u <= u1; ++u)
          column_triangles_[fill[static_cast<std::size_t>(u) + static_cast<std::size_t>(nu) * v]++] =
              static_cast<std::uint32_t>(i);
    }
  }

  std::size_t voxelIndex(const AxisFrame& f, int iu, int iv, int iw) const {
    glm::ivec3 c;
    c[f.u] = iu;
    c[f.v] = iv;
    c[f.w] = iw;
    return grid_.index(c.x, c.y, c.z);
  }

  void sweepAxis(int axis, std::vector<float>& coverage) {
    project(axis);
    const AxisFrame& f = kFrames[axis];
    const int nv = grid_.dims[f.v];
    std::atomic<std::uint64_t> rays{0}, holes{0};
    parallelFor(0, nv, [&](std::int64_t iv) {
      std::uint64_t row_rays = 0, row_holes = 0;
      sweepRow(axis, static_cast<int>(iv), coverage, row_rays, row_holes);
      rays += row_rays;
      holes += row_holes;
      const auto done = ++rows_done_;
      if (progress_) progress_(0.9 * static_cast<double>(done) / static_cast<double>(std::max<std::int64_t>(total_rows_, 1)));
    });
    stats_.rays += rays;
    stats_.rays_through_holes += holes;
  }

  void sweepRow(int axis, int iv, std::vector<float>& coverage, std::uint64_t& ray_count, std::uint64_t& hole_count) {
    const AxisFrame& f = kFrames[axis];
    const int nu = grid_.dims[f.u], nw = grid_.dims[f.w];
    const int S = S_, rays_per_column = S * S;
    std::vector<std::vector<Crossing>> rays(static_cast<std::size_t>(rays_per_column));
    std::vector<double> direct(static_cast<std::size_t>(nw));
    std::vector<std::int32_t> diff(static_cast<std::size_t>(nw) + 1);
    std::vector<float> estimate(static_cast<std::size_t>(nu) * static_cast<std::size_t>(nw), 0.0f);
    std::vector<std::uint16_t>& valid = valid_[axis];

    auto addInterval = [&](double a, double b) {
      a = std::max(a, 0.0);
      b = std::min(b, static_cast<double>(nw));
      if (!(b > a)) return;
      const int ia = std::min(static_cast<int>(a), nw - 1), ib = std::min(static_cast<int>(b), nw - 1);
      if (ia == ib) {
        direct[static_cast<std::size_t>(ia)] += b - a;
        return;
      }
      direct[static_cast<std::size_t>(ia)] += (ia + 1) - a;
      direct[static_cast<std::size_t>(ib)] += b - ib;
      diff[static_cast<std::size_t>(ia) + 1] += 1;
      diff[static_cast<std::size_t>(ib)] -= 1;
    };

    for (int iu = 0; iu < nu; ++iu) {
      const std::size_t column = static_cast<std::size_t>(iu) + static_cast<std::size_t>(nu) * iv;
      ray_count += static_cast<std::uint64_t>(rays_per_column);
      const std::size_t begin = column_start_[column], end = column_start_[column + 1];
      if (begin == end) {  // nothing crosses: every sub-ray is valid and outside
        valid[column] = static_cast<std::uint16_t>(rays_per_column);
        continue;
      }
      for (auto& r : rays) r.clear();
      const std::int64_t base_u = iu * kFixedOne, base_v = std::int64_t(iv) * kFixedOne;
      for (std::size_t k = begin; k < end; ++k) {
        const ProjectedTriangle& t = triangles_[column_triangles_[k]];
        for (int sv = 0; sv < S; ++sv) {
          const std::int64_t pv = base_v + offsets_[static_cast<std::size_t>(sv)];
          if (pv < t.vmin || pv > t.vmax) continue;
          for (int su = 0; su < S; ++su) {
            const std::int64_t pu = base_u + offsets_[static_cast<std::size_t>(su)];
            if (pu < t.umin || pu > t.umax) continue;
            Int128 e[3];
            bool inside = true;
            for (int i = 0; i < 3 && inside; ++i) {
              const int j = (i + 1) % 3;
              e[i] = Int128(t.du[i]) * (pv - t.v[j]) - Int128(t.dv[i]) * (pu - t.u[j]);
              const int sign = e[i] > 0 ? 1 : (e[i] < 0 ? -1 : t.tie[i]);
              inside = sign == t.orient;
            }
            if (!inside) continue;
            const double w = (static_cast<double>(e[0]) * t.w[0] + static_cast<double>(e[1]) * t.w[1] +
                              static_cast<double>(e[2]) * t.w[2]) *
                             t.inv_area2;
            rays[static_cast<std::size_t>(su + S * sv)].push_back({w, t.crossing});
            if (w >= 0.0 && w < nw) touched_[voxelIndex(f, iu, iv, static_cast<int>(w))] = 1;
          }
        }
      }
      std::fill(direct.begin(), direct.end(), 0.0);
      std::fill(diff.begin(), diff.end(), 0);
      int valid_rays = 0;
      for (auto& r : rays) {
        int total = 0;
        for (const Crossing& c : r) total += c.change;
        if (total != 0) {  // entered or left through a hole: abstain
          ++hole_count;
          continue;
        }
        ++valid_rays;
        if (r.empty()) continue;
        std::sort(r.begin(), r.end(), [](const Crossing& a, const Crossing& b) { return a.w < b.w; });
        int winding = 0;
        double start = 0.0;
        for (const Crossing& c : r) {
          const int before = winding;
          winding += c.change;
          if (before == 0 && winding != 0) start = c.w;
          else if (before != 0 && winding == 0) addInterval(start, c.w);
        }
      }
      valid[column] = static_cast<std::uint16_t>(valid_rays);
      if (valid_rays == 0) continue;
      std::int32_t run = 0;
      float* out = estimate.data() + static_cast<std::size_t>(iu) * nw;
      for (int iw = 0; iw < nw; ++iw) {
        run += diff[static_cast<std::size_t>(iw)];
        out[iw] = static_cast<float>(std::clamp((direct[static_cast<std::size_t>(iw)] + run) / valid_rays, 0.0, 1.0));
      }
    }

    if (axis < 2) {
      std::vector<std::uint16_t>& dst = axis_estimate_[axis];
      for (int iu = 0; iu < nu; ++iu)
        for (int iw = 0; iw < nw; ++iw) {
          const float c = estimate[static_cast<std::size_t>(iu) * nw + iw];
          if (c > 0.0f) dst[voxelIndex(f, iu, iv, iw)] = static_cast<std::uint16_t>(std::lround(c * 65535.0f));
        }
      return;
    }
    // Last axis (z, columns over x, row = y): vote per voxel with the stored x and y estimates.
    const int nx = grid_.dims.x, ny = grid_.dims.y;
    std::vector<std::uint32_t>& undecided = undecided_rows_[static_cast<std::size_t>(iv)];
    const int j = iv;
    for (int k = 0; k < nw; ++k)
      for (int i = 0; i < nu; ++i) {
        const std::size_t index = grid_.index(i, j, k);
        double c[3];
        int weight[3];
        weight[0] = valid_[0][static_cast<std::size_t>(j) + static_cast<std::size_t>(ny) * k];
        weight[1] = valid_[1][static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * k];
        weight[2] = valid[static_cast<std::size_t>(i) + static_cast<std::size_t>(nu) * iv];
        c[0] = axis_estimate_[0][index] / 65535.0;
        c[1] = axis_estimate_[1][index] / 65535.0;
        c[2] = estimate[static_cast<std::size_t>(i) * nw + k];
        const float voted = voteAxes(c, weight, options_.axis_agreement, options_.majority_vote);
        if (voted >= 0.0f) coverage[index] = voted;
        else undecided.push_back(static_cast<std::uint32_t>(k) * static_cast<std::uint32_t>(nu) +
                                 static_cast<std::uint32_t>(i));
      }
  }

  void resolveByWindingNumber(std::vector<float>& coverage) {
    std::vector<std::size_t> voxels;
    const int ny = grid_.dims.y, nx = grid_.dims.x;
    for (int j = 0; j < ny; ++j)
      for (std::uint32_t packed : undecided_rows_[static_cast<std::size_t>(j)]) {
        const int k = static_cast<int>(packed / static_cast<std::uint32_t>(nx));
        const int i = static_cast<int>(packed % static_cast<std::uint32_t>(nx));
        voxels.push_back(grid_.index(i, j, k));
      }
    undecided_rows_ = {};
    stats_.winding_voxels = voxels.size();
    if (voxels.empty()) {
      if (progress_) progress_(1.0);
      return;
    }
    const FastWindingNumber winding(mesh_, options_.winding_beta);
    const double threshold = options_.winding_threshold;
    const glm::dvec3 h = grid_.voxelSize();
    const int S = S_;
    std::atomic<std::uint64_t> evaluations{0};
    std::atomic<std::size_t> done{0};
    const std::int64_t chunk = 64;
    const auto chunks = static_cast<std::int64_t>((voxels.size() + chunk - 1) / chunk);
    parallelFor(0, chunks, [&](std::int64_t c) {
      std::uint64_t evals = 0;
      const std::size_t first = static_cast<std::size_t>(c * chunk);
      const std::size_t last = std::min(voxels.size(), first + static_cast<std::size_t>(chunk));
      for (std::size_t n = first; n < last; ++n) {
        const std::size_t index = voxels[n];
        const int i = static_cast<int>(index % static_cast<std::size_t>(nx));
        const int j = static_cast<int>((index / static_cast<std::size_t>(nx)) % static_cast<std::size_t>(ny));
        const int k = static_cast<int>(index / (static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny)));
        auto inside = [&](int a, int b, int d) {
          const glm::dvec3 p = grid_.bounds_min + (glm::dvec3(i, j, k) + (glm::dvec3(a, b, d) + 0.5) / double(S)) * h;
          ++evals;
          return std::abs(winding(p)) > threshold;
        };
        if (!touched_[index]) {
          // No surface seen inside: w is smooth (harmonic) across the voxel. Clearly on one side
          // at the centre → the whole voxel; otherwise the corner sub-samples, then all of them.
          const glm::dvec3 centre = grid_.center(i, j, k);
          ++evals;
          const double w = std::abs(winding(centre)) - threshold;
          if (std::abs(w) > 0.25) {
            coverage[index] = w > 0.0 ? 1.0f : 0.0f;
            continue;
          }
          int count = 0;
          for (int corner = 0; corner < 8; ++corner)
            count += inside((corner & 1) ? S - 1 : 0, (corner & 2) ? S - 1 : 0, (corner & 4) ? S - 1 : 0) ? 1 : 0;
          if (count == 0 || count == 8) {
            coverage[index] = count == 8 ? 1.0f : 0.0f;
            continue;
          }
        }
        int count = 0;
        for (int d = 0; d < S; ++d)
          for (int b = 0; b < S; ++b)
            for (int a = 0; a < S; ++a) count += inside(a, b, d) ? 1 : 0;
        coverage[index] = static_cast<float>(count) / static_cast<float>(S * S * S);
      }
      evaluations += evals;
      const std::size_t finished = done += (last - first);
      if (progress_) progress_(0.9 + 0.1 * static_cast<double>(finished) / static_cast<double>(voxels.size()));
    });
    stats_.winding_evaluations = evaluations;
  }

  const TriangleMesh& mesh_;
  const GridSpec& grid_;
  const MeshVoxelizeOptions& options_;
  const ProgressFn& progress_;
  MeshVoxelizeStats& stats_;
  const int S_;
  std::array<std::int64_t, 16> offsets_{};
  std::vector<glm::dvec3> voxel_coords_;
  std::vector<ProjectedTriangle> triangles_;
  std::vector<std::size_t> column_start_;
  std::vector<std::uint32_t> column_triangles_;
  std::vector<std::uint16_t> axis_estimate_[2];  // x and y estimates, quantised to 1/65535
  std::vector<std::uint16_t> valid_[3];          // valid sub-rays per column, per axis
  std::vector<std::uint8_t> touched_;            // some sub-ray crossed the surface inside the voxel
  std::vector<std::vector<std::uint32_t>> undecided_rows_;  // per y row: voxels for the winding number
  std::atomic<std::int64_t> rows_done_{0};
  std::int64_t total_rows_ = 0;
};

}  // namespace

Region voxelizeSolid(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                     const ProgressFn& progress, MeshVoxelizeStats& stats) {
  return SolidVoxelizer(mesh, grid, options, progress, stats).run();
}

}  // namespace eik
