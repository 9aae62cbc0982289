#include "voxelize/material_spec.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/limits.h"
#include "core/text.h"

namespace eik {

std::string formatValue(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string joinedList(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

std::vector<KeyValue> splitKeyValues(const std::string& spec, const std::string& source) {
  std::vector<KeyValue> pairs;
  std::set<std::string> seen;
  if (trim(spec).empty()) return pairs;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = spec.find(',', start);
    const std::string item(
        trim(std::string_view(spec).substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos)
      throw InputError(source, item.empty() ? "(empty item)" : item,
                       "expected KEY=VALUE (items are separated by commas)");
    std::string key(trim(std::string_view(item).substr(0, eq)));
    std::string value(trim(std::string_view(item).substr(eq + 1)));
    if (key.empty()) throw InputError(source, item, "missing key before '='");
    if (!seen.insert(key).second) throw InputError(source, key, "given more than once");
    pairs.emplace_back(std::move(key), std::move(value));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return pairs;
}

double parseNumber(const std::string& text, const std::string& source, const std::string& key) {
  const std::string t(trim(text));
  double value = 0.0;
  const char* first = t.data();
  const char* last = t.data() + t.size();
  if (!t.empty() && *first == '+') ++first;  // from_chars does not take a leading '+'
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (t.empty() || ec != std::errc() || ptr != last || !std::isfinite(value))
    throw InputError(source, key, "'" + text + "' is not a number");
  if (!finiteAsFloat(value))
    throw InputError(source, key, "'" + text + "' is beyond the range of a 32-bit float (the fields store floats)");
  return value;
}

glm::dvec3 parseTriple(const std::string& text, const std::string& source, const std::string& key) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const std::size_t colon = text.find(':', start);
    parts.push_back(text.substr(start, colon == std::string::npos ? std::string::npos : colon - start));
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  if (parts.size() == 1) return glm::dvec3(parseNumber(parts[0], source, key));
  if (parts.size() != 3)
    throw InputError(source, key, "'" + text + "' must be R:G:B (three numbers separated by ':') or one number");
  return {parseNumber(parts[0], source, key), parseNumber(parts[1], source, key), parseNumber(parts[2], source, key)};
}

const std::vector<std::string>& materialKeys() {
  static const std::vector<std::string> keys = {"ior", "n", "sigma_a", "emission", "albedo",
                                                "scatter", "g", "abbe", "name"};
  return keys;
}

bool isMaterialKey(std::string_view key) {
  const auto& keys = materialKeys();
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

Material applyMaterialOverrides(const std::vector<KeyValue>& pairs, Material base, const std::string& source) {
  std::optional<double> abbe;
  bool have_ior = false;
  for (const auto& [key, value] : pairs) {
    auto fail = [&, &key = key](const std::string& what) { throw InputError(source, key, what); };
    auto rgbAtLeastZero = [&, &key = key, &value = value] {
      const glm::dvec3 v = parseTriple(value, source, key);
      if (v.x < 0.0 || v.y < 0.0 || v.z < 0.0) fail("'" + value + "' must not be negative");
      return glm::vec3(v);
    };
    if (key == "ior" || key == "n") {
      if (have_ior) fail("ior and n are the same key; give one");
      have_ior = true;
      const double n = parseNumber(value, source, key);
      if (n < 1.0) fail(formatValue(n) + " is below 1 (a refractive index is at least 1, vacuum)");
      base.ior = static_cast<float>(n);
    } else if (key == "sigma_a") {
      base.sigma_a = rgbAtLeastZero();
    } else if (key == "emission") {
      base.emission = rgbAtLeastZero();
    } else if (key == "albedo") {
      const glm::vec3 a = rgbAtLeastZero();
      if (a.x > 1.0f || a.y > 1.0f || a.z > 1.0f) fail("'" + value + "' must lie in [0, 1]");
      base.albedo = a;
      base.opaque = true;
    } else if (key == "scatter") {
      const double w = parseNumber(value, source, key);
      if (w < 0.0 || w > 1.0) fail(formatValue(w) + " is outside [0, 1]");
      base.scatter = static_cast<float>(w);
    } else if (key == "g") {
      const double g = parseNumber(value, source, key);
      if (g <= -1.0 || g >= 1.0) fail(formatValue(g) + " is outside (-1, 1)");
      base.g = static_cast<float>(g);
    } else if (key == "abbe") {
      const double v = parseNumber(value, source, key);
      if (v <= 0.0) fail(formatValue(v) + " must be positive (glasses have Abbe numbers of about 20 to 90)");
      abbe = v;
    } else if (key == "name") {
      if (value.empty()) fail("must not be empty");
      base.name = value;
    } else {
      fail("unknown material key (valid keys: " + joinedList(materialKeys()) + ")");
    }
  }
  // docs/volume-format.md: B = 0.523655·(n − 1)/V_d, with the final n.
  if (abbe) base.dispersion_b = cauchyBFromAbbe(base.ior, static_cast<float>(*abbe));
  return base;
}

Material parseMaterialSpec(const std::string& spec, Material base, const std::string& source) {
  const auto pairs = splitKeyValues(spec, source);
  if (pairs.empty()) throw InputError(source, "", "empty material spec (expected KEY=VALUE[,KEY=VALUE...])");
  return applyMaterialOverrides(pairs, std::move(base), source);
}

}  // namespace eik
