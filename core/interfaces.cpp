#include "core/interfaces.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/error.h"
#include "core/parallel.h"

namespace eik {

nlohmann::json InterfaceTable::toJson() const {
  nlohmann::json slots_json = nlohmann::json::array();
  for (const InterfaceSlot& s : slots) {
    nlohmann::json slot = {{"name", s.name},
                           {"ior", s.ior},
                           {"dispersion_b", s.dispersion_b},
                           {"graded", s.graded},
                           {"opaque", s.opaque}};
    if (s.sigma_a) slot["sigma_a"] = {s.sigma_a->x, s.sigma_a->y, s.sigma_a->z};
    slots_json.push_back(slot);
  }
  return {{"band", band}, {"slots", slots_json}};
}

namespace {

double finiteNumber(const nlohmann::json& j, const std::string& source, const std::string& key) {
  if (!j.is_number()) throw InputError(source, key, "expected a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) throw InputError(source, key, "must be finite");
  return v;
}

bool boolean(const nlohmann::json& j, const std::string& source, const std::string& key) {
  if (!j.is_boolean()) throw InputError(source, key, "expected true or false");
  return j.get<bool>();
}

}  // namespace

MaterialValues deepMaterialValues(const Volume& volume, const InterfaceTable& table, const Field& field, double depth,
                                  bool with_air) {
  const int slots = static_cast<int>(table.slots.size());
  const std::size_t media = static_cast<std::size_t>(slots) + 1;
  MaterialValues result;
  result.seen.assign(media, false);
  result.value.assign(media, glm::dvec3(0.0));
  const Field* interfaces = volume.find("interfaces");
  if (!interfaces || slots == 0) return result;
  const int components = std::min(field.components, 3);
  // In chunks of voxels in parallel, each with its own first values, merged in order.
  constexpr std::size_t kChunk = 1 << 16;
  const std::size_t count = volume.grid.count();
  std::vector<MaterialValues> chunks((count + kChunk - 1) / kChunk, result);
  auto differ = [](const glm::dvec3& a, const glm::dvec3& b) {
    for (int c = 0; c < 3; ++c)
      if (std::abs(a[c] - b[c]) > 1e-6 * (1.0 + std::abs(b[c]))) return true;
    return false;
  };
  parallelFor(0, static_cast<std::int64_t>(chunks.size()), [&](std::int64_t chunk) {
    MaterialValues& part = chunks[static_cast<std::size_t>(chunk)];
    const std::size_t begin = static_cast<std::size_t>(chunk) * kChunk, end = std::min(count, begin + kChunk);
    for (std::size_t v = begin; v < end && part.one_value; ++v) {
      const float* d = interfaces->voxel(v);
      glm::dvec4 distances(1e30);
      bool deep = true;
      for (int k = 0; k < slots; ++k) {
        distances[k] = d[k];
        deep = deep && std::abs(d[k]) >= depth;
      }
      if (!deep) continue;
      const int slot = materialSlot(distances, slots);
      if (slot >= 0 && table.slots[static_cast<std::size_t>(slot)].opaque) continue;
      if (slot < 0 && !with_air) continue;
      const std::size_t m = static_cast<std::size_t>(slot + 1);
      glm::dvec3 x(0.0);
      for (int c = 0; c < components; ++c) x[c] = field.voxel(v)[c];
      if (!part.seen[m]) {
        part.seen[m] = true;
        part.value[m] = x;
      } else if (differ(x, part.value[m])) {
        part.one_value = false;
      }
    }
  });
  for (const MaterialValues& part : chunks) {
    result.one_value = result.one_value && part.one_value;
    for (std::size_t m = 0; m < media && result.one_value; ++m) {
      if (!part.seen[m]) continue;
      if (result.seen[m] && differ(part.value[m], result.value[m])) result.one_value = false;
      result.seen[m] = true;
      result.value[m] = part.value[m];
    }
  }
  return result;
}

std::optional<AirMedium> airMediumBox(const Volume& volume, const InterfaceTable& table, double depth) {
  const Field* interfaces = volume.find("interfaces");
  const Field* sigma = volume.find("sigma_a");
  const Field* scatter = volume.find("scatter");
  const int slots = static_cast<int>(table.slots.size());
  if (!interfaces || slots == 0 || (!sigma && !scatter)) return std::nullopt;
  const GridSpec& grid = volume.grid;
  const glm::ivec3 dims = grid.dims;
  auto deepAir = [&](std::size_t v) {
    const float* d = interfaces->voxel(v);
    glm::dvec4 distances(1e30);
    for (int k = 0; k < slots; ++k) {
      if (std::abs(d[k]) < depth) return false;
      distances[k] = d[k];
    }
    return materialSlot(distances, slots) < 0;
  };
  // What blends by coverage: σa (rgb) and ω̂ (a); g is the smoke's wherever ω̂ is not 0.
  auto valueAt = [&](std::size_t v) {
    glm::dvec4 x(0.0);
    if (sigma)
      for (int c = 0; c < 3; ++c) x[c] = sigma->voxel(v)[c];
    if (scatter) x.w = scatter->voxel(v)[0];
    return x;
  };
  auto gAt = [&](std::size_t v) { return scatter && scatter->components > 1 ? double(scatter->voxel(v)[1]) : 0.0; };
  // The box of the deep air voxels that are not 0, z-slices in parallel.
  std::vector<glm::ivec3> slice_min(static_cast<std::size_t>(dims.z), dims), slice_max(static_cast<std::size_t>(dims.z), glm::ivec3(-1));
  parallelFor(0, dims.z, [&](std::int64_t z64) {
    const int z = static_cast<int>(z64);
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) {
        const std::size_t v = grid.index(x, y, z);
        if (valueAt(v) == glm::dvec4(0.0) || !deepAir(v)) continue;
        slice_min[static_cast<std::size_t>(z)] = glm::min(slice_min[static_cast<std::size_t>(z)], glm::ivec3(x, y, z));
        slice_max[static_cast<std::size_t>(z)] = glm::max(slice_max[static_cast<std::size_t>(z)], glm::ivec3(x, y, z));
      }
  });
  glm::ivec3 lo(dims), hi(-1);
  for (std::size_t z = 0; z < slice_min.size(); ++z) {
    lo = glm::min(lo, slice_min[z]);
    hi = glm::max(hi, slice_max[z]);
  }
  if (hi.x < 0 || glm::any(glm::lessThan(hi - lo, glm::ivec3(2)))) return std::nullopt;  // none, or no inside
  // The one value inside (every deep air voxel off the box's faces' layer).
  auto inner = [&](int x, int y, int z) { return x > lo.x && x < hi.x && y > lo.y && y < hi.y && z > lo.z && z < hi.z; };
  auto differ = [](double a, double b) { return std::abs(a - b) > 1e-6 * (1.0 + std::abs(b)); };
  bool one = true, seen = false;
  glm::dvec4 c(0.0);
  double g = 0.0;
  for (int z = lo.z + 1; z < hi.z && one; ++z)
    for (int y = lo.y + 1; y < hi.y && one; ++y)
      for (int x = lo.x + 1; x < hi.x && one; ++x) {
        const std::size_t v = grid.index(x, y, z);
        if (!deepAir(v)) continue;
        const glm::dvec4 value = valueAt(v);
        if (!seen) {
          seen = true;
          c = value;
          g = gAt(v);
        }
        for (int k = 0; k < 4; ++k) one = one && !differ(value[k], c[k]);
        one = one && (c.w == 0.0 || !differ(gAt(v), g));
      }
  if (!one || !seen || c == glm::dvec4(0.0)) return std::nullopt;
  // Each face layer's voxels: the share f of the inside value they hold (by the largest component).
  int dominant = 0;
  for (int k = 1; k < 4; ++k)
    if (c[k] > c[dominant]) dominant = k;
  auto share = [&](std::size_t v) { return valueAt(v)[dominant] / c[dominant]; };
  auto proportional = [&](std::size_t v, double f) {
    const glm::dvec4 value = valueAt(v);
    for (int k = 0; k < 4; ++k)
      if (std::abs(value[k] - f * c[k]) > 1e-5 * (1.0 + std::abs(c[k]))) return false;
    return value.w == 0.0 || !differ(gAt(v), g);
  };
  // A face's share from its voxels off the box's edges.
  glm::dvec3 share_lo(0.0), share_hi(0.0);
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      double sum = 0.0;
      int count = 0;
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      for (int i = lo[a] + 1; i < hi[a]; ++i)
        for (int j = lo[b] + 1; j < hi[b]; ++j) {
          glm::ivec3 p;
          p[axis] = side ? hi[axis] : lo[axis];
          p[a] = i;
          p[b] = j;
          const std::size_t v = grid.index(p.x, p.y, p.z);
          if (!deepAir(v)) continue;
          sum += share(v);
          ++count;
        }
      if (count == 0) return std::nullopt;
      (side ? share_hi : share_lo)[axis] = sum / count;
    }
  // Every voxel of the faces' layer holds the product of its faces' shares (coverage of an
  // axis-aligned box; 0.02: the voxelizer's supersampled coverage is quantised) times the value.
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) {
        if (inner(x, y, z)) continue;
        const std::size_t v = grid.index(x, y, z);
        if (!deepAir(v)) continue;
        const glm::ivec3 p(x, y, z);
        double expected = 1.0;
        for (int axis = 0; axis < 3; ++axis)
          expected *= p[axis] == lo[axis] ? share_lo[axis] : p[axis] == hi[axis] ? share_hi[axis] : 1.0;
        const double f = share(v);
        if (std::abs(f - expected) > 0.02 || !proportional(v, f)) return std::nullopt;
      }
  AirMedium box;
  const glm::dvec3 voxel = grid.voxelSize();
  box.lo = grid.bounds_min + (glm::dvec3(lo) + 1.0 - share_lo) * voxel;
  box.hi = grid.bounds_min + (glm::dvec3(hi) + share_hi) * voxel;
  box.sigma_a = glm::dvec3(c);
  box.scatter = glm::dvec2(c.w, c.w > 0.0 ? g : 0.0);
  return box;
}

