// Receivers (ALGORITHM.md "Receivers"; docs/physics.md "Receivers"): a diffuse plane — the scene's
// ground — that stops the light and gets its own map of planar irradiance, finer than the volume.
//
// Where a patch crosses the plane, each corner's ray meets the plane: the four points are the
// patch's footprint, and its flux Φ spreads uniformly over it. A texel gets Φ·(area of footprint ∩
// texel)/(area of footprint): exact, so footprints that tile the plane (a wavefront in free air)
// give every texel its exact irradiance, and the flux is conserved to the last texel. The
// irradiance of a texel is its flux over its area. It is planar irradiance — flux through the
// plane per area — which carries the cos θ of oblique light, unlike the volume's fluence-like
// `irradiance` field.
#pragma once

#include <array>
#include <cassert>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "core/receiver_map.h"
#include "lightsim/simulator.h"

namespace eik {

struct Patch;

// The map's geometry for a bake: the box `box_lo`..`box_hi` seen from the light (projected along a
// directional light, or from a point light) onto the plane — the volume's shadow — grown by its
// own size on every side (for the light the object reflects or bends beyond it), within the square
// of half extent `spec.half_extent` around `spec.point`; texels of spec.pitch_voxels·h (h the
// grid's smallest voxel edge; coarser if the map would exceed kMaxReceiverTexels per axis, the
// NRRD limit). The irradiance is left empty. Throws InputError naming "receiver" when the light
// does not reach the plane from its front (normal) side.
ReceiverMap receiverGeometry(const ReceiverSpec& spec, const LightSpec& light, const GridSpec& grid,
                             const glm::dvec3& box_lo, const glm::dvec3& box_hi);
// One lattice for several lights' runs that are summed (a scene's lights): the union of each
// light's region above, at the same pitch (coarser only to stay within kMaxReceiverTexels).
ReceiverMap receiverGeometry(const ReceiverSpec& spec, const std::vector<LightSpec>& lights, const GridSpec& grid,
                             const glm::dvec3& box_lo, const glm::dvec3& box_hi);
constexpr int kMaxReceiverTexels = 1024;

// Where the rays of a patch's corners (x_c along w_c) meet the plane, in the plane's (u, v)
// coordinates. False when a corner's ray never meets the plane: it runs parallel to it, or it is
// above the plane heading away (the patch is then not received; it goes on, and leaves the box).
bool patchFootprint(const Patch& patch, const ReceiverMap& map, std::array<glm::dvec2, 4>& footprint);

// Adds flux Φ spread uniformly over the quadrilateral `footprint` ((u, v) coordinates) to the
// per-texel flux sums `texel_flux` (W, texelCount() long): split into the triangles (0, 1, 2) and
// (0, 2, 3), each taking Φ·|its area|/(|area 1| + |area 2|) (a fold or twist keeps its flux), each
// clipped exactly against every texel it touches. Flux falling outside the map is dropped.
// Only the texel rows [row_begin, row_end) are written (each row's share is computed the same way
// whatever the range), so that bands of rows can be filled in parallel with the same sums.
void depositFootprint(const ReceiverMap& map, const std::array<glm::dvec2, 4>& footprint, const glm::dvec3& flux,
                      std::vector<glm::dvec3>& texel_flux, int row_begin = 0,
                      int row_end = std::numeric_limits<int>::max());
// Texel rows of a map `width` texels wide held from `data` on, data[0] being the first texel of row
// `first_row`; only rows [row_begin, row_end) are written. A whole map (first_row 0) or one band of
// it (FootprintSums keeps a band only once something lands in it). With `rgb` instead of `data`:
// three floats a texel, the layout of a map's irradiance (FootprintSums' fine level).
struct TexelRows {
  glm::dvec3* data = nullptr;
  int width = 0;
  int first_row = 0;
  int row_begin = 0;
  int row_end = 0;
  float* rgb = nullptr;
  int channels = 3;  // of `rgb` or `grey`: 3, or 1 for a grey map (every flux's channels equal: the first)
  double* grey = nullptr;  // one double a texel (channels 1), instead of `data`
  void add(int j, int i, const glm::dvec3& flux) const {
    const std::size_t t = static_cast<std::size_t>(j - first_row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(i);
    assert(channels == 3 || (flux.x == flux.y && flux.y == flux.z));  // FootprintSums(map, grey): only grey flux
    if (grey) {
      grey[t] += flux.x;
    } else if (rgb && channels == 1) {
      rgb[t] += static_cast<float>(flux.x);
    } else if (rgb) {
      float* texel = rgb + 3 * t;
      for (int c = 0; c < 3; ++c) texel[c] += static_cast<float>(flux[c]);
    } else {
      data[t] += flux;
    }
  }
};
// The same into `rows`.
void depositFootprint(const ReceiverMap& map, const std::array<glm::dvec2, 4>& footprint, const glm::dvec3& flux,
                      const TexelRows& rows);

// A directional light's light on the map where no followed patch carries it (ALGORITHM.md
// "Receivers", direct light): per texel (W, texelCount() long), E_L·|L·n|·pitch² (the plane's
// irradiance from the light over the texel) less the flux the initial patches `followed` would
// put on it going straight (their corners' rays along L, depositFootprint), at least 0. The cells
// that meet the map and not the box, left out of the list (initialPatches with DirectCells),
// tile the rest of every texel, so the map gets what their footprints would give it, to rounding.
// Throws InputError naming "receiver" when the light does not reach the plane's front.
// Held by bands of FootprintSums::kBandRows texel rows: the bands no followed footprint reaches
// (most of a map) hold nothing, their texels' light is the closed form's (a 1024² map: 25 MB that
// were written and read, and zeroed by the kernel first, now kept for the shadow's bands alone).
class DirectMapLight {
 public:
  // W on texel (i, j).
  glm::dvec3 flux(int i, int j) const {
    const glm::dvec3 full = closedForm(i, j);
    const std::size_t t =
        static_cast<std::size_t>(j % kRows) * static_cast<std::size_t>(map_.texels.x) + static_cast<std::size_t>(i);
    if (grey_) {
      const std::vector<double>& band = followed_grey_[static_cast<std::size_t>(j / kRows)];
      return band.empty() ? full : glm::max(full - glm::dvec3(band[t]), glm::dvec3(0.0));
    }
    const std::vector<glm::dvec3>& band = followed_[static_cast<std::size_t>(j / kRows)];
    if (band.empty()) return full;
    return glm::max(full - band[t], glm::dvec3(0.0));
  }
  // Every texel's, u fastest (the GPU path's receiver pass).
  std::vector<glm::dvec3> texels() const;
  // Bands of rows that hold the followed patches' light (the rest: the closed form alone).
  int heldBands() const;

