// Choosing the voxel grid for a set of objects: `--res`, `--pad` and `--bounds` of `voxelize`
// (docs/programs.md).
#pragma once

#include <limits>
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "core/limits.h"

namespace eik {

// An axis-aligned box in world space. Default-constructed it is empty (min > max) and grows with
// extend().
struct Bounds {
  glm::dvec3 min{std::numeric_limits<double>::infinity()};
  glm::dvec3 max{-std::numeric_limits<double>::infinity()};

  bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  glm::dvec3 extent() const { return empty() ? glm::dvec3(0.0) : max - min; }
  glm::dvec3 center() const { return 0.5 * (min + max); }
  void extend(const glm::dvec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void extend(const Bounds& b) {
    if (b.empty()) return;
    extend(b.min);
    extend(b.max);
  }
  bool contains(const Bounds& b, double tolerance = 0.0) const {
    return glm::all(glm::lessThanEqual(min - tolerance, b.min)) && glm::all(glm::lessThanEqual(b.max, max + tolerance));
  }
};

// Air added around the objects by default, in voxels on every side. The Gaussian pre-smoothing of
// n (σ = 0.75 voxel by default, thesis §3.1) spreads a surface over about ±3σ ≈ ±2.3 voxels; with
// 3 voxels of air the outermost voxel centres lie at least 2.5 voxels (3.3σ) from any surface, so
// the smoothed n there is within 4·10⁻⁴·(n − 1) of air. Rays therefore enter and leave the grid in
// air and the boundary layer lies wholly inside the grid (central differences need one more voxel
// on each side). With 2 voxels the border would still hold about 2 % of the index step.
constexpr double kDefaultPadVoxels = 3.0;
// Largest grid dimension makeGrid accepts: what the volume writer and every reader accept
// (core/limits.h), so a grid too large fails before any work.
constexpr int kMaxGridDim = kMaxVolumeAxis;

// Grid for objects spanning `objects`:
//  - without explicit bounds: cubic voxels of size h = (longest extent of `objects`) / res, the
//    longest axis spanned by exactly `res` voxels and the others by ceil(extent/h) voxels (at least
//    one), then `pad_voxels` voxels of air added on every side (rounded up to whole voxels), centred
//    on the objects. A sphere at --res 128 --pad 3 gives 134³.
//  - with explicit bounds: those bounds exactly; h = (longest extent) / res, and each other axis gets
//    round(extent/h) voxels (at least one), so voxels are cubic when the extents are multiples of
//    h and as close to cubic as the bounds allow otherwise. No padding is added.
// Throws InputError naming --res, --pad or --bounds for res < 1, pad < 0, an inverted or flat
// explicit box, empty objects or a grid larger than kMaxGridDim along an axis.
GridSpec makeGrid(const Bounds& objects, int res_longest_axis, double pad_voxels = kDefaultPadVoxels,
                  const std::optional<Bounds>& explicit_bounds = std::nullopt);

// Parses "MINX,MINY,MINZ,MAXX,MAXY,MAXZ" (the --bounds value); errors name `source`.
Bounds parseBounds(const std::string& text, const std::string& source = "--bounds");

}  // namespace eik
