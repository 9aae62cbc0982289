// The volume analysis of viewer/volume_analysis.h.
#include "viewer/volume_analysis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"

namespace eik {

namespace {

// n at each voxel: the ior field's, or where it was left unread in a volume of sharp constant-n
// materials (SceneLoadOptions::leave_constant_optics_unread) the n its interface distances give,
// which is what voxelize wrote (core/interfaces.h slotIndexAt); 1 in a volume without either.
class IndexAt {
 public:
  explicit IndexAt(const Volume& v) : ior_(v.find("ior")) {
    if (ior_ || !v.unread_fields.count("ior")) return;
    table_ = interfaceTable(v);
    if (constantSlots(table_)) distances_ = v.find("interfaces");
  }
  bool known() const { return ior_ || distances_; }
  float operator()(std::size_t i) const {
    if (ior_) return ior_->data[i];
    return distances_ ? slotIndexAt(table_, distances_->data.data(), distances_->components, i) : 1.0f;
  }

 private:
  const Field* ior_;
  InterfaceTable table_;
  const Field* distances_ = nullptr;
};

// The fields the analyses read (null where the volume has none).
struct MediumFields {
  IndexAt n;  // the ior field or what stands for it
  const Field *grad, *sigma, *emission, *scatter, *opaque;
  explicit MediumFields(const Volume& v)
      : n(v), grad(v.find("ior_grad")), sigma(v.find("sigma_a")), emission(v.find("emission")),
        scatter(v.find("scatter")), opaque(v.find("opaque")) {}
};

}  // namespace

bool activeRegion(const Volume& volume, glm::dvec3& lo, glm::dvec3& hi) {
  const GridSpec& grid = volume.grid;
  const glm::ivec3 dims = grid.dims;
  const double h = std::min({grid.voxelSize().x, grid.voxelSize().y, grid.voxelSize().z});
  const MediumFields f(volume);
  const Field *grad = f.grad, *sigma = f.sigma, *emission = f.emission, *scatter = f.scatter, *opaque = f.opaque;
  auto nontrivial = [&](std::size_t i) {
    auto positive3 = [&](const Field* f) { return f && (f->voxel(i)[0] > 0 || f->voxel(i)[1] > 0 || f->voxel(i)[2] > 0); };
    if (std::abs(f.n(i) - 1.0f) > 1e-5f) return true;
    if (grad) {
      const float* v = grad->voxel(i);
      if ((std::abs(v[0]) + std::abs(v[1]) + std::abs(v[2])) * h > 1e-6) return true;
    }
    return positive3(sigma) || positive3(emission) || (scatter && scatter->voxel(i)[0] > 0) ||
           (opaque && opaque->voxel(i)[3] > 0);
  };
  // Each z-slice's extent in parallel, then theirs together.
  std::vector<glm::ivec3> slice_min(static_cast<std::size_t>(dims.z), dims), slice_max(static_cast<std::size_t>(dims.z), glm::ivec3(-1));
  parallelFor(0, dims.z, [&](std::int64_t z64) {
    const int z = static_cast<int>(z64);
    glm::ivec3& smin = slice_min[static_cast<std::size_t>(z)];
    glm::ivec3& smax = slice_max[static_cast<std::size_t>(z)];
    for (int y = 0; y < dims.y; ++y) {
      // A row's extent from its two ends: its first and last non-trivial voxels (its inside, an
      // object's interior, needs no look).
      int first = 0;
      while (first < dims.x && !nontrivial(grid.index(first, y, z))) ++first;
      if (first == dims.x) continue;
      int last = dims.x - 1;
      while (!nontrivial(grid.index(last, y, z))) --last;
      smin = glm::min(smin, glm::ivec3(first, y, z));
      smax = glm::max(smax, glm::ivec3(last, y, z));
    }
  });
  glm::ivec3 imin(dims), imax(-1);
  for (int z = 0; z < dims.z; ++z) {
    imin = glm::min(imin, slice_min[static_cast<std::size_t>(z)]);
    imax = glm::max(imax, slice_max[static_cast<std::size_t>(z)]);
  }
  if (imax.x < 0) return false;
  const glm::dvec3 voxel = grid.voxelSize();
  lo = glm::max(grid.bounds_min, grid.bounds_min + glm::dvec3(imin - 1) * voxel);
  hi = glm::min(grid.bounds_max, grid.bounds_min + glm::dvec3(imax + 2) * voxel);
  return true;
}

namespace {

// The window of voxels along one axis that brick b reads: its kBrickVoxels and kBrickMargin on
// either side, clamped to the grid ([first, last)).
void brickWindow(int b, int voxels, int& first, int& last) {
  first = std::max(b * kBrickVoxels - kBrickMargin, 0);
  last = std::min(b * kBrickVoxels + kBrickVoxels + kBrickMargin, voxels);
}

// The least and greatest value of each of `channels` channels (n; σa's three) and whether a voxel
// breaks homogeneity by itself, over boxes of voxels: structure of arrays, element e's channel c
// at e·channels + c.
struct BoxRanges {
  int channels = 1;
  std::vector<float> lo, hi;
  std::vector<std::uint8_t> busy;

