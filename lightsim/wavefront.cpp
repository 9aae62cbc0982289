#include "lightsim/wavefront.h"

#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "core/scene.h"

namespace eik {

namespace {

constexpr const char* kOptionsSource = "lightsim options";

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// One axis of a GL_LINEAR + GL_CLAMP_TO_EDGE lookup: i₀, i₁ and the weight f of i₁.
struct AxisTap {
  int i0, i1;
  double f;
};

// From the continuous voxel coordinate c: clamp-to-edge, i₀ = floor(c), i₁ = min(i₀ + 1, n − 1).
inline AxisTap clampedTap(double c, int n) {
  const double top = static_cast<double>(n - 1);
  c = c > 0.0 ? (c < top ? c : top) : 0.0;  // NaN → 0
  int i0 = static_cast<int>(std::floor(c));
  if (i0 > n - 1) i0 = n - 1;
  const int i1 = i0 + 1 < n ? i0 + 1 : n - 1;
  return {i0, i1, c - static_cast<double>(i0)};
}

inline AxisTap axisTap(double world, double lo, double scale, int n) {
  // uvw = (x − min)/extent, c = uvw·dims − 0.5 (ALGORITHM.md "Units and inputs"); scale = dims/extent,
  // a multiplication where a division cost 4 % of a bake.
  double c = (world - lo) * scale - 0.5;
  return clampedTap(c, n);
}

struct Taps3 {
  AxisTap x, y, z;
};

// dims/extent per axis: voxel coordinates per world unit.
inline glm::dvec3 tapScale(const GridSpec& g) { return glm::dvec3(g.dims) / g.extent(); }

inline Taps3 taps3(const GridSpec& g, const glm::dvec3& p, const glm::dvec3& scale) {
  return {axisTap(p.x, g.bounds_min.x, scale.x, g.dims.x), axisTap(p.y, g.bounds_min.y, scale.y, g.dims.y),
          axisTap(p.z, g.bounds_min.z, scale.z, g.dims.z)};
}

// Σ weight·at(index) over the eight taps, for any Out with Out*double and Out+Out (double, glm
// vectors); at(i) is voxel i's value.
template <typename Out, typename At>
inline Out blendTaps(const GridSpec& g, const Taps3& t, At&& at) {
  const std::size_t nx = static_cast<std::size_t>(g.dims.x);
  const std::size_t nxy = nx * static_cast<std::size_t>(g.dims.y);
  const std::size_t y0 = static_cast<std::size_t>(t.y.i0) * nx, y1 = static_cast<std::size_t>(t.y.i1) * nx;
  const std::size_t z0 = static_cast<std::size_t>(t.z.i0) * nxy, z1 = static_cast<std::size_t>(t.z.i1) * nxy;
  const std::size_t x0 = static_cast<std::size_t>(t.x.i0), x1 = static_cast<std::size_t>(t.x.i1);
  const double fx = t.x.f, fy = t.y.f, fz = t.z.f;
  const double gx = 1.0 - fx, gy = 1.0 - fy, gz = 1.0 - fz;
  const Out c00 = at(x0 + y0 + z0) * gx + at(x1 + y0 + z0) * fx;
  const Out c10 = at(x0 + y1 + z0) * gx + at(x1 + y1 + z0) * fx;
  const Out c01 = at(x0 + y0 + z1) * gx + at(x1 + y0 + z1) * fx;
  const Out c11 = at(x0 + y1 + z1) * gx + at(x1 + y1 + z1) * fx;
  return (c00 * gy + c10 * fy) * gz + (c01 * gy + c11 * fy) * fz;
}

// The trilinear interpolant of a field of one T a voxel (glm vectors).
template <typename Out, typename T>
inline Out interpolate(const std::vector<T>& data, const GridSpec& g, const Taps3& t) {
  return blendTaps<Out>(g, t, [&](std::size_t i) { return Out(data[i]); });
}

// interpolate for S < 4 floats a voxel (the used slots' distances), the rest of the vec4 `rest`:
// the same weights and the same order of sums per component, so the same values as the vec4's.
template <int S>
inline glm::dvec4 interpolateUsed(const std::vector<float>& data, float rest, const GridSpec& g, const Taps3& t) {
  glm::dvec4 out(static_cast<double>(rest));
  for (int k = 0; k < S; ++k)
    out[k] = blendTaps<double>(g, t, [&](std::size_t i) { return static_cast<double>(data[i * S + static_cast<std::size_t>(k)]); });
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Sampling

double voxelEdge(const GridSpec& grid) {
  const glm::dvec3 h = grid.voxelSize();
  return std::min(h.x, std::min(h.y, h.z));
}

TrilinearTaps trilinearTaps(const GridSpec& grid, const glm::dvec3& world) {
  const Taps3 t = taps3(grid, world, tapScale(grid));
  TrilinearTaps out;
  for (int k = 0; k < 8; ++k) {
    const int kx = k & 1, ky = (k >> 1) & 1, kz = (k >> 2) & 1;
    out.index[k] = grid.index(kx ? t.x.i1 : t.x.i0, ky ? t.y.i1 : t.y.i0, kz ? t.z.i1 : t.z.i0);
    out.weight[k] = (kx ? t.x.f : 1.0 - t.x.f) * (ky ? t.y.f : 1.0 - t.y.f) * (kz ? t.z.f : 1.0 - t.z.f);
  }
  return out;
}

glm::dvec4 sampleTrilinear(const Field& field, const GridSpec& grid, const glm::dvec3& world) {
  const TrilinearTaps taps = trilinearTaps(grid, world);
  glm::dvec4 out(0.0);
  const int comps = std::min(field.components, 4);
  for (int k = 0; k < 8; ++k) {
    const float* v = field.voxel(taps.index[k]);
    for (int c = 0; c < comps; ++c) out[c] += taps.weight[k] * static_cast<double>(v[c]);
  }
  return out;
}

VolumeSampler::VolumeSampler(const Volume& volume) : VolumeSampler(volume, nullptr) {}

VolumeSampler::VolumeSampler(const Volume& volume, std::vector<float>* interfaces_data)
    : grid_(volume.grid), h_(voxelEdge(volume.grid)), tap_scale_(tapScale(volume.grid)) {
  const std::size_t n = grid_.count();
  // The copies below, in chunks of voxels in parallel.
  constexpr std::int64_t kChunk = 1 << 16;
  const std::int64_t chunks = static_cast<std::int64_t>((n + kChunk - 1) / kChunk);
  auto forChunks = [&](auto&& body) {
    parallelFor(0, chunks, [&](std::int64_t c) {
      const std::size_t begin = static_cast<std::size_t>(c * kChunk);
      body(begin, std::min(n, begin + static_cast<std::size_t>(kChunk)));
    });
  };
  table_ = interfaceTable(volume);
  // n and ∇n are read from the fields only where a sample returns them: everywhere without sharp
  // interfaces, in graded materials with them (homogeneous materials and air have their own n).
  // Elsewhere they are not copied (at 132³ that is 37 MB not written), and need not have been
  // read (VolumeReadOptions::leave_unread) nor written (voxelize leaves ∇n out).
  const bool reads_n = !constantSlots(table_);
  const Field* ior = reads_n ? &volume.require("ior", 1) : volume.find("ior");
  const Field* grad = reads_n ? &volume.require("ior_grad", 3) : volume.find("ior_grad");
  if (reads_n) {
    ior_grad_.resize(n);
    forChunks([&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const float* g = grad->voxel(i);
        ior_grad_[i] = glm::vec4(ior->data[i], g[0], g[1], g[2]);
      }
    });
  }
  if (const Field* sa = volume.find("sigma_a")) {
    if (sa->components != 3) throw InputError("volume", "sigma_a", "expected 3 components");
    bool any = false;
    for (float v : sa->data) any = any || v != 0.0f;
    if (any) {
      sigma_a_.resize(n);
      for (std::size_t i = 0; i < n; ++i) sigma_a_[i] = glm::vec3(sa->voxel(i)[0], sa->voxel(i)[1], sa->voxel(i)[2]);
    }
  }
  findMaterialAbsorption(volume);  // reads the volume's distances: before they may be taken below
  const Field* d = nullptr;
  const float* dist_data = nullptr;  // d's distances, `dist_stride` floats a voxel
  std::size_t dist_stride = 0;
  std::vector<std::uint8_t> slot_signs;  // while the tables are built
  if (!table_.empty()) {
    d = volume.find("interfaces");  // one distance per slot, or four (interfaceTable checked which)
    const int used = slotCount();
    const std::optional<float> unused = unusedSlotDistance(*d, used, table_.band);
    unused_distance_ = unused.value_or(0.0f);
    // Where the distances are read below: the field's, or the sampler's own once it took them.
    dist_data = d->data.data();
    dist_stride = static_cast<std::size_t>(d->components);
    if (unused && interfaces_data == &d->data && d->components == used) {
      used_distances_ = std::move(*interfaces_data);  // the same layout: taken, not copied
      dist_data = used_distances_.data();
      dist_stride = static_cast<std::size_t>(used);
    } else if (unused) {
      used_distances_.resize(n * static_cast<std::size_t>(used));
      forChunks([&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          for (int k = 0; k < used; ++k)
            used_distances_[i * static_cast<std::size_t>(used) + static_cast<std::size_t>(k)] = d->voxel(i)[k];
      });
    } else {
      distances_.resize(n);
      forChunks([&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          const float* v = d->voxel(i);
          distances_[i] = glm::vec4(v[0], v[1], v[2], v[3]);
        }
      });
    }
    // Each voxel's signs once (bit k: slot k's distance < 0; bit 4 + k: it is 0), for the cells'
    // materials here and the quiet bricks below, which compare them between neighbours.
    slot_signs = std::vector<std::uint8_t>(n);
    forChunks([&](std::size_t begin, std::size_t end) {
      const float* data = dist_data;
      const std::size_t stride = dist_stride;
      for (std::size_t i = begin; i < end; ++i) {
        std::uint8_t bits = 0;
        for (int k = 0; k < used; ++k) {
          const float v = data[i * stride + static_cast<std::size_t>(k)];
          bits |= static_cast<std::uint8_t>((v < 0.0f ? 1 : 0) << k | (v == 0.0f ? 1 : 0) << (4 + k));
        }
        slot_signs[i] = bits;
      }
    });
    // Each cell's material where its eight taps agree (materialAt): a slot's distance < 0 at every
    // tap or at none.
    const glm::ivec3 dims = grid_.dims;
    const int used_bits = (1 << used) - 1;
    cell_material_.assign(n, kMixedCell);
    parallelFor(0, dims.z, [&](std::int64_t z64) {
      const int z = static_cast<int>(z64), z1 = std::min(z + 1, dims.z - 1);
      for (int y = 0; y < dims.y; ++y) {
        const int y1 = std::min(y + 1, dims.y - 1);
        const std::uint8_t* rows[4] = {&slot_signs[grid_.index(0, y, z)], &slot_signs[grid_.index(0, y1, z)],
                                       &slot_signs[grid_.index(0, y, z1)], &slot_signs[grid_.index(0, y1, z1)]};
        std::int8_t* out = &cell_material_[grid_.index(0, y, z)];
        for (int x = 0; x < dims.x; ++x) {
          const int x1 = std::min(x + 1, dims.x - 1);
          int inside = 0, outside = 0;  // bit k: slot k's distance < 0 (≥ 0) at some tap
          for (const std::uint8_t* row : rows) {
            inside |= row[x] | row[x1];
            outside |= ~row[x] | ~row[x1];
          }
          inside &= used_bits;
          outside &= used_bits;
          if ((inside & outside) != 0) continue;  // a slot changes sign in the cell
          std::int8_t material = -1;
          for (int k = 0; k < used && material < 0; ++k)
            if (inside & (1 << k)) material = static_cast<std::int8_t>(k);
          out[x] = material;
        }
      }
    });
  }
  // The quiet bricks, from the volume's own fields (what the copies above would give).
  QuietMap::FieldViews views;
  views.ior = ior ? ior->data.data() : nullptr;  // read only in graded materials (QuietMap)
  views.grad = grad ? grad->data.data() : nullptr;
  if (d) {
    views.distances = dist_data;
    views.distances_stride = dist_stride;
    views.slot_signs = slot_signs.data();
  }
  if (!sigma_a_.empty()) views.sigma_a = &sigma_a_[0].x;
  quiet_ = QuietMap(grid_, views, table_);
  // The smallest n: every material's and air's with sharp interfaces, the field's where it is read.
  min_ior_ = std::numeric_limits<double>::infinity();
  if (sharp()) {
    min_ior_ = 1.0;  // air
    for (const InterfaceSlot& slot : table_.slots)
      if (!slot.graded) min_ior_ = std::min(min_ior_, slot.ior);
  }
  if (reads_n)
    for (const float v : ior->data) min_ior_ = std::min(min_ior_, static_cast<double>(v));  // graded slots and smoothed n
}

void VolumeSampler::findMaterialAbsorption(const Volume& volume) {
  const Field* sigma = volume.find("sigma_a");
  if (!sharp() || sigma_a_.empty() || !sigma) return;
  MaterialValues deep = deepMaterialValues(volume, table_, *sigma, kDeepVoxels * h_);
  if (!deep.one_value || (deep.seen[0] && deep.value[0] != glm::dvec3(0.0))) {
    // σa in the air: per material still where it is one box of smoke (airMediumBox).
    std::optional<AirMedium> air = airMediumBox(volume, table_, kDeepVoxels * h_);
    if (!air) return;
    deep = deepMaterialValues(volume, table_, *sigma, kDeepVoxels * h_, false);
    if (!deep.one_value) return;
    air_ = air;
  }
  // Each transparent material's σa: the one the voxelizer recorded in the slot table, which its deep
  // voxels must agree with; else that of its deep voxels. A material with neither (a wall thinner
  // than two voxels in a volume from before the table held σa) leaves σa to the field.
  for (int k = 0; k < slotCount(); ++k) {
    const std::size_t s = static_cast<std::size_t>(k), m = s + 1;
    const std::optional<glm::dvec3>& recorded = table_.slots[s].sigma_a;
    if (opaque(k)) {
      slot_sigma_a_[s] = glm::dvec3(0.0);
    } else if (recorded) {
      if (deep.seen[m] && glm::vec3(deep.value[m]) != glm::vec3(*recorded)) {
        air_.reset();
        return;
      }
      slot_sigma_a_[s] = *recorded;
    } else if (deep.seen[m]) {
      slot_sigma_a_[s] = deep.value[m];
    } else {
      air_.reset();
      return;
    }
  }
  absorption_per_material_ = true;
}

double VolumeSampler::ior(const glm::dvec3& world) const { return iorAndGradient(world).x; }

glm::dvec4 VolumeSampler::iorAndGradient(const glm::dvec3& world) const {
  if (sharp()) return materialOptics(materialAt(world), world);
  return interpolate<glm::dvec4>(ior_grad_, grid_, taps3(grid_, world, tap_scale_));
}

int VolumeSampler::materialAt(const glm::dvec3& world) const {
  if (!sharp()) return -1;
  const Taps3 t = taps3(grid_, world, tap_scale_);
  const std::int8_t cell = cell_material_[grid_.index(t.x.i0, t.y.i0, t.z.i0)];
  return cell != kMixedCell ? cell : materialSlot(distances(world), slotCount());
}

glm::dvec4 VolumeSampler::distances(const glm::dvec3& world) const {
  if (!sharp()) return glm::dvec4(0.0);
  const Taps3 taps = taps3(grid_, world, tap_scale_);
  switch (used_distances_.empty() ? 4 : slotCount()) {
    case 1: return interpolateUsed<1>(used_distances_, unused_distance_, grid_, taps);
    case 2: return interpolateUsed<2>(used_distances_, unused_distance_, grid_, taps);
    case 3: return interpolateUsed<3>(used_distances_, unused_distance_, grid_, taps);
    default: return interpolate<glm::dvec4>(distances_, grid_, taps);
  }
}

glm::dvec4 VolumeSampler::materialOptics(int slot, const glm::dvec3& world) const {
  if (!sharp()) return iorAndGradient(world);
  if (slot < 0) return {1.0, 0.0, 0.0, 0.0};
  const InterfaceSlot& s = table_.slots[static_cast<std::size_t>(slot)];
  if (!s.graded) return {s.ior, 0.0, 0.0, 0.0};
  return interpolate<glm::dvec4>(ior_grad_, grid_, taps3(grid_, world, tap_scale_));
}



QuietMap VolumeSampler::absorberMap() const {
  std::vector<std::uint8_t> flags(grid_.count(), 0);
  for (std::size_t i = 0; i < sigma_a_.size() && i < flags.size(); ++i)
    flags[i] = sigma_a_[i].x != 0.0f || sigma_a_[i].y != 0.0f || sigma_a_[i].z != 0.0f;
  return QuietMap(grid_, flags);
}

glm::dvec3 VolumeSampler::interfaceNormal(int slot, const glm::dvec3& world) const {
  if (!sharp()) return glm::dvec3(0.0);
  // Slot `slot`'s distance from a lookup's taps, as distances() interpolates it.
  const int used = used_distances_.empty() ? 4 : slotCount();
  auto distance = [&](const Taps3& t) {
    if (used == 4) return blendTaps<double>(grid_, t, [&](std::size_t i) { return static_cast<double>(distances_[i][slot]); });
    return blendTaps<double>(grid_, t, [&](std::size_t i) {
      return static_cast<double>(used_distances_[i * static_cast<std::size_t>(used) + static_cast<std::size_t>(slot)]);
    });
  };
  // Central differences half a voxel either side on each axis: the offset axis' taps are the only
  // ones that change, the others are the point's own.
  const glm::dvec3 h = 0.5 * grid_.voxelSize();
  const Taps3 mid = taps3(grid_, world, tap_scale_);
  glm::dvec3 g;
  for (int a = 0; a < 3; ++a) {
    Taps3 plus = mid, minus = mid;
    AxisTap& p = a == 0 ? plus.x : a == 1 ? plus.y : plus.z;
    AxisTap& m = a == 0 ? minus.x : a == 1 ? minus.y : minus.z;
    p = axisTap(world[a] + h[a], grid_.bounds_min[a], tap_scale_[a], grid_.dims[a]);
    m = axisTap(world[a] - h[a], grid_.bounds_min[a], tap_scale_[a], grid_.dims[a]);
    g[a] = (distance(plus) - distance(minus)) / (2.0 * h[a]);
  }
  const double len = glm::length(g);
  return len > 0.0 ? g / len : glm::dvec3(0.0);
}

glm::dvec3 VolumeSampler::sigmaA(const glm::dvec3& world) const {
  if (sigma_a_.empty()) return glm::dvec3(0.0);
  return interpolate<glm::dvec3>(sigma_a_, grid_, taps3(grid_, world, tap_scale_));
}

// ---------------------------------------------------------------------------------------------
// Geometry

bool insideBox(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
  return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
}

bool rayHitsBox(const glm::dvec3& origin, const glm::dvec3& dir, const glm::dvec3& lo, const glm::dvec3& hi) {
  double t_near = 0.0, t_far = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0.0) {
      if (origin[a] < lo[a] || origin[a] > hi[a]) return false;
      continue;
    }
    double t1 = (lo[a] - origin[a]) / dir[a];
    double t2 = (hi[a] - origin[a]) / dir[a];
    if (t1 > t2) std::swap(t1, t2);
    t_near = std::max(t_near, t1);
    t_far = std::min(t_far, t2);
    if (t_near > t_far) return false;
  }
  return true;
}

