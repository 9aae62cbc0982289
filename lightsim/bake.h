// What a bake adds to a volume (ALGORITHM.md "Bake output", docs/volume-format.md), and reading the light
// of `lightsim --light ... --power ...` or `--scene` (docs/programs.md).
#pragma once

#include <filesystem>
#include <optional>
#include <vector>
#include <string>

#include "core/volume.h"
#include "lightsim/simulator.h"

namespace eik {

// Adds (or replaces) the fields `irradiance` (RGB, W/m²) and `light_dir` (unit, 0 where no light
// passed), the result's receiver maps (grey where their channels agree: ReceiverMap::makeGrey) and
// the manifest entries "light" (LightSpec::toJson) and "bake_stats" (SimulationStats::toJson). Throws std::invalid_argument when the result's fields do not fit the
// volume's grid (3 components, one per voxel).
void applyBake(Volume& volume, const BakeResult& result, const LightSpec& light);
// The same for a bake of several lights summed (a scene's): "light" the first, whose direct light
// a receiver map's reader takes off exactly, and "lights" all of them in order (only when there are
// two or more; a one-light bake removes an earlier bake's list).
void applyBake(Volume& volume, const BakeResult& result, const std::vector<LightSpec>& lights);
// The same, moving the result's fields and maps into the volume instead of copying them (at 128³
// a receiver map of 1024² texels is 12 MB of fresh memory a copy would touch).
void applyBake(Volume& volume, BakeResult&& result, const LightSpec& light);
void applyBake(Volume& volume, BakeResult&& result, const std::vector<LightSpec>& lights);

// Whether the viewer reads a bake's volume fields (irradiance, light_dir) for this volume: it does
// for in-scattering (a `scatter` field with a non-zero albedo somewhere), for opaque embeddings (an
// `opaque` field with its indicator set somewhere), and for the ground under the volume when no
// receiver map is baked (`receiver_map` false). `lightsim --volume-deposits auto` deposits only then.
bool viewerReadsVolumeLight(const Volume& volume, bool receiver_map);

// The options a bake ran with, as the baked manifest's "bake_options" (`lightsim` writes it;
// docs/volume-format.md): what a re-bake with another light needs to make the same kind of bake
// (the viewer window's, viewer/background_bake.h). Not the progress callback or cancel flag.
nlohmann::json bakeOptionsToJson(const SimulationOptions& options);
// Back: keys that are absent keep `defaults`' values. InputError naming `source` and the key for a
// wrong type or an unknown name, and what validateOptions refuses.
SimulationOptions bakeOptionsFromJson(const nlohmann::json& json, const std::string& source,
                                      SimulationOptions defaults = {});

// Filters the bake's irradiance with a normalised 3D Gaussian of σ voxels (core/gaussian_filter.h),
// a reconstruction filter for the deposits at patch midpoints. It keeps the sum of the irradiance
// except within 3σ of the grid's faces (the borders clamp), and leaves the light direction as it is.
// σ = 0 does nothing.
void smoothIrradiance(BakeResult& result, const GridSpec& grid, double sigma_voxels);

// Parses `--light` ("directional:DX,DY,DZ" or "point:X,Y,Z") and `--power` ("R,G,B", or one value
// for all three channels). The direction is normalised. Throws InputError naming --light or
// --power for malformed text, a non-finite number, a zero direction, a negative channel or a power
// that is zero in every channel.
LightSpec parseLight(const std::string& light, const std::string& power = "1,1,1");

// Every light of a SCENE.json, in its order, as LightSpecs (`lightsim SCENE.json`, `--scene`).
// Throws InputError naming the file for a scene without lights or a light without power (and what
// readScene throws).
std::vector<LightSpec> lightsFromScene(const std::filesystem::path& file);
// The first of them.
LightSpec lightFromScene(const std::filesystem::path& file);

// Parses `--receiver` ("PX,PY,PZ:NX,NY,NZ[:HALF_EXTENT]"): the plane through P with normal N
// (normalised), and its half extent (default unbounded). InputError naming --receiver otherwise.
ReceiverSpec parseReceiver(const std::string& text);

// The ground of a SCENE.json as a receiver (`lightsim --scene`), or nullopt when it has none.
std::optional<ReceiverSpec> receiverFromScene(const std::filesystem::path& file);

// True when the bake had no initial patch: the light misses the volume (the bake is all zeros).
inline bool lightMissedVolume(const SimulationStats& stats) { return stats.initial_patches == 0; }

}  // namespace eik