 private:
  friend DirectMapLight directMapLight(const ReceiverMap&, const LightSpec&, const std::vector<Patch>&);
  static constexpr int kRows = 16;  // FootprintSums::kBandRows
  // The light's flux over texel (i, j): E_L·|L·n|·pitch², or a point light's I·a(θ)·cos θ/d²·pitch².
  glm::dvec3 closedForm(int i, int j) const {
    if (!point_) return full_;
    const glm::dvec3 to_texel = map_.texelCenter(i, j) - light_.position;
    const double d = glm::length(to_texel);
    return full_ * (light_.attenuation(to_texel / d) / (d * d * d));
  }
  ReceiverMap map_;  // the geometry (no irradiance)
  bool point_ = false;
  LightSpec light_;
  glm::dvec3 full_{0.0};
  std::vector<std::vector<glm::dvec3>> followed_;  // per band: the followed patches' straight flux, or none
  // …or, for a grey light (every patch's flux grey), one double a texel: a third of the memory.
  bool grey_ = false;
  std::vector<std::vector<double>> followed_grey_;
};
DirectMapLight directMapLight(const ReceiverMap& map, const LightSpec& light, const std::vector<Patch>& followed);

// The per-texel flux sums of a map being baked (the CPU twin's), with coarser levels for wide
// footprints. A footprint whose box covers more than kFineFootprintTexels texels (dim light spread
// thin: rays leaving an object at grazing angles, which land in long slivers across the map) goes to
// the first level k ≤ kFootprintLevels, of texels 2^k times larger, where it covers at most that
// many, or the last; resolve() spreads each coarse texel's flux evenly over its 4^k texels. So its
// uniform flux density is kept over its quadrilateral to 1/16 of its size or finer, and the work
// of a footprint is bounded, not its area in texels (measured on the 128³ sphere over a floor: 46 k
// footprints that each crossed half the map). Footprints up to 16×16 texels (4 voxels at the
// default pitch) are deposited exactly, as depositFootprint says.
class FootprintSums {
 public:
  static constexpr int kFootprintLevels = 4;
  static constexpr double kFineFootprintTexels = 256.0;
  // Rows are filled in bands of this many (a multiple of 2^kFootprintLevels, so that a band of the
  // map is a whole band of every level).
  static constexpr int kBandRows = 16;