SplitAxes splitAxes(const Patch& p, double threshold, SplitRule rule) {
  if (rule == SplitRule::Quad) {
    const bool split = p.longestEdge() > threshold;
    return {split, split};
  }
  const double u_edge = std::max(glm::length(p.x[1] - p.x[0]), glm::length(p.x[2] - p.x[3]));
  const double v_edge = std::max(glm::length(p.x[2] - p.x[1]), glm::length(p.x[3] - p.x[0]));
  return {u_edge > threshold, v_edge > threshold};
}

int splitPatch(const Patch& parent, const VolumeSampler& sampler, SplitAxes axes, std::array<Patch, 4>& children,
               std::array<std::array<glm::dvec4, 4>, 4>* corner_samples) {
  const int nu = axes.u ? 2 : 1, nv = axes.v ? 2 : 1;
  const int count = nu * nv;
  // The (nu + 1) × (nv + 1) corner grid at (u, v) = (iu/nu, iv/nv) (ALGORITHM.md step 6), computed
  // once so that children sharing a corner get identical bits.
  glm::dvec3 gx[3][3], gw[3][3];
  glm::dvec4 gs[3][3];
  int gm[3][3];
  // With sharp interfaces a patch splits only while all its corners are in one material (the
  // analysis keeps a patch that straddles an interface whole): the new corners are in it too.
  const bool one_medium = parent.medium[0] == parent.medium[1] && parent.medium[1] == parent.medium[2] &&
                          parent.medium[2] == parent.medium[3];
  for (int iv = 0; iv <= nv; ++iv) {
    for (int iu = 0; iu <= nu; ++iu) {
      const double u = static_cast<double>(iu) / nu, v = static_cast<double>(iv) / nv;
      gx[iu][iv] = bilinear(parent.x, u, v);
      gm[iu][iv] = one_medium ? parent.medium[0] : sampler.materialAt(gx[iu][iv]);
      gs[iu][iv] = sampler.materialOptics(gm[iu][iv], gx[iu][iv]);
      gw[iu][iv] = renormalised(bilinear(parent.w, u, v), gs[iu][iv].x);
    }
  }
  double total_area = 0.0;
  std::array<double, 4> areas{};
  for (int j = 0; j < count; ++j) {
    const int u0 = j % nu, v0 = j / nu;
    const int cu[4] = {u0, u0 + 1, u0 + 1, u0};
    const int cv[4] = {v0, v0, v0 + 1, v0 + 1};
    Patch& child = children[j];
    for (int c = 0; c < 4; ++c) {
      child.x[c] = gx[cu[c]][cv[c]];
      child.w[c] = gw[cu[c]][cv[c]];
      child.medium[c] = gm[cu[c]][cv[c]];
      if (corner_samples) (*corner_samples)[j][c] = gs[cu[c]][cv[c]];
    }
    child.depth = parent.depth + 0.25 * count;  // +1 for 2×2, +½ for 1×2
    child.n_in = parent.n_in;
    child.cos_in = parent.cos_in;
    child.t_fresnel = parent.t_fresnel;
    child.reflect_pending = parent.reflect_pending;
    child.crossed = parent.crossed;
    child.reflected = parent.reflected;
    child.bounce = parent.bounce;
    areas[j] = child.area();
    child.area0 = areas[j];
    total_area += areas[j];
  }
  // Φ_child = Φ·A_child / Σ A_children: flux conserved exactly (to rounding).
  for (int j = 0; j < count; ++j)
    children[j].flux = total_area > 0.0 ? parent.flux * (areas[j] / total_area) : parent.flux / static_cast<double>(count);
  return count;
}