double boxShare(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& lo, const glm::dvec3& hi) {
  double enter = 0.0, leave = 1.0;
  for (int k = 0; k < 3; ++k) {
    const double d = b[k] - a[k];
    if (d == 0.0) {
      if (a[k] < lo[k] || a[k] > hi[k]) return 0.0;
      continue;
    }
    const double t0 = (lo[k] - a[k]) / d, t1 = (hi[k] - a[k]) / d;
    enter = std::max(enter, std::min(t0, t1));
    leave = std::min(leave, std::max(t0, t1));
  }
  return std::max(leave - enter, 0.0);
}

InterfaceTable interfaceTable(const Volume& volume, const std::string& source) {
  InterfaceTable table;
  const bool has_field = volume.has("interfaces");
  const bool has_table = volume.metadata.is_object() && volume.metadata.contains("interfaces");
  if (!has_field && !has_table) return table;
  if (has_field && !has_table)
    throw InputError(source, "interfaces", "the volume has an interfaces field but no interfaces table");
  if (!has_field) throw InputError(source, "fields.interfaces", "the manifest lists interfaces but has no such field");
  const int components = volume.find("interfaces")->components;
  const nlohmann::json& j = volume.metadata.at("interfaces");
  if (!j.is_object()) throw InputError(source, "interfaces", "expected an object");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.key() != "band" && it.key() != "slots")
      throw InputError(source, "interfaces." + it.key(), "unknown key (expected one of: band, slots)");
  if (!j.contains("band")) throw InputError(source, "interfaces.band", "missing");
  table.band = finiteNumber(j.at("band"), source, "interfaces.band");
  if (!(table.band > 0.0)) throw InputError(source, "interfaces.band", "must be positive");
  if (!j.contains("slots") || !j.at("slots").is_array())
    throw InputError(source, "interfaces.slots", "expected an array");
  const nlohmann::json& slots = j.at("slots");
  if (slots.empty() || slots.size() > static_cast<std::size_t>(kMaxInterfaceSlots))
    throw InputError(source, "interfaces.slots",
                     "must hold 1 to " + std::to_string(kMaxInterfaceSlots) + " slots, has " +
                         std::to_string(slots.size()));
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const std::string key = "interfaces.slots[" + std::to_string(i) + "]";
    const nlohmann::json& s = slots[i];
    if (!s.is_object()) throw InputError(source, key, "expected an object");
    InterfaceSlot slot;
    for (auto it = s.begin(); it != s.end(); ++it) {
      const std::string k = it.key(), field = key + "." + k;
      if (k == "name") {
        if (!it->is_string()) throw InputError(source, field, "expected a string");
        slot.name = it->get<std::string>();
      } else if (k == "ior") {
        slot.ior = finiteNumber(*it, source, field);
        if (!(slot.ior >= 1.0 && slot.ior <= 10.0)) throw InputError(source, field, "must be in [1, 10]");
      } else if (k == "dispersion_b") {
        slot.dispersion_b = finiteNumber(*it, source, field);
      } else if (k == "graded") {
        slot.graded = boolean(*it, source, field);
      } else if (k == "opaque") {
        slot.opaque = boolean(*it, source, field);
      } else if (k == "sigma_a") {
        if (!it->is_array() || it->size() != 3) throw InputError(source, field, "expected an array of 3 numbers");
        glm::dvec3 sigma;
        for (int c = 0; c < 3; ++c) {
          sigma[c] = finiteNumber((*it)[static_cast<std::size_t>(c)], source, field);
          if (!(sigma[c] >= 0.0)) throw InputError(source, field, "must not be negative");
        }
        slot.sigma_a = sigma;
      } else {
        throw InputError(source, field,
                         "unknown key (expected one of: dispersion_b, graded, ior, name, opaque, sigma_a)");
      }
    }
    table.slots.push_back(slot);
  }
  // One distance per slot, or four (the unused slots' +band: volumes written before).
  if (components != static_cast<int>(table.slots.size()) && components != kMaxInterfaceSlots)
    throw InputError(source, "fields.interfaces",
                     std::to_string(components) + " components for " + std::to_string(table.slots.size()) +
                         " slots (expected one per slot, or " + std::to_string(kMaxInterfaceSlots) + ")");
  return table;
}