  BoxRanges(std::size_t elements, int c)
      : channels(c), lo(elements * static_cast<std::size_t>(c)), hi(elements * static_cast<std::size_t>(c)), busy(elements) {}
};

// The least and greatest of each of C channels over `count` elements `step` apart (C floats each)
// into lo and hi: kept in registers, written once.
template <int C>
void rangeOf(const float* lo_in, const float* hi_in, std::size_t step, int count, float* lo, float* hi) {
  float l[C], u[C];
  for (int k = 0; k < C; ++k) l[k] = lo_in[k], u[k] = hi_in[k];
  for (int v = 1; v < count; ++v) {
    const std::size_t at = static_cast<std::size_t>(v) * step * C;
    for (int k = 0; k < C; ++k) {
      l[k] = std::min(l[k], lo_in[at + static_cast<std::size_t>(k)]);
      u[k] = std::max(u[k], hi_in[at + static_cast<std::size_t>(k)]);
    }
  }
  for (int k = 0; k < C; ++k) lo[k] = l[k], hi[k] = u[k];
}

void rangeOf(int channels, const float* lo_in, const float* hi_in, std::size_t step, int count, float* lo, float* hi) {
  if (channels == 1) rangeOf<1>(lo_in, hi_in, step, count, lo, hi);
  else rangeOf<4>(lo_in, hi_in, step, count, lo, hi);
}

// `in` (dims) reduced along `axis` over each brick's window: dims[axis] becomes the brick count.
BoxRanges reduceAlong(const BoxRanges& in, glm::ivec3 dims, int axis, glm::ivec3& out_dims) {
  out_dims = dims;
  out_dims[axis] = (dims[axis] + kBrickVoxels - 1) / kBrickVoxels;
  const int c = in.channels;
  BoxRanges out(static_cast<std::size_t>(out_dims.x) * out_dims.y * out_dims.z, c);
  const std::size_t stride[3] = {1, static_cast<std::size_t>(dims.x), static_cast<std::size_t>(dims.x) * dims.y};
  parallelFor(0, out_dims.z, [&](std::int64_t z) {
    const float* in_lo = in.lo.data();
    const float* in_hi = in.hi.data();
    const std::uint8_t* in_busy = in.busy.data();
    const std::size_t step = stride[axis];
    for (int y = 0; y < out_dims.y; ++y)
      for (int x = 0; x < out_dims.x; ++x) {
        glm::ivec3 o(x, y, static_cast<int>(z));
        int first = 0, last = 0;
        brickWindow(o[axis], dims[axis], first, last);
        const std::size_t e = (static_cast<std::size_t>(o.z) * out_dims.y + static_cast<std::size_t>(o.y)) * out_dims.x + static_cast<std::size_t>(o.x);
        o[axis] = first;
        const std::size_t base = (static_cast<std::size_t>(o.z) * dims.y + static_cast<std::size_t>(o.y)) * dims.x + static_cast<std::size_t>(o.x);
        rangeOf(c, in_lo + base * c, in_hi + base * c, step, last - first, &out.lo[e * c], &out.hi[e * c]);
        std::uint8_t busy = 0;
        for (int v = 0; v < last - first; ++v) busy |= in_busy[base + static_cast<std::size_t>(v) * step];
        out.busy[e] = busy;
      }
  });
  return out;
}

}  // namespace

std::vector<float> homogeneousBricks(const Volume& volume, glm::ivec3& brick_dims) {
  const GridSpec& grid = volume.grid;
  const glm::ivec3 dims = grid.dims;
  brick_dims = (dims + kBrickVoxels - 1) / kBrickVoxels;
  const double h = std::min({grid.voxelSize().x, grid.voxelSize().y, grid.voxelSize().z});
  const MediumFields f(volume);
  const Field *grad = f.grad, *sigma = f.sigma, *emission = f.emission, *scatter = f.scatter, *opaque = f.opaque;
  if (!f.n.known()) throw InputError("volume", "ior", "the homogeneous bricks need n");
  // A brick is homogeneous when no voxel of its box (the brick and its margin) is busy — breaks
  // homogeneity by itself with ∇n, emission, scattering or an opaque embedding — and n and each σa
  // differ from those of the box's first voxel by no more than the tolerances. The box is a product
  // of three windows, so the least and greatest n and σa over it come one axis at a time: along x
  // straight from the fields, then along y and z over the shrinking arrays (each voxel is read by
  // two windows of a row, not by the (4 + 2·2)³ / 4³ = 8 boxes that hold it). Rounding is monotonic,
  // so the largest |v − first| is that of the least or greatest v: the same bricks as comparing
  // every voxel of every box.
  const int channels = sigma ? 4 : 1;
  const bool any_busy = grad || emission || scatter || opaque;  // ∇n left unread or out: 0
  glm::ivec3 row_dims(brick_dims.x, dims.y, dims.z);
  BoxRanges rows(static_cast<std::size_t>(row_dims.x) * row_dims.y * row_dims.z, channels);
  parallelFor(0, dims.z, [&](std::int64_t z) {
    std::vector<float> values(static_cast<std::size_t>(dims.x) * channels);  // one row, channels interleaved
    std::vector<std::uint8_t> busy(static_cast<std::size_t>(dims.x), 0);
    for (int y = 0; y < dims.y; ++y) {
      const std::size_t row = grid.index(0, y, static_cast<int>(z));
      for (int x = 0; x < dims.x; ++x) {
        const std::size_t i = row + static_cast<std::size_t>(x);
        float* v = &values[static_cast<std::size_t>(x) * channels];
        v[0] = f.n(i);
        if (sigma) std::copy_n(sigma->voxel(i), 3, v + 1);
        if (!any_busy) continue;
        const float* g = grad ? grad->voxel(i) : nullptr;
        bool b = g && (std::abs(g[0]) + std::abs(g[1]) + std::abs(g[2])) * h > 1e-4;
        if (emission) b = b || emission->voxel(i)[0] > 0 || emission->voxel(i)[1] > 0 || emission->voxel(i)[2] > 0;
        if (scatter) b = b || scatter->voxel(i)[0] > 0;
        if (opaque) b = b || opaque->voxel(i)[3] > 0;
        busy[static_cast<std::size_t>(x)] = b;
      }
      for (int bx = 0; bx < brick_dims.x; ++bx) {
        int first = 0, last = 0;
        brickWindow(bx, dims.x, first, last);
        const std::size_t e = (static_cast<std::size_t>(z) * dims.y + static_cast<std::size_t>(y)) * brick_dims.x + bx;
        const float* v = &values[static_cast<std::size_t>(first) * channels];
        rangeOf(channels, v, v, 1, last - first, &rows.lo[e * channels], &rows.hi[e * channels]);
        std::uint8_t any = 0;
        for (int x = first; x < last; ++x) any |= busy[static_cast<std::size_t>(x)];
        rows.busy[e] = any;
      }
    }
  });
  glm::ivec3 column_dims, brick_check;
  const BoxRanges columns = reduceAlong(rows, row_dims, 1, column_dims);
  const BoxRanges boxes = reduceAlong(columns, column_dims, 2, brick_check);
  std::vector<float> bricks(static_cast<std::size_t>(brick_dims.x) * brick_dims.y * brick_dims.z, 0.0f);
  for (int bz = 0; bz < brick_dims.z; ++bz)
    for (int by = 0; by < brick_dims.y; ++by)
      for (int bx = 0; bx < brick_dims.x; ++bx) {
        const std::size_t e = (static_cast<std::size_t>(bz) * brick_dims.y + by) * brick_dims.x + bx;
        const glm::ivec3 lo = glm::max(glm::ivec3(bx, by, bz) * kBrickVoxels - kBrickMargin, glm::ivec3(0));
        const std::size_t first = grid.index(lo.x, lo.y, lo.z);
        bool homogeneous = boxes.busy[e] == 0;
        const float* vlo = &boxes.lo[e * channels];
        const float* vhi = &boxes.hi[e * channels];
        const float n0 = f.n(first);
        if (std::abs(vhi[0] - n0) > 1e-4f || std::abs(vlo[0] - n0) > 1e-4f) homogeneous = false;
        for (int c = 1; c < channels; ++c) {
          const float s0 = sigma->voxel(first)[c - 1];
          if (std::abs(vhi[c] - s0) > 1e-6f * (1.0f + s0) || std::abs(vlo[c] - s0) > 1e-6f * (1.0f + s0)) homogeneous = false;
        }
        bricks[e] = homogeneous ? 1.0f : 0.0f;
      }
  return bricks;
}

bool materialTouchesBox(const Volume& volume) {
  const GridSpec& grid = volume.grid;
  const IndexAt n(volume);
  if (!n.known()) throw InputError("volume", "ior", "whether the material touches the box needs n");
  const glm::ivec3 last = grid.dims - 1;
  auto material = [&](int i, int j, int k) { return std::abs(n(grid.index(i, j, k)) - 1.0f) > 1e-3f; };
  // The two faces across z, then across y, then across x (only the voxels on the box's faces).
  for (int k : {0, last.z})
    for (int j = 0; j <= last.y; ++j)
      for (int i = 0; i <= last.x; ++i)
        if (material(i, j, k)) return true;
  for (int k = 0; k <= last.z; ++k) {
    for (int j : {0, last.y})
      for (int i = 0; i <= last.x; ++i)
        if (material(i, j, k)) return true;
    for (int j = 0; j <= last.y; ++j)
      if (material(0, j, k) || material(last.x, j, k)) return true;
  }
  return false;
}

bool absorbingRegion(const Volume& volume, glm::dvec3& lo, glm::dvec3& hi) {
  const Field* sigma = volume.find("sigma_a");
  if (!sigma) return false;
  const GridSpec& grid = volume.grid;
  glm::ivec3 imin(grid.dims), imax(-1);
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const float* v = sigma->voxel(grid.index(i, j, k));
        if (v[0] > 0 || v[1] > 0 || v[2] > 0) {
          imin = glm::min(imin, glm::ivec3(i, j, k));
          imax = glm::max(imax, glm::ivec3(i, j, k));
        }
      }
  if (imax.x < 0) return false;
  const glm::dvec3 voxel = grid.voxelSize();
  lo = glm::max(grid.bounds_min, grid.bounds_min + glm::dvec3(imin - 1) * voxel);
  hi = glm::min(grid.bounds_max, grid.bounds_min + glm::dvec3(imax + 2) * voxel);
  return true;
}

