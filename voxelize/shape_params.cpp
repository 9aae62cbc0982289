#include "voxelize/shape_params.h"

#include <algorithm>
#include <utility>

#include "core/error.h"

namespace eik {

std::string ProceduralSpec::text() const {
  std::string out = kProceduralPrefix + name;
  for (const auto& [key, value] : params) out += "," + key + "=" + value;
  return out;
}

ParamDef numberParam(std::string key, std::string def, double lo, double hi, bool lo_open, std::string meaning) {
  ParamDef p;
  p.key = std::move(key);
  p.default_value = std::move(def);
  p.lo = lo;
  p.hi = hi;
  p.lo_open = lo_open;
  p.meaning = std::move(meaning);
  return p;
}
ParamDef positiveParam(std::string key, std::string def, std::string meaning) {
  return numberParam(std::move(key), std::move(def), 0.0, 1e300, true, std::move(meaning));
}
ParamDef iorParam(std::string key, std::string def, std::string meaning) {
  return numberParam(std::move(key), std::move(def), 1.0, 1e300, false, std::move(meaning));
}
ParamDef tripleParam(std::string key, std::string def, double lo, bool lo_open, std::string meaning) {
  ParamDef p = numberParam(std::move(key), std::move(def), lo, 1e300, lo_open, std::move(meaning));
  p.kind = ParamKind::Triple;
  return p;
}
ParamDef choiceParam(std::string key, std::string def, std::vector<std::string> choices, std::string meaning) {
  ParamDef p;
  p.key = std::move(key);
  p.kind = ParamKind::Choice;
  p.default_value = std::move(def);
  p.choices = std::move(choices);
  p.meaning = std::move(meaning);
  return p;
}
ParamDef centerParam() { return tripleParam("center", "0:0:0", -1e300, false, "centre of the object (X:Y:Z)"); }

double ShapeParams::number(const std::string& key) const {
  return parseNumber(values_.at(key), source_, key);
}
glm::dvec3 ShapeParams::vec(const std::string& key) const { return parseTriple(values_.at(key), source_, key); }

bool ShapeParams::given(const std::string& key) const {
  return given_.count(key) != 0 || std::any_of(material_pairs_.begin(), material_pairs_.end(),
                                               [&](const KeyValue& kv) { return kv.first == key; });
}

float ShapeParams::dispersionFor(double n, float fallback) const {
  for (const auto& [key, value] : material_pairs_)
    if (key == "abbe") return cauchyBFromAbbe(static_cast<float>(n), static_cast<float>(parseNumber(value, source_, key)));
  return fallback;
}

void ShapeParams::fail(const std::string& key, const std::string& what) const { throw InputError(source_, key, what); }

ShapeParams::ShapeParams(const std::string& shape_name, const std::vector<ParamDef>& defs,
                         const std::vector<std::string>& material_keys, const ProceduralSpec& spec)
    : source_(kProceduralPrefix + spec.name) {
  for (const auto& def : defs) {
    defs_[def.key] = &def;
    if (!def.default_value.empty()) values_[def.key] = def.default_value;
  }
  for (const auto& [key, value] : spec.params) {
    const bool material_key = std::find(material_keys.begin(), material_keys.end(), key) != material_keys.end();
    if (material_key) {
      material_pairs_.emplace_back(key, value);
      continue;
    }
    auto it = defs_.find(key);
    if (it == defs_.end()) {
      std::vector<std::string> valid;
      for (const auto& def : defs) valid.push_back(def.key);
      for (const auto& k : material_keys) valid.push_back(k);
      const std::string what = isMaterialKey(key) ? "material key not accepted by shape '" + shape_name + "'"
                                                  : "unknown key for shape '" + shape_name + "'";
      fail(key, what + " (valid keys: " + joinedList(valid) + ")");
    }
    const ParamDef& def = *it->second;
    if (def.kind == ParamKind::Choice) {
      if (std::find(def.choices.begin(), def.choices.end(), value) == def.choices.end())
        fail(key, "'" + value + "' is not one of " + joinedList(def.choices));
    } else {
      auto check = [&, &key = key](double v) {  // a structured binding named for clang 14 (fuzz builds)
        const bool below = def.lo_open ? !(v > def.lo) : !(v >= def.lo);
        const bool above = def.hi_open ? !(v < def.hi) : !(v <= def.hi);
        if (below || above) {
          std::string range;
          if (def.hi >= 1e300)
            range = std::string("must be ") + (def.lo_open ? "> " : ">= ") + formatValue(def.lo);
          else
            range = std::string("must lie in ") + (def.lo_open ? "(" : "[") + formatValue(def.lo) + ", " +
                    formatValue(def.hi) + (def.hi_open ? ")" : "]");
          fail(key, formatValue(v) + " is out of range: " + range);
        }
      };
      if (def.kind == ParamKind::Number) {
        check(parseNumber(value, source_, key));
      } else {
        const glm::dvec3 v = parseTriple(value, source_, key);
        check(v.x);
        check(v.y);
        check(v.z);
      }
    }
    values_[key] = value;
    given_[key] = value;
  }
  // Validate the material keys now, so errors surface at parse time.
  (void)material(Material{});
}

}  // namespace eik