Field fourSlotDistances(const Field& interfaces, double band) {
  if (interfaces.components >= kMaxInterfaceSlots) return interfaces;
  Field four;
  four.components = kMaxInterfaceSlots;
  const std::size_t voxels = interfaces.data.size() / static_cast<std::size_t>(interfaces.components);
  four.data.assign(voxels * kMaxInterfaceSlots, static_cast<float>(band));
  for (std::size_t i = 0; i < voxels; ++i) std::copy_n(interfaces.voxel(i), interfaces.components, four.voxel(i));
  return four;
}

bool constantSlots(const InterfaceTable& table) {
  return !table.empty() && std::none_of(table.slots.begin(), table.slots.end(), [](const InterfaceSlot& s) { return s.graded; });
}

const Field* iorGradient(const Volume& volume, const InterfaceTable& table, const std::string& source) {
  if (const auto unread = volume.unread_fields.find("ior_grad"); unread != volume.unread_fields.end()) {
    if (unread->second != 3)
      throw InputError(source, "ior_grad", std::to_string(unread->second) + " components, expected 3");
    return nullptr;
  }
  if (!volume.has("ior_grad") && constantSlots(table)) return nullptr;
  return &volume.require("ior_grad", 3, source);
}

const Field* refractiveIndex(const Volume& volume, const InterfaceTable& table, const std::string& source) {
  if (const auto unread = volume.unread_fields.find("ior"); unread != volume.unread_fields.end()) {
    if (unread->second != 1) throw InputError(source, "ior", std::to_string(unread->second) + " components, expected 1");
    if (constantSlots(table)) return nullptr;
  }
  return &volume.require("ior", 1, source);
}

