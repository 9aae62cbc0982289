#include "voxelize/sharp_interfaces.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "core/parallel.h"

namespace eik {
namespace {

bool graded(const Region& r) { return !r.ior.empty(); }

// What makes two regions one optical material.
std::string opticalKey(const Region& r, std::size_t index) {
  if (r.material.opaque) return "opaque";
  if (graded(r)) return "graded#" + std::to_string(index);
  char key[64];
  std::snprintf(key, sizeof key, "n=%.7g,B=%.7g", static_cast<double>(r.material.ior),
                static_cast<double>(r.material.dispersion_b));
  return key;
}

bool airLike(const Region& r) { return !r.material.opaque && !graded(r) && r.material.ior == 1.0f; }

// ∇n of the graded materials (buildSharpVolume): central differences of n where all three axes'
// neighbours carry the same graded n, one-sided next to a homogeneous voxel, 0 elsewhere.
void addGradedGradient(Volume& volume, const GridSpec& grid, std::size_t stride, int slot_count,
                       const std::vector<int>& graded_region_of_slot, float band_f) {
  const Field& interfaces = volume.fields.at("interfaces");
  const Field& ior = volume.fields.at("ior");
  Field& grad = volume.addField("ior_grad", 3);
  const glm::dvec3 h = grid.voxelSize();
  auto gradedAt = [&](int i, int j, int k) {
    const float* d = &interfaces.data[stride * grid.index(i, j, k)];
    for (int s = 0; s < slot_count; ++s)
      if (graded_region_of_slot[static_cast<std::size_t>(s)] >= 0 && d[s] < band_f) return true;
    return false;
  };
  parallelFor(0, grid.dims.z, [&](std::int64_t zz) {
    const int k = static_cast<int>(zz);
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        if (!gradedAt(i, j, k)) continue;
        const glm::ivec3 c(i, j, k);
        float* g = grad.voxel(grid.index(i, j, k));
        for (int axis = 0; axis < 3; ++axis) {
          glm::ivec3 lo = c, hi = c;
          lo[axis] -= 1;
          hi[axis] += 1;
          const bool has_lo = lo[axis] >= 0 && gradedAt(lo.x, lo.y, lo.z);
          const bool has_hi = hi[axis] < grid.dims[axis] && gradedAt(hi.x, hi.y, hi.z);
          const double n_c = ior.data[grid.index(c.x, c.y, c.z)];
          double derivative = 0.0;
          if (has_lo && has_hi)
            derivative = (ior.data[grid.index(hi.x, hi.y, hi.z)] - ior.data[grid.index(lo.x, lo.y, lo.z)]) / (2.0 * h[axis]);
          else if (has_hi)
            derivative = (ior.data[grid.index(hi.x, hi.y, hi.z)] - n_c) / h[axis];
          else if (has_lo)
            derivative = (n_c - ior.data[grid.index(lo.x, lo.y, lo.z)]) / h[axis];
          g[axis] = static_cast<float>(derivative);
        }
      }
  });
}

}  // namespace

