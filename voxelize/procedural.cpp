#include "voxelize/procedural.h"

#include <utility>

#include "core/error.h"
#include "voxelize/material_spec.h"
#include "voxelize/procedural_shapes.h"

namespace eik {

const std::vector<ProceduralShapeInfo>& proceduralShapes() {
  static const std::vector<ProceduralShapeInfo> infos = [] {
    std::vector<ProceduralShapeInfo> out;
    for (const auto& def : shapeDefs()) {
      ProceduralShapeInfo info;
      info.name = def.name;
      info.description = def.description;
      for (const auto& p : def.params)
        info.params.push_back({p.key, p.default_value.empty() ? "(unset)" : p.default_value,
                               p.meaning + (p.kind == ParamKind::Choice ? " [" + joinedList(p.choices) + "]" : "")});
      info.material_keys = def.material_keys;
      info.regions = def.regions;
      out.push_back(std::move(info));
    }
    return out;
  }();
  return infos;
}

bool isProceduralSpec(const std::string& input) { return input.rfind(kProceduralPrefix, 0) == 0; }

ProceduralSpec parseProceduralSpec(const std::string& text) {
  std::string body = isProceduralSpec(text) ? text.substr(std::string(kProceduralPrefix).size()) : text;
  ProceduralSpec spec;
  const std::size_t comma = body.find(',');
  spec.name = body.substr(0, comma);
  while (!spec.name.empty() && spec.name.back() == ' ') spec.name.pop_back();
  if (spec.name.empty()) {
    throw InputError(text.empty() ? std::string(kProceduralPrefix) : text, "",
                     "missing shape name (valid shapes: " + shapeNames() + ")");
  }
  const ShapeDef& shape = findShape(spec.name, kProceduralPrefix + spec.name);
  if (comma != std::string::npos)
    for (auto& [key, value] : splitKeyValues(body.substr(comma + 1), kProceduralPrefix + spec.name))
      spec.params[key] = value;
  const ShapeParams validate(shape.name, shape.params, shape.material_keys, spec);  // throws on unknown keys and bad values
  (void)shape.build(validate, 0.0);  // and on inconsistent combinations (e.g. radius > size/2)
  return spec;
}

Bounds proceduralBounds(const ProceduralSpec& spec) {
  Bounds b;
  for (const auto& s : buildShapeSolids(spec, 0.0)) b.extend(s.bounds);
  return b;
}

std::vector<ImplicitSolid> proceduralSolids(const ProceduralSpec& spec, const GridSpec& grid) {
  return buildShapeSolids(spec, grid.voxelSize().y);
}

std::vector<Region> voxelizeProcedural(const ProceduralSpec& spec, const GridSpec& grid,
                                       const ProceduralOptions& options, const ProgressFn& progress) {
  const auto solids = proceduralSolids(spec, grid);
  std::vector<Region> regions;
  regions.reserve(solids.size());
  const double n = static_cast<double>(solids.size());
  for (std::size_t i = 0; i < solids.size(); ++i) {
    ProgressFn part;
    if (progress) part = [&progress, i, n](double f) { progress((static_cast<double>(i) + f) / n); };
    regions.push_back(voxelizeImplicit(solids[i], grid, options, part));
  }
  return regions;
}

}  // namespace eik
