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