SlotAssignment assignInterfaceSlots(const std::vector<Region>& regions, double band) {
  SlotAssignment result;
  result.table.band = band;
  result.slot_of_region.assign(regions.size(), -1);
  const std::vector<std::size_t> order = compositeOrder(regions);
  // Air-like regions after the last region that is not: nothing outside them differs from air.
  std::size_t last_optical = 0;
  bool any_optical = false;
  for (std::size_t rank = 0; rank < order.size(); ++rank)
    if (!airLike(regions[order[rank]])) last_optical = rank, any_optical = true;
  std::map<std::string, int> slot_of_key;
  std::vector<std::string> names;
  for (std::size_t rank = 0; rank < order.size(); ++rank) {
    const std::size_t i = order[rank];
    const Region& r = regions[i];
    if (airLike(r) && (!any_optical || rank > last_optical)) continue;
    const std::string key = opticalKey(r, i);
    auto found = slot_of_key.find(key);
    if (found == slot_of_key.end()) {
      InterfaceSlot slot;
      slot.name = r.material.opaque ? "opaque" : r.material.name;
      slot.ior = r.material.opaque ? 1.0 : static_cast<double>(r.material.ior);
      slot.dispersion_b = r.material.opaque ? 0.0 : static_cast<double>(r.material.dispersion_b);
      slot.graded = graded(r);
      slot.opaque = r.material.opaque;
      if (!r.material.opaque) slot.sigma_a = glm::dvec3(r.material.sigma_a);
      found = slot_of_key.emplace(key, static_cast<int>(result.table.slots.size())).first;
      result.table.slots.push_back(slot);
      names.push_back(r.name);
    } else {
      names[static_cast<std::size_t>(found->second)] += ", " + r.name;
      // Objects of one n but different σa: the slot has no σa of its own (the field has it).
      InterfaceSlot& slot = result.table.slots[static_cast<std::size_t>(found->second)];
      if (slot.sigma_a && *slot.sigma_a != glm::dvec3(r.material.sigma_a)) slot.sigma_a.reset();
    }
    result.slot_of_region[i] = found->second;
  }
  if (result.table.slots.size() > static_cast<std::size_t>(kMaxInterfaceSlots)) {
    std::string list;
    for (std::size_t k = 0; k < names.size(); ++k) list += (k ? "; " : "") + names[k];
    throw InputError("--interfaces", "sharp",
                     std::to_string(result.table.slots.size()) + " distinct materials need an interface (" + list +
                         "), at most " + std::to_string(kMaxInterfaceSlots) +
                         " are supported: give objects of one material the same n, or use --interfaces smooth");
  }
  return result;
}

namespace {

// buildSharpVolume; `releasable` (the same regions, or null) gives up each array once read.
Volume buildSharp(const std::vector<Region>& regions, std::vector<Region>* releasable, const GridSpec& grid,
                  double band, const CompositeOptions& options) {
  auto release = [&](std::vector<float> Region::*array) {
    if (releasable)
      for (Region& r : *releasable) std::vector<float>().swap(r.*array);
  };
  const std::size_t count = grid.count();
  for (const Region& r : regions) {
    if (r.distance.size() != count)
      throw std::invalid_argument("buildSharpVolume: region '" + r.name + "' has no distance field");
    if (graded(r) && r.ior_at_center.size() != count)
      throw std::invalid_argument("buildSharpVolume: graded region '" + r.name + "' has no ior_at_center");
  }
  const SlotAssignment slots = assignInterfaceSlots(regions, band);
  const int slot_count = static_cast<int>(slots.table.slots.size());

  // n is not blended by coverage here: it comes from the distances below, every voxel's. The
  // composite makes the fields that are (σa, emission, …) and the materials' volumes.
  CompositeOptions blended = options;
  blended.ior = false;
  Volume volume = compositeRegions(regions, grid, blended);
  release(&Region::coverage);  // read by compositing only (a region's `ior` says it is graded: kept)

  // Slot distances: the union (min) of their regions, one per slot (docs/volume-format.md).
  const std::size_t stride = static_cast<std::size_t>(std::max(slot_count, 1));
  Field& interfaces = volume.addField("interfaces", static_cast<int>(stride));
  std::fill(interfaces.data.begin(), interfaces.data.end(), static_cast<float>(band));
  std::vector<int> graded_region_of_slot(static_cast<std::size_t>(std::max(slot_count, 0)), -1);
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const int k = slots.slot_of_region[i];
    if (k < 0) continue;
    if (graded(regions[i])) graded_region_of_slot[static_cast<std::size_t>(k)] = static_cast<int>(i);
    const std::vector<float>& d = regions[i].distance;
    for (std::size_t v = 0; v < count; ++v) {
      float& slot = interfaces.data[stride * v + static_cast<std::size_t>(k)];
      slot = std::min(slot, d[v]);
    }
  }
  release(&Region::distance);