std::array<Patch, 4> splitPatch(const Patch& parent, const VolumeSampler& sampler,
                                std::array<std::array<glm::dvec4, 4>, 4>* corner_samples) {
  std::array<Patch, 4> children;
  splitPatch(parent, sampler, SplitAxes{true, true}, children, corner_samples);
  return children;
}

// ---------------------------------------------------------------------------------------------
// Fresnel (the corrected thesis Eq. 3.6; docs/physics.md)

double fresnelReflectance(double n1, double n2, double cos_i) {
  cos_i = std::min(std::fabs(cos_i), 1.0);
  const double sin_i2 = std::max(0.0, 1.0 - cos_i * cos_i);
  const double ratio = n1 / n2;
  const double sin_t2 = ratio * ratio * sin_i2;  // Snell: n1 sin θi = n2 sin θt
  if (sin_t2 >= 1.0) return 1.0;                 // beyond the critical angle
  const double cos_t = std::sqrt(1.0 - sin_t2);
  const double rs_den = n1 * cos_i + n2 * cos_t;
  const double rp_den = n1 * cos_t + n2 * cos_i;
  if (rs_den <= 0.0 || rp_den <= 0.0) return 1.0;
  const double rs = (n1 * cos_i - n2 * cos_t) / rs_den;
  const double rp = (n1 * cos_t - n2 * cos_i) / rp_den;
  return 0.5 * (rs * rs + rp * rp);
}

