#include "voxelize/grid_builder.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "voxelize/material_spec.h"

namespace eik {
namespace {

std::string str(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

int checkedDim(double voxels, const char* axis, const std::string& source) {
  if (!(voxels <= static_cast<double>(kMaxGridDim)))
    throw InputError(source, "", std::string("the grid would need ") + str(std::ceil(voxels)) + " voxels along " +
                                     axis + " (at most " + std::to_string(kMaxGridDim) + ")");
  return std::max(1, static_cast<int>(voxels));
}

}  // namespace

GridSpec makeGrid(const Bounds& objects, int res, double pad_voxels, const std::optional<Bounds>& explicit_bounds) {
  if (res < 1) throw InputError("--res", "", std::to_string(res) + " must be at least 1");
  if (res > kMaxGridDim)
    throw InputError("--res", "", std::to_string(res) + " exceeds the largest grid dimension " + std::to_string(kMaxGridDim));
  const char* axes[3] = {"x", "y", "z"};
  GridSpec grid;

  if (explicit_bounds) {
    const Bounds& b = *explicit_bounds;
    for (int a = 0; a < 3; ++a)
      if (!(b.max[a] > b.min[a]) || !std::isfinite(b.min[a]) || !std::isfinite(b.max[a]))
        throw InputError("--bounds", axes[a], "max " + str(b.max[a]) + " must be greater than min " + str(b.min[a]));
    const glm::dvec3 ext = b.max - b.min;
    const double h = std::max({ext.x, ext.y, ext.z}) / res;
    for (int a = 0; a < 3; ++a) grid.dims[a] = checkedDim(std::round(ext[a] / h), axes[a], "--bounds");
    grid.bounds_min = b.min;
    grid.bounds_max = b.max;
    return grid;
  }

  if (!(pad_voxels >= 0.0) || !std::isfinite(pad_voxels))
    throw InputError("--pad", "", str(pad_voxels) + " must be a number of voxels >= 0");
  if (objects.empty()) throw InputError("voxelize", "bounds", "the inputs contain no geometry");
  const glm::dvec3 ext = objects.extent();
  const double longest = std::max({ext.x, ext.y, ext.z});
  if (!(longest > 0.0) || !std::isfinite(longest))
    throw InputError("voxelize", "bounds", "the inputs have no extent (a single point); give --bounds");
  const double h = longest / res;
  if (pad_voxels > kMaxGridDim)
    throw InputError("--pad", "", str(pad_voxels) + " voxels of air exceed the largest grid dimension " +
                                      std::to_string(kMaxGridDim));
  const int pad = static_cast<int>(std::ceil(pad_voxels - 1e-9));
  for (int a = 0; a < 3; ++a) {
    // The longest axis gets exactly `res` voxels; the tolerance keeps 1.0000000001 from becoming 2.
    const double span = std::max(1.0, std::ceil(ext[a] / h - 1e-6));
    grid.dims[a] = checkedDim(span + 2.0 * pad, axes[a], span <= kMaxGridDim ? "--pad" : "--res");
  }
  const glm::dvec3 half = 0.5 * h * glm::dvec3(grid.dims);
  grid.bounds_min = objects.center() - half;
  grid.bounds_max = objects.center() + half;
  return grid;
}

Bounds parseBounds(const std::string& text, const std::string& source) {
  std::vector<double> v;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    v.push_back(parseNumber(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start), source,
                            "value " + std::to_string(v.size() + 1)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != 6)
    throw InputError(source, "", "'" + text + "' must be six numbers MINX,MINY,MINZ,MAXX,MAXY,MAXZ");
  Bounds b;
  b.min = {v[0], v[1], v[2]};
  b.max = {v[3], v[4], v[5]};
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a)
    if (!(b.max[a] > b.min[a]))
      throw InputError(source, axes[a], "max " + str(b.max[a]) + " must be greater than min " + str(b.min[a]));
  return b;
}

}  // namespace eik