SlotMedia slotMedia(const Volume& volume, const InterfaceTable& table) {
  SlotMedia result;
  const Field* interfaces = volume.find("interfaces");
  if (table.empty() || !interfaces) return result;
  const int slots = static_cast<int>(table.slots.size());
  result.media.assign(static_cast<std::size_t>(slots) + 1, MaterialMedium{});
  const GridSpec& grid = volume.grid;
  const double depth = kMediumDepthVoxels * std::min({grid.voxelSize().x, grid.voxelSize().y, grid.voxelSize().z});
  // For one field: each material's value where it is deep inside, and whether it is one value there;
  // `recorded` (σa: the slot table's) stands in for a material with no deep voxel and must agree
  // with its deep voxels where it has some.
  auto constantIn = [&](const Field* field, auto&& recorded, auto&& store, bool with_air) {
    if (!field) return true;  // absent: 0 everywhere, as the media start
    const MaterialValues deep = deepMaterialValues(volume, table, *field, depth, with_air);
    if (!deep.one_value) return false;
    for (std::size_t m = 0; m < result.media.size(); ++m) {
      const bool opaque = m > 0 && table.slots[m - 1].opaque;
      const std::optional<glm::dvec3> known = m > 0 ? recorded(table.slots[m - 1]) : std::nullopt;
      if (known && deep.seen[m] && glm::vec3(*known) != glm::vec3(deep.value[m])) return false;
      // A material never met deep inside: unknown, unless the table knows it, it is air (a material
      // that fills the box leaves no air inside it) or opaque (no ray goes on in it).
      if (!deep.seen[m] && m > 0 && !opaque && !known) return false;
      if (deep.seen[m] || known) store(result.media[m], deep.seen[m] ? deep.value[m] : *known);
    }
    return true;
  };
  auto constants = [&](bool with_air) {
    result.sigma_a_constant = constantIn(
        volume.find("sigma_a"), [](const InterfaceSlot& s) { return s.sigma_a; },
        [](MaterialMedium& medium, const glm::dvec3& x) { medium.sigma_a = x; }, with_air);
    result.scatter_constant = constantIn(
        volume.find("scatter"), [](const InterfaceSlot&) { return std::optional<glm::dvec3>(); },
        [](MaterialMedium& medium, const glm::dvec3& x) { medium.scatter = glm::dvec2(x); }, with_air);
  };
  constants(true);
  // The air alone may vary, as a box of smoke: every slot's medium one constant without it.
  if (!(result.sigma_a_constant && result.scatter_constant)) {
    if (std::optional<AirMedium> box = airMediumBox(volume, table, depth)) {
      const SlotMedia with_air = result;
      result.media.assign(result.media.size(), MaterialMedium{});
      constants(false);
      if (result.sigma_a_constant && result.scatter_constant) {
        result.air_box = box;
        result.media[0] = MaterialMedium{};  // outside the box
      } else {
        result = with_air;
      }
    }
  }
  if (!result.sigma_a_constant)
    for (MaterialMedium& m : result.media) m.sigma_a = glm::dvec3(0.0);
  if (!result.scatter_constant)
    for (MaterialMedium& m : result.media) m.scatter = glm::dvec2(0.0);
  return result;
}

}  // namespace eik