std::optional<float> unusedSlotDistance(const Field& interfaces, int used, double band) {
  if (used >= interfaces.components)
    return interfaces.components < kMaxInterfaceSlots ? std::optional<float>(static_cast<float>(band)) : std::nullopt;
  if (interfaces.data.empty()) return std::nullopt;
  const std::size_t stride = static_cast<std::size_t>(interfaces.components);
  const std::size_t voxels = interfaces.data.size() / stride;
  const float value = interfaces.data[static_cast<std::size_t>(used)];
  // In chunks of voxels in parallel; each chunk says whether its unused distances are all `value`.
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  const std::size_t chunks = (voxels + kChunk - 1) / kChunk;
  std::vector<std::uint8_t> constant(chunks, 1);
  parallelFor(0, static_cast<std::int64_t>(chunks), [&](std::int64_t c) {
    const std::size_t begin = static_cast<std::size_t>(c) * kChunk, end = std::min(voxels, begin + kChunk);
    bool same = true;
    for (std::size_t i = begin; i < end && same; ++i)
      for (std::size_t k = static_cast<std::size_t>(used); k < stride; ++k) same = same && interfaces.data[i * stride + k] == value;
    constant[static_cast<std::size_t>(c)] = same ? 1 : 0;
  });
  if (!std::all_of(constant.begin(), constant.end(), [](std::uint8_t c) { return c != 0; })) return std::nullopt;
  return value;
}

}  // namespace eik