// Measured on a glass sphere (n = 1.5, R = 20 voxels, σ = 0.75 voxel, 64³, directional light):
// the exact formula at the inner edge (ALGORITHM.md as written) reflected 0.44 W of the 0.785 W
// through the sphere, against 0.129 W for the sharp sphere's entry + exit reflections
// ∫ (R + (1 − R)R) 2 sin θ cos θ dθ · πr²; with both rules below it gives 0.13 W (lightsim tests).
double boundaryReflectance(double n_in, double cos_in, double n_out, double cos_out, double index_tolerance) {
  if (std::fabs(n_out - n_in) < index_tolerance) return 0.0;
  if (n_in <= n_out || cos_out < 0.0) return fresnelReflectance(n_in, n_out, cos_in);
  return fresnelReflectance(n_out, n_in, cos_out);
}

// ---------------------------------------------------------------------------------------------
// Initialisation

void orthonormalBasis(const glm::dvec3& L, glm::dvec3& u, glm::dvec3& v) {
  const glm::dvec3 a = glm::abs(L);
  glm::dvec3 e(0.0);
  if (a.x <= a.y && a.x <= a.z) e.x = 1.0;
  else if (a.y <= a.z) e.y = 1.0;
  else e.z = 1.0;
  u = glm::normalize(glm::cross(e, L));
  v = glm::cross(L, u);
}

