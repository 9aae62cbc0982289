// The parameters of a procedural shape: the spec as written (`procedural:NAME[,key=value...]`,
// docs/programs.md), the schema of each shape's keys (kind, default, range, meaning), and their
// validation against it. The shapes themselves are in procedural_shapes.cpp.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "voxelize/material.h"
#include "voxelize/material_spec.h"

namespace eik {

constexpr const char* kProceduralPrefix = "procedural:";

struct ProceduralSpec {
  std::string name;                           // shape name, e.g. "sphere"
  std::map<std::string, std::string> params;  // key -> value text as given (validated on use)

  // "procedural:NAME[,key=value...]", for messages.
  std::string text() const;
};

enum class ParamKind { Number, Triple, Choice };

// One key of a shape: a number, an X:Y:Z triple (each component range-checked) or one of a list of
// words.
struct ParamDef {
  std::string key;
  ParamKind kind = ParamKind::Number;
  std::string default_value;  // empty: optional, unset by default
  double lo = -1e300, hi = 1e300;
  bool lo_open = false, hi_open = false;
  std::vector<std::string> choices;
  std::string meaning;
};

// A number in [lo, hi] ((lo, hi] when lo_open).
ParamDef numberParam(std::string key, std::string def, double lo, double hi, bool lo_open, std::string meaning);
// A number > 0.
ParamDef positiveParam(std::string key, std::string def, std::string meaning);
// A refractive index, >= 1.
ParamDef iorParam(std::string key, std::string def, std::string meaning);
// X:Y:Z (or one value for all three), each >= lo (> lo when lo_open).
ParamDef tripleParam(std::string key, std::string def, double lo, bool lo_open, std::string meaning);
// One of `choices`.
ParamDef choiceParam(std::string key, std::string def, std::vector<std::string> choices, std::string meaning);
// center=X:Y:Z, the shift every shape takes.
ParamDef centerParam();

// A shape's validated parameters: the spec's keys checked against the shape's schema `defs` (and
// `material_keys`, the material_spec.h keys the shape also accepts), defaults filled in.
class ShapeParams {
 public:
  // Throws InputError "procedural:NAME: KEY: what" for an unknown key (listing the valid keys), a
  // value that is not a number or out of range, or a bad material key.
  ShapeParams(const std::string& shape_name, const std::vector<ParamDef>& defs,
              const std::vector<std::string>& material_keys, const ProceduralSpec& spec);

  double number(const std::string& key) const;
  glm::dvec3 vec(const std::string& key) const;
  std::string text(const std::string& key) const { return values_.at(key); }
  // Whether the shape takes `key` (given or defaulted).
  bool has(const std::string& key) const { return values_.count(key) > 0; }
  // Whether the user gave `key` (a shape key or a material key).
  bool given(const std::string& key) const;
  // The Cauchy B for index n if the user gave `abbe`, else `fallback` (for shapes whose n is not the
  // material key's).
  float dispersionFor(double n, float fallback) const;
  // `base` with the material keys the user gave applied.
  Material material(Material base) const { return applyMaterialOverrides(material_pairs_, std::move(base), source_); }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  std::string source_;
  std::map<std::string, std::string> values_;  // shape keys, defaults filled in
  std::map<std::string, std::string> given_;
  std::vector<KeyValue> material_pairs_;
  std::map<std::string, const ParamDef*> defs_;
};

}  // namespace eik