  // `grey`: every flux deposited has three equal channels (a grey light, nothing that colours it),
  // and the fine level keeps one float a texel (a third of the memory, 12.6 → 4.2 MB at 1024²);
  // irradiance() then gives a grey map (ReceiverMap::components 1).
  explicit FootprintSums(const ReceiverMap& map, bool grey = false);
  int channels() const { return channels_; }
  // The level a footprint goes to.
  int level(const std::array<glm::dvec2, 4>& footprint) const;
  // depositFootprint into its level, for the map rows of band `band` only.
  void deposit(const std::array<glm::dvec2, 4>& footprint, const glm::dvec3& flux, int band);
  int bands() const { return (map_.texels.y + kBandRows - 1) / kBandRows; }
  // Each map texel's flux (W): its own plus its share of every coarser level's texel over it.
  std::vector<glm::dvec3> resolve() const;
  // The map's irradiance (channels() floats a texel): each texel's flux as resolve() gives it, plus
  // `extra`'s (directMapLight's; none: nothing), times inv_area, written over the fine level's sums,
  // whose storage `out` then takes (the map's irradiance is the only copy: no second 12 MB at
  // 1024²). The sums are spent: nothing may be deposited or resolved after.
  void irradiance(const DirectMapLight* extra, double inv_area, std::vector<float>& out);

 private:
  // Row j's sums on every level (null where the band holds none), and texel i's flux from them.
  struct RowSums {
    const float* fine = nullptr;  // level 0: RGB floats, or grey ones (channels 1)
    int channels = 3;
    const glm::dvec3* level[kFootprintLevels + 1] = {};  // levels ≥ 1 (RGB)
    const double* grey_level[kFootprintLevels + 1] = {};  // …or grey (channels 1)
    glm::dvec3 flux(int i) const;
  };
  RowSums rowSums(int j) const;

  ReceiverMap map_;                      // geometry only
  std::vector<ReceiverMap> coarse_;      // level k ≥ 1 at index k − 1: pitch·2^k
  // Level 0's per-texel flux in floats, laid out as the map's irradiance (becomes it: irradiance()).
  // In doubles by bands it took 19 MB of fresh memory on the 128³ sphere's 1024² map besides the
  // 12 MB output; float sums differ from those by rounding (about 1e-7 of a texel's flux).
  std::vector<float> fine_;
  int channels_ = 3;
  // Level k ≥ 1's per-texel flux by bands of kBandRows >> k rows (band b: its rows from
  // b·(kBandRows >> k)), each band's made at the first footprint that lands in it.
  std::vector<std::vector<std::vector<glm::dvec3>>> bands_;
  std::vector<std::vector<std::vector<double>>> grey_bands_;  // the same for grey sums (channels 1)
};

// Area of the intersection of triangle (a, b, c) with the axis-aligned square [lo, hi] (exact,
// Sutherland–Hodgman clipping).
double triangleSquareOverlap(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& lo,
                             const glm::dvec2& hi);

}  // namespace eik