double cubeCellSolidAngle(double a0, double b0, double a1, double b1) {
  auto F = [](double a, double b) { return std::atan2(a * b, std::sqrt(a * a + b * b + 1.0)); };
  return F(a1, b1) - F(a0, b1) - F(a1, b0) + F(a0, b0);
}

const std::array<CubeFace, 6>& cubeFaces() {
  static const std::array<CubeFace, 6> faces{{
      {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},    // +X: y × z = x
      {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},   // −X: z × y = −x
      {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}},    // +Y: z × x = y
      {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},   // −Y: x × z = −y
      {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},    // +Z: x × y = z
      {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}},   // −Z: y × x = −z
  }};
  return faces;
}

double pointLightStartRadius(const glm::dvec3& position, const GridSpec& grid) {
  const double h = voxelEdge(grid);
  const double eps = 0.5 * h;
  const glm::dvec3 outside = glm::max(glm::max(grid.bounds_min - position, position - grid.bounds_max), glm::dvec3(0.0));
  const double dist = glm::length(outside);  // 0 inside the box
  return std::max(eps, dist - h);
}

int pointLightCubeResolution(double start_radius, const GridSpec& grid, const SimulationOptions& options) {
  const double edge = options.patch_voxels * voxelEdge(grid);
  const double m = std::ceil(2.0 * start_radius / edge - 1e-9);
  if (!(m >= 1.0)) return 1;
  return static_cast<int>(std::min<double>(m, kMaxCubeResolution));
}

