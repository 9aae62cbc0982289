// The volume analysis of viewer/volume_analysis.h.
#include "viewer/volume_analysis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/parallel.h"

namespace eik {

namespace {

// The fields the analyses read (null where the volume has none).
struct MediumFields {
  const Field *ior, *grad, *sigma, *emission, *scatter, *opaque;
  explicit MediumFields(const Volume& v)
      : ior(v.find("ior")), grad(v.find("ior_grad")), sigma(v.find("sigma_a")), emission(v.find("emission")),
        scatter(v.find("scatter")), opaque(v.find("opaque")) {}
};

}  // namespace

bool activeRegion(const Volume& volume, glm::dvec3& lo, glm::dvec3& hi) {
  const GridSpec& grid = volume.grid;
  const glm::ivec3 dims = grid.dims;
  const double h = std::min({grid.voxelSize().x, grid.voxelSize().y, grid.voxelSize().z});
  const MediumFields f(volume);
  const Field *ior = f.ior, *grad = f.grad, *sigma = f.sigma, *emission = f.emission, *scatter = f.scatter,
              *opaque = f.opaque;
  auto nontrivial = [&](std::size_t i) {
    auto positive3 = [&](const Field* f) { return f && (f->voxel(i)[0] > 0 || f->voxel(i)[1] > 0 || f->voxel(i)[2] > 0); };
    if (ior && std::abs(ior->voxel(i)[0] - 1.0f) > 1e-5f) return true;
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

std::vector<float> homogeneousBricks(const Volume& volume, glm::ivec3& brick_dims) {
  const GridSpec& grid = volume.grid;
  const glm::ivec3 dims = grid.dims;
  brick_dims = (dims + kBrickVoxels - 1) / kBrickVoxels;
  const double h = std::min({grid.voxelSize().x, grid.voxelSize().y, grid.voxelSize().z});
  const MediumFields f(volume);
  const Field *ior = f.ior, *grad = f.grad, *sigma = f.sigma, *emission = f.emission, *scatter = f.scatter,
              *opaque = f.opaque;
  // Per voxel: does it break homogeneity by itself (∇n, emission, scattering, opaque)?
  std::vector<unsigned char> busy(grid.count(), 0);
  parallelFor(
      0, static_cast<std::int64_t>(grid.count()),
      [&](std::int64_t i64) {
        const std::size_t i = static_cast<std::size_t>(i64);
        const float* g = grad ? grad->voxel(i) : nullptr;  // ∇n left unread: 0 (constant-n materials)
        bool b = g && (std::abs(g[0]) + std::abs(g[1]) + std::abs(g[2])) * h > 1e-4;
        if (emission) b = b || emission->voxel(i)[0] > 0 || emission->voxel(i)[1] > 0 || emission->voxel(i)[2] > 0;
        if (scatter) b = b || scatter->voxel(i)[0] > 0;
        if (opaque) b = b || opaque->voxel(i)[3] > 0;
        busy[i] = b;
      },
      1 << 15);
  std::vector<float> bricks(static_cast<std::size_t>(brick_dims.x) * brick_dims.y * brick_dims.z, 0.0f);
  parallelFor(0, brick_dims.z, [&](std::int64_t bz64) {
    const int bz = static_cast<int>(bz64);
    for (int by = 0; by < brick_dims.y; ++by)
      for (int bx = 0; bx < brick_dims.x; ++bx) {
        const glm::ivec3 lo = glm::max(glm::ivec3(bx, by, bz) * kBrickVoxels - kBrickMargin, glm::ivec3(0));
        const glm::ivec3 hi = glm::min(glm::ivec3(bx, by, bz) * kBrickVoxels + kBrickVoxels + kBrickMargin, dims) - 1;
        const std::size_t first = grid.index(lo.x, lo.y, lo.z);
        bool homogeneous = true;
        for (int k = lo.z; k <= hi.z && homogeneous; ++k)
          for (int j = lo.y; j <= hi.y && homogeneous; ++j)
            for (int i = lo.x; i <= hi.x && homogeneous; ++i) {
              const std::size_t v = grid.index(i, j, k);
              if (busy[v] || std::abs(ior->data[v] - ior->data[first]) > 1e-4f) homogeneous = false;
              if (sigma)
                for (int c = 0; c < 3; ++c)
                  if (std::abs(sigma->voxel(v)[c] - sigma->voxel(first)[c]) > 1e-6f * (1.0f + sigma->voxel(first)[c]))
                    homogeneous = false;
            }
        bricks[(static_cast<std::size_t>(bz) * brick_dims.y + by) * brick_dims.x + bx] = homogeneous ? 1.0f : 0.0f;
      }
  });
  return bricks;
}

bool materialTouchesBox(const Volume& volume) {
  const GridSpec& grid = volume.grid;
  const Field* ior = volume.find("ior");
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const bool face = i == 0 || j == 0 || k == 0 || i == grid.dims.x - 1 || j == grid.dims.y - 1 ||
                          k == grid.dims.z - 1;
        if (face && std::abs(ior->data[grid.index(i, j, k)] - 1.0f) > 1e-3f) return true;
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
  auto constantIn = [&](const Field* field, auto&& recorded, auto&& store) {
    if (!field) return true;  // absent: 0 everywhere, as the media start
    const MaterialValues deep = deepMaterialValues(volume, table, *field, depth);
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
  result.sigma_a_constant = constantIn(
      volume.find("sigma_a"), [](const InterfaceSlot& s) { return s.sigma_a; },
      [](MaterialMedium& medium, const glm::dvec3& x) { medium.sigma_a = x; });
  result.scatter_constant = constantIn(
      volume.find("scatter"), [](const InterfaceSlot&) { return std::optional<glm::dvec3>(); },
      [](MaterialMedium& medium, const glm::dvec3& x) { medium.scatter = glm::dvec2(x); });
  if (!result.sigma_a_constant)
    for (MaterialMedium& m : result.media) m.sigma_a = glm::dvec3(0.0);
  if (!result.scatter_constant)
    for (MaterialMedium& m : result.media) m.scatter = glm::dvec2(0.0);
  return result;
}

}  // namespace eik