  // n, B and the material label at the voxel centres (`ior` made once the distances are released,
  // whose memory it then takes: the 128³ sphere touches two grids of floats here, not four).
  Field& ior = volume.addField("ior", 1);
  const bool any_dispersion = std::any_of(slots.table.slots.begin(), slots.table.slots.end(),
                                          [](const InterfaceSlot& s) { return s.dispersion_b != 0.0; });
  Field* dispersion = nullptr;
  if (any_dispersion || volume.has("dispersion")) {
    dispersion = &volume.addField("dispersion", 1);
  }
  const float band_f = static_cast<float>(band);
  parallelFor(0, static_cast<std::int64_t>(count), [&](std::int64_t vv) {
    const std::size_t v = static_cast<std::size_t>(vv);
    const float* d = &interfaces.data[stride * v];
    int label = -1;
    for (int k = 0; k < slot_count; ++k)
      if (d[k] < 0.0f) {
        label = k;
        break;
      }
    float n = 1.0f, b = 0.0f;
    if (label >= 0) {
      const InterfaceSlot& s = slots.table.slots[static_cast<std::size_t>(label)];
      n = static_cast<float>(s.ior);
      b = static_cast<float>(s.dispersion_b);
    }
    // A graded material's own n inside it, and continued over the band around it where the
    // neighbouring material is homogeneous (which uses its constant n, not this field).
    for (int k = 0; k < slot_count; ++k) {
      const int r = graded_region_of_slot[static_cast<std::size_t>(k)];
      if (r < 0) continue;
      const bool inside = label == k;
      const bool beside = label < 0 || !slots.table.slots[static_cast<std::size_t>(label)].graded;
      if (inside || (beside && d[k] < band_f)) {
        n = regions[static_cast<std::size_t>(r)].ior_at_center[v];
        break;
      }
    }
    ior.data[v] = n;
    if (dispersion) dispersion->data[v] = b;
  }, 4096);

  // ∇n: central differences of n where all three axes' neighbours carry the same graded n (inside
  // a graded material or on its continuation), one-sided next to a homogeneous voxel; 0 in the
  // homogeneous materials and air. With slots none of which is graded it is 0 throughout and left
  // out (core/interfaces.h constantSlots: at 132³ 28 MB that nothing reads); without slots (only
  // n = 1 objects) there is no table to say so, and the zero field is written.
  const bool any_graded = std::any_of(graded_region_of_slot.begin(), graded_region_of_slot.end(), [](int r) { return r >= 0; });
  if (any_graded) addGradedGradient(volume, grid, stride, slot_count, graded_region_of_slot, band_f);
  else if (slot_count == 0) volume.addField("ior_grad", 3);

  if (slot_count > 0) {
    volume.metadata["interfaces"] = slots.table.toJson();
  } else {
    // Nothing needs an interface (only n = 1 objects, such as smoke): no table and no field, since
    // a table of no slots is not a valid volume (core/interfaces.h) and n is 1 everywhere.
    volume.fields.erase("interfaces");
  }
  volume.metadata["ior_smoothing_sigma_voxels"] = 0.0;
  volume.metadata["ior_gradient"] = slot_count > 0 && !any_graded ? "left out: no graded material (sharp interfaces)"
                                                                   : "graded materials only (sharp interfaces)";
  return volume;
}

}  // namespace

Volume buildSharpVolume(const std::vector<Region>& regions, const GridSpec& grid, double band,
                        const CompositeOptions& options) {
  return buildSharp(regions, nullptr, grid, band, options);
}

Volume buildSharpVolume(std::vector<Region>&& regions, const GridSpec& grid, double band, const CompositeOptions& options) {
  return buildSharp(regions, &regions, grid, band, options);
}

}  // namespace eik