namespace {


// Cells per side for a length: ceil(length/edge), at least 1; an exact multiple (to rounding) is
// not rounded up.
int cellsFor(double length, double edge) {
  const double n = std::ceil(length / edge - 1e-9);
  return n < 1.0 ? 1 : static_cast<int>(n);
}

// Does the ray origin + t·dir (t ≥ 0) meet the receiver map's rectangle, grown by `margin` (a
// patch whose midpoint ray passes just outside still covers the border texels)?
bool rayHitsMap(const glm::dvec3& origin, const glm::dvec3& dir, const ReceiverMap* map, double margin) {
  if (!map) return false;
  const double facing = glm::dot(dir, map->normal);
  if (!(facing < 0.0)) return false;
  const double t = -glm::dot(origin - map->point, map->normal) / facing;
  if (!(t >= 0.0)) return false;
  const glm::dvec2 uv = map->planeCoordinates(origin + t * dir) - map->origin;
  return uv.x >= -margin && uv.y >= -margin && uv.x <= map->texels.x * map->pitch + margin &&
         uv.y <= map->texels.y * map->pitch + margin;
}

std::vector<Patch> directionalPatches(const LightSpec& light, const GridSpec& grid, const VolumeSampler& sampler,
                                      const SimulationOptions& options, const ReceiverMap* map, DirectCells* direct,
                                      double* flux_ref) {
  const glm::dvec3 L = glm::normalize(light.direction);
  glm::dvec3 U, V;
  orthonormalBasis(L, U, V);
  const double h = voxelEdge(grid);
  glm::dvec3 lo, hi;
  propagationBox(grid, options, lo, hi);
  double umin = std::numeric_limits<double>::infinity(), umax = -umin, vmin = umin, vmax = -umin, tmin = umin;
  auto cover = [&](const glm::dvec3& c) {
    umin = std::min(umin, glm::dot(c, U));
    umax = std::max(umax, glm::dot(c, U));
    vmin = std::min(vmin, glm::dot(c, V));
    vmax = std::max(vmax, glm::dot(c, V));
    tmin = std::min(tmin, glm::dot(c, L));
  };
  for (int k = 0; k < 8; ++k) cover(glm::dvec3((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z));
  if (map) {
    // The receiver's map is lit wholly, also where the box does not shade it.
    const glm::dvec2 size = glm::dvec2(map->texels) * map->pitch;
    for (int k = 0; k < 4; ++k) {
      const glm::dvec2 uv = map->origin + glm::dvec2((k & 1) ? size.x : 0.0, (k & 2) ? size.y : 0.0);
      cover(map->point + uv.x * map->u + uv.y * map->v);
    }
  }
  // The plane through the box corner first along L, moved back by ½h.
  const double t0 = tmin - 0.5 * h;
  const double edge = options.patch_voxels * h;
  const int nu = cellsFor(umax - umin, edge), nv = cellsFor(vmax - vmin, edge);
  if (options.deposit_kernel == DepositKernel::Track) {
    // Patches of exactly `edge`: a plane wave along a grid axis then meets the deposit lattice
    // commensurately (track_deposit.h), and neighbouring maps tile alike.
    umax = umin + nu * edge;
    vmax = vmin + nv * edge;
  }
  auto uAt = [&](int i) { return umin + (umax - umin) * (static_cast<double>(i) / nu); };
  auto vAt = [&](int i) { return vmin + (vmax - vmin) * (static_cast<double>(i) / nv); };
  auto point = [&](double u, double v) { return u * U + v * V + t0 * L; };

  // The cells that go straight to the map, when they are left to directMapLight, per row.
  const bool leave_direct = direct != nullptr && map != nullptr;
  std::vector<DirectCells> row_direct(leave_direct ? static_cast<std::size_t>(nv) : 0);
  std::vector<double> row_ref(static_cast<std::size_t>(nv), 0.0);
  std::vector<std::vector<Patch>> rows(static_cast<std::size_t>(nv));
  parallelFor(0, nv, [&](std::int64_t iv64) {
    const int iv = static_cast<int>(iv64);
    std::vector<Patch>& row = rows[static_cast<std::size_t>(iv)];
    const double v0 = vAt(iv), v1 = vAt(iv + 1);
    for (int iu = 0; iu < nu; ++iu) {
      const double u0 = uAt(iu), u1 = uAt(iu + 1);
      Patch p;
      // x₀ = (u₀, v₀), x₁ = (u₁, v₀), x₂ = (u₁, v₁), x₃ = (u₀, v₁): N along L.
      p.x = {point(u0, v0), point(u1, v0), point(u1, v1), point(u0, v1)};
      const bool box = rayHitsBox(p.midpoint(), L, lo, hi);
      if (!box && !rayHitsMap(p.midpoint(), L, map, edge)) continue;
      if (!box && leave_direct) {
        const glm::dvec3 flux = light.power * p.area();  // Φ = E_L·A, as the patch would carry
        DirectCells& d = row_direct[static_cast<std::size_t>(iv)];
        ++d.cells;
        d.flux += flux;
        double& ref = row_ref[static_cast<std::size_t>(iv)];
        ref = std::max(ref, std::max(flux.x, std::max(flux.y, flux.z)));
        continue;
      }
      for (int c = 0; c < 4; ++c) {
        p.medium[c] = sampler.materialAt(p.x[c]);
        p.w[c] = L * sampler.materialOptics(p.medium[c], p.x[c]).x;
      }
      p.area0 = p.area();
      p.flux = light.power * p.area0;  // Φ = E_L·A
      row.push_back(p);
    }
  });
  std::vector<Patch> patches;
  for (auto& row : rows) patches.insert(patches.end(), row.begin(), row.end());
  for (const DirectCells& d : row_direct) {
    direct->cells += d.cells;
    direct->flux += d.flux;
  }
  if (flux_ref)
    for (const double ref : row_ref) *flux_ref = std::max(*flux_ref, ref);
  return patches;
}

std::vector<Patch> pointPatches(const LightSpec& light, const GridSpec& grid, const VolumeSampler& sampler,
                                const SimulationOptions& options, const ReceiverMap* map, DirectCells* direct,
                                double* flux_ref) {
  glm::dvec3 lo, hi;
  propagationBox(grid, options, lo, hi);
  const glm::dvec3 p = light.position;
  const double r0 = pointLightStartRadius(p, grid);
  const int m = pointLightCubeResolution(r0, grid, options);
  const auto& faces = cubeFaces();
  auto param = [m](int i) { return -1.0 + 2.0 * (static_cast<double>(i) / m); };

  // The cells that go straight to the map, when they are left to directMapLight, per row.
  const bool leave_direct = direct != nullptr && map != nullptr;
  std::vector<DirectCells> row_direct(leave_direct ? static_cast<std::size_t>(6 * m) : 0);
  std::vector<double> row_ref(static_cast<std::size_t>(6 * m), 0.0);
  std::vector<std::vector<Patch>> rows(static_cast<std::size_t>(6 * m));
  parallelFor(0, 6 * static_cast<std::int64_t>(m), [&](std::int64_t row_index) {
    const CubeFace& face = faces[static_cast<std::size_t>(row_index / m)];
    const int j = static_cast<int>(row_index % m);
    std::vector<Patch>& row = rows[static_cast<std::size_t>(row_index)];
    const double b0 = param(j), b1 = param(j + 1);
    auto dirAt = [&](double a, double b) { return glm::normalize(face.normal + a * face.s + b * face.t); };
    for (int i = 0; i < m; ++i) {
      const double a0 = param(i), a1 = param(i + 1);
      const glm::dvec3 centre = dirAt(0.5 * (a0 + a1), 0.5 * (b0 + b1));
      // A spot light sends nothing outside its cone (its intensity at the cell's centre direction).
      const double attenuation = light.attenuation(centre);
      if (!(attenuation > 0.0)) continue;
      const bool box = rayHitsBox(p, centre, lo, hi);
      if (!box && !rayHitsMap(p, centre, map, options.patch_voxels * voxelEdge(grid))) continue;
      if (!box && leave_direct) {
        const glm::dvec3 flux = light.power * (attenuation * cubeCellSolidAngle(a0, b0, a1, b1));  // Φ = I·Ω_cell
        DirectCells& d = row_direct[static_cast<std::size_t>(row_index)];
        ++d.cells;
        d.flux += flux;
        double& ref = row_ref[static_cast<std::size_t>(row_index)];
        ref = std::max(ref, std::max(flux.x, std::max(flux.y, flux.z)));
        continue;
      }
      const glm::dvec3 dirs[4] = {dirAt(a0, b0), dirAt(a1, b0), dirAt(a1, b1), dirAt(a0, b1)};
      Patch patch;
      for (int c = 0; c < 4; ++c) {
        patch.x[c] = p + r0 * dirs[c];
        patch.medium[c] = sampler.materialAt(patch.x[c]);
        patch.w[c] = sampler.materialOptics(patch.medium[c], patch.x[c]).x * dirs[c];
      }
      patch.area0 = patch.area();
      patch.flux = light.power * (attenuation * cubeCellSolidAngle(a0, b0, a1, b1));  // Φ = I·Ω_cell
      row.push_back(patch);
    }
  });
  std::vector<Patch> patches;
  for (auto& row : rows) patches.insert(patches.end(), row.begin(), row.end());
  for (const DirectCells& d : row_direct) {
    direct->cells += d.cells;
    direct->flux += d.flux;
  }
  if (flux_ref)
    for (const double ref : row_ref) *flux_ref = std::max(*flux_ref, ref);
  return patches;
}

}  // namespace

double brightestIrradiance(const LightSpec& light, const GridSpec& grid) {
  const double power = std::max(light.power.x, std::max(light.power.y, light.power.z));
  if (light.type == LightSpec::Type::Directional) return power;
  const glm::dvec3 nearest = glm::clamp(light.position, grid.bounds_min, grid.bounds_max);
  const double d2 = glm::dot(nearest - light.position, nearest - light.position);
  return d2 > 0.0 ? power / d2 : 0.0;
}

void validateLight(const LightSpec& light) {
  if (!finite3(light.power)) throw InputError("light", "power", "must be finite");
  if (light.power.x < 0.0 || light.power.y < 0.0 || light.power.z < 0.0)
    throw InputError("light", "power", "must not be negative");
  if (std::max(light.power.x, std::max(light.power.y, light.power.z)) > kMaxLightPower)
    throw InputError("light", "power", "must be at most 1e30 (bakes store 32-bit floats)");
  if (light.type == LightSpec::Type::Directional) {
    if (!finite3(light.direction) || glm::length(light.direction) == 0.0)
      throw InputError("light", "direction", "must be a finite, non-zero vector");
  } else if (!finite3(light.position)) {
    throw InputError("light", "position", "must be finite");
  }
  if (!(light.angular_diameter_deg >= 0.0 && light.angular_diameter_deg <= kMaxAngularDiameterDeg))
    throw InputError("light", "angular_diameter_deg", "must be in [0, 20] degrees");
  if (!(light.radius >= 0.0 && std::isfinite(light.radius))) throw InputError("light", "radius", "must be finite, >= 0");
  if (light.type == LightSpec::Type::Spot) {
    if (!finite3(light.direction) || glm::length(light.direction) == 0.0)
      throw InputError("light", "direction", "a spot light's axis must be a finite, non-zero vector");
    if (!(light.outer_cone_deg > 0.0 && light.outer_cone_deg <= 90.0 && light.inner_cone_deg >= 0.0 &&
          light.inner_cone_deg < light.outer_cone_deg))
      throw InputError("light", "cone", "expected 0 <= inner_cone_deg < outer_cone_deg <= 90");
  }
}

std::vector<Patch> initialPatches(const LightSpec& light, const GridSpec& grid, const VolumeSampler& sampler,
                                  const SimulationOptions& options, double* flux_ref, const ReceiverMap* map,
                                  DirectCells* direct) {
  validateLight(light);
  validateOptions(options);
  if (direct) *direct = DirectCells{};
  double ref = 0.0;  // the left-out cells' (directionalPatches), then the patches'
  std::vector<Patch> patches =
      light.type == LightSpec::Type::Directional
          ? directionalPatches(light, grid, sampler, options, map, options.direct_receiver_light ? direct : nullptr, &ref)
          : pointPatches(light, grid, sampler, options, map, options.direct_receiver_light ? direct : nullptr, &ref);
  if (flux_ref) {
    for (const Patch& patch : patches) ref = std::max(ref, std::max(patch.flux.x, std::max(patch.flux.y, patch.flux.z)));
    *flux_ref = ref;
  }
  return patches;
}

void adjustInitialPatches(std::vector<Patch>& patches, const VolumeSampler& sampler, const SimulationOptions& options,
                          double& flux_ref) {
  if (!options.initial_patches) return;
  options.initial_patches(patches, sampler);
  for (const Patch& patch : patches) flux_ref = std::max(flux_ref, std::max(patch.flux.x, std::max(patch.flux.y, patch.flux.z)));
}

// ---------------------------------------------------------------------------------------------
// Constants of a run

void propagationBox(const GridSpec& grid, const SimulationOptions& options, glm::dvec3& lo, glm::dvec3& hi) {
  const double margin = options.deposit_kernel == DepositKernel::Track ? voxelEdge(grid) : 0.0;
  lo = grid.bounds_min - margin;
  hi = grid.bounds_max + margin;
}

void validateOptions(const SimulationOptions& o) {
  auto positive = [](double v, const char* name) {
    if (!std::isfinite(v) || v <= 0.0) throw InputError(kOptionsSource, name, "must be a positive number");
  };
  positive(o.step_voxels, "step_voxels");
  positive(o.patch_voxels, "patch_voxels");
  positive(o.split_voxels, "split_voxels");
  if (o.max_depth < 0 || o.max_depth > 16) throw InputError(kOptionsSource, "max_depth", "must be in [0, 16]");
  if (!std::isfinite(o.flux_threshold) || o.flux_threshold < 0.0)
    throw InputError(kOptionsSource, "flux_threshold", "must not be negative");
  if (o.max_steps < 0) throw InputError(kOptionsSource, "max_steps", "must not be negative");
  if (!std::isfinite(o.straight_step_voxels) || o.straight_step_voxels < 0.0 || o.straight_step_voxels > 64.0)
    throw InputError(kOptionsSource, "straight_step_voxels", "must be in [0, 64]");
  if (!std::isfinite(o.boundary_on) || !std::isfinite(o.boundary_off) || o.boundary_off < 0.0 ||
      o.boundary_off > o.boundary_on)
    throw InputError(kOptionsSource, "boundary_off", "must be in [0, boundary_on]");
}

double timeStep(const GridSpec& grid, const SimulationOptions& options) { return options.step_voxels * voxelEdge(grid); }

int maxSteps(const GridSpec& grid, const SimulationOptions& options) {
  if (options.max_steps > 0) return options.max_steps;
  const double steps = std::ceil(4.0 * glm::length(grid.extent()) / timeStep(grid, options));
  return static_cast<int>(std::min(steps, 1e9));
}

}  // namespace eik
