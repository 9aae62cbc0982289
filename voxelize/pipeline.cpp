#include "voxelize/pipeline.h"

#include <sys/resource.h>

#include <cstdio>
#include <filesystem>
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/scene.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "voxelize/composite.h"
#include "voxelize/material_spec.h"
#include "voxelize/mesh_scene.h"
#include "voxelize/mesh_voxelizer.h"
#include "voxelize/procedural.h"
#include "voxelize/scene_export.h"
#include "voxelize/sharp_interfaces.h"

namespace eik {

double interfaceBand(const GridSpec& grid) {
  const glm::dvec3 h = grid.voxelSize();
  return kInterfaceBandVoxels * std::max(h.x, std::max(h.y, h.z));
}

namespace {

// buildVolume; `releasable` (the same regions, or null) gives up each array once read.
Volume buildFrom(const std::vector<Region>& regions, std::vector<Region>* releasable, const GridSpec& grid,
                 const PipelineOptions& options) {
  // Progress: compositing is about half the work, smoothing and the gradient the rest.
  auto report = [&options](double from, double to) -> ProgressFn {
    if (!options.progress) return {};
    return [&options, from, to](double f) { options.progress(from + (to - from) * f); };
  };
  CompositeOptions composite;
  composite.all_fields = options.all_fields;
  composite.progress = report(0.0, 0.5);
  if (options.interfaces == InterfaceMode::Sharp) {
    const double band = options.band > 0.0 ? options.band : interfaceBand(grid);
    Volume volume = releasable ? buildSharpVolume(std::move(*releasable), grid, band, composite)
                               : buildSharpVolume(regions, grid, band, composite);
    if (options.progress) options.progress(1.0);
    return volume;
  }
  Volume volume = compositeRegions(regions, grid, composite);

  Field& ior = volume.fields.at("ior");
  gaussianSmooth(ior, grid, options.smooth_sigma_voxels);  // Eq. 3.2
  // n(λ) = n + B·(1/λ² − 1/λ_d²): the Cauchy B is part of n, so it is smoothed with it. Then
  // B/(n − 1) stays the material's own ratio through the boundary layer, which the viewer's
  // ∇n(λ) = ∇n·(1 + c·B/(n − 1)) relies on.
  if (auto dispersion = volume.fields.find("dispersion"); dispersion != volume.fields.end())
    gaussianSmooth(dispersion->second, grid, options.smooth_sigma_voxels);
  if (options.progress) options.progress(0.8);
  volume.fields["ior_grad"] = gradient(ior, grid, options.gradient);  // Eq. 3.1
  volume.metadata["ior_smoothing_sigma_voxels"] = options.smooth_sigma_voxels;
  volume.metadata["ior_gradient"] = gradientOperatorName(options.gradient);
  if (options.progress) options.progress(1.0);
  return volume;
}

}  // namespace

Volume buildVolume(const std::vector<Region>& regions, const GridSpec& grid, const PipelineOptions& options) {
  return buildFrom(regions, nullptr, grid, options);
}

Volume buildVolume(std::vector<Region>&& regions, const GridSpec& grid, const PipelineOptions& options) {
  return buildFrom(regions, &regions, grid, options);
}

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// One object to voxelise: a mesh from a file, or a procedural shape.
struct Input {
  std::string source;  // the argument as given
  std::optional<ProceduralSpec> procedural;
  std::optional<TriangleMesh> mesh;
};

struct LoadedInputs {
  std::vector<Input> objects;
  std::vector<MeshScene> scenes;  // glTF lights and cameras for the SCENE.json
};

double peakMemoryMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// The i-th --material applies to the i-th OBJ/procedural input; a single one applies to all.
const std::string* materialFor(const VoxelizeOptions& o, std::size_t overridable_index) {
  if (o.materials.empty()) return nullptr;
  if (o.materials.size() == 1) return &o.materials[0];
  return overridable_index < o.materials.size() ? &o.materials[overridable_index] : nullptr;
}

// --material keys become shape parameters unless the spec gives them itself, so the spec wins.
ProceduralSpec withMaterial(const ProceduralSpec& spec, const std::string& material) {
  std::string text = spec.text();
  for (const auto& [key, value] : splitKeyValues(material, "--material")) {
    if (!isMaterialKey(key)) throw InputError("--material", key, "unknown material key");
    if (spec.params.count(key) || (key == "ior" && spec.params.count("n")) || (key == "n" && spec.params.count("ior")))
      continue;
    text += "," + key + "=" + value;
  }
  return parseProceduralSpec(text);
}

// The checks that need no input read: before any work, since a failure at the end would waste it.
void checkOptions(const VoxelizeOptions& o) {
  if (o.inputs.empty()) throw InputError("command line", "INPUT", "no input given (see voxelize --help)");
  if (o.output.empty()) throw InputError("command line", "-o", "no output given (-o OUT.vol.json)");
  if (o.output.size() < 9 || o.output.substr(o.output.size() - 9) != ".vol.json")
    throw InputError("-o", o.output, "the output manifest must end in .vol.json");
  if (o.pad < 0) throw InputError("--pad", "", "must not be negative");
  // Output directories must exist before any work starts: a failure at the end would waste it.
  for (const std::string* path : {&o.output, &o.stats, &o.scene}) {
    if (path->empty()) continue;
    fs::path dir = fs::absolute(*path).parent_path();
    if (!fs::is_directory(dir)) throw InputError(*path, "", "directory " + dir.string() + " does not exist");
  }
  if (!(o.smooth >= 0) || o.smooth > 8) throw InputError("--smooth", "", "must be in [0, 8] voxels");
  if (o.interfaces != "sharp" && o.interfaces != "smooth")
    throw InputError("--interfaces", o.interfaces, "expected sharp or smooth");
}

// 1. Read every input; validate everything before any heavy work.
LoadedInputs loadInputs(const VoxelizeOptions& o) {
  LoadedInputs loaded;
  std::size_t overridable = 0;
  for (const std::string& arg : o.inputs) {
    if (isProceduralSpec(arg)) {
      Input in{arg, parseProceduralSpec(arg), std::nullopt};
      if (const std::string* m = materialFor(o, overridable++)) in.procedural = withMaterial(*in.procedural, *m);
      loaded.objects.push_back(std::move(in));
      continue;
    }
    fs::path path(arg);
    const std::string ext = lower(path.extension().string());
    MeshScene scene = loadMeshFile(path);
    for (const std::string& w : scene.warnings) std::fprintf(stderr, "voxelize: warning: %s: %s\n", arg.c_str(), w.c_str());
    const bool is_obj = ext == ".obj";
    const std::string* material = is_obj ? materialFor(o, overridable++) : nullptr;
    for (TriangleMesh& mesh : scene.meshes) {
      if (material) mesh.material = parseMaterialSpec(*material, mesh.material);
      loaded.objects.push_back(Input{arg, std::nullopt, std::move(mesh)});
    }
    scene.meshes.clear();
    loaded.scenes.push_back(std::move(scene));
  }
  if (!o.materials.empty() && o.materials.size() != 1 && o.materials.size() != overridable)
    throw InputError("--material", "", "given " + std::to_string(o.materials.size()) + " times for " +
                                          std::to_string(overridable) + " OBJ/procedural inputs (give it once, or once per such input)");
  return loaded;
}

// 2. The grid.
GridSpec chooseGrid(const std::vector<Input>& inputs, const VoxelizeOptions& o, json& stats) {
  Bounds objects;
  for (const Input& in : inputs) {
    if (in.procedural) {
      objects.extend(proceduralBounds(*in.procedural));
    } else {
      MeshBounds b = in.mesh->bounds();
      if (!b.empty()) {
        objects.extend(b.min);
        objects.extend(b.max);
      }
    }
  }
  std::optional<Bounds> explicit_bounds;
  if (!o.bounds.empty()) explicit_bounds = parseBounds(o.bounds);
  const GridSpec grid = makeGrid(objects, o.res, o.pad, explicit_bounds);
  stats["grid"] = {{"dims", {grid.dims.x, grid.dims.y, grid.dims.z}},
                   {"bounds_min", {grid.bounds_min.x, grid.bounds_min.y, grid.bounds_min.z}},
                   {"bounds_max", {grid.bounds_max.x, grid.bounds_max.y, grid.bounds_max.z}},
                   {"voxel_size", grid.voxelSize().x}};
  stats["voxels"] = grid.count();
  if (!o.quiet)
    std::fprintf(stderr, "voxelize: %zu object(s) on a %d x %d x %d grid, voxel %.4g\n", inputs.size(), grid.dims.x,
                 grid.dims.y, grid.dims.z, grid.voxelSize().x);
  return grid;
}

// 3. Occupancy of every object.
std::vector<Region> voxelizeObjects(const std::vector<Input>& inputs, const GridSpec& grid, const VoxelizeOptions& o,
                                    json& stats) {
  const Stopwatch clock;
  std::vector<Region> regions;
  json objects_stats = json::array();
  // With sharp interfaces and no material that blends a field by coverage (composite.h
  // blendsFields), a procedural shape's coverage is read for its volume alone: n comes from the
  // distances. It is then taken from the distance at each voxel centre (one sample a voxel,
  // clamp(½ − d/h, 0, 1)) instead of S³ sub-samples: the same fields to the bit, the 128³ sphere's
  // command 85 → 70 ms, its reported volume 3e-5 larger (VoxelizeFiles test
  // ASharpClearShapeTakesItsOccupancyAtTheVoxelCentres).
  bool coverage_blends = o.interfaces != "sharp";
  for (const Input& in : inputs) {
    if (in.mesh) coverage_blends |= blendsFields(in.mesh->material);
    if (in.procedural)
      for (const ImplicitSolid& solid : proceduralSolids(*in.procedural, grid)) coverage_blends |= blendsFields(solid.material);
  }
  stats["procedural_supersample"] = coverage_blends ? o.supersample : 1;
  {
    ProgressBar bar("voxelize", !o.quiet);
    const double share = 1.0 / static_cast<double>(inputs.size());
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const Input& in = inputs[i];
      ProgressFn progress = [&bar, i, share](double f) { bar.update((static_cast<double>(i) + f) * share); };
      const double band = o.interfaces == "sharp" ? interfaceBand(grid) : 0.0;
      if (in.procedural) {
        ProceduralOptions options;
        options.supersample = coverage_blends ? o.supersample : 1;
        options.distance_band = band;
        for (Region& r : voxelizeProcedural(*in.procedural, grid, options, progress)) {
          objects_stats.push_back({{"input", in.source}, {"region", r.name}, {"enclosed_volume", r.enclosed_volume}});
          regions.push_back(std::move(r));
        }
      } else {
        MeshVoxelizeOptions options;
        options.supersample = o.supersample;
        options.distance_band = band;
        options.surface_mode = o.surface == "solid" ? SurfaceMode::Solid
                               : o.surface == "surface" ? SurfaceMode::Surface
                                                        : SurfaceMode::Auto;
        MeshVoxelizeStats ms;
        Region r = voxelizeMesh(*in.mesh, grid, options, progress, &ms);
        objects_stats.push_back({{"input", in.source},
                                 {"region", r.name},
                                 {"triangles", in.mesh->triangleCount()},
                                 {"open_surface", ms.open_surface},
                                 {"decision", ms.decision},
                                 {"rays_through_holes", ms.rays_through_holes},
                                 {"winding_voxels", ms.winding_voxels},
                                 {"dropped_triangles", ms.dropped_triangles},
                                 {"enclosed_volume", r.enclosed_volume},
                                 {"seconds", ms.seconds}});
        regions.push_back(std::move(r));
      }
    }
    bar.finish();
  }
  stats["objects"] = objects_stats;
  stats["time_occupancy_s"] = clock.seconds();
  return regions;
}

// 4. Composite, smooth n, take its gradient. The regions are released once composited.
Volume buildFields(std::vector<Region>& regions, const GridSpec& grid, const VoxelizeOptions& o, json& stats) {
  const Stopwatch clock;
  PipelineOptions pipeline;
  pipeline.interfaces = o.interfaces == "sharp" ? InterfaceMode::Sharp : InterfaceMode::Smooth;
  pipeline.smooth_sigma_voxels = o.smooth;
  ProgressBar fields_bar("n and grad n", !o.quiet);
  pipeline.progress = fields_bar.callback();
  Volume volume = buildVolume(std::move(regions), grid, pipeline);
  fields_bar.finish();
  regions.clear();
  stats["time_fields_s"] = clock.seconds();
  json sources = json::array();
  for (const std::string& s : o.inputs) sources.push_back(s);
  volume.metadata["source"] = {{"program", "voxelize"},
                               {"inputs", sources},
                               {"res", o.res},
                               {"pad_voxels", o.pad},
                               {"supersample", o.supersample}};
  return volume;
}

// 5. Write the volume (atomically) and, if wanted, its scene; returns the scene's path ("" for none).
fs::path writeOutputs(const Volume& volume, const std::vector<MeshScene>& scenes, const GridSpec& grid,
                      const VoxelizeOptions& o, json& stats) {
  const Stopwatch clock;
  VolumeWriteOptions write;
  write.gzip = !o.raw;
  write.detached = o.detached;
  fs::path out(o.output);
  fs::path scene_path = o.scene;
  const SceneExport exported = exportScene(scenes, out, grid);
  if (scene_path.empty() && exported.from_gltf)
    scene_path = out.parent_path() / (out.filename().string().substr(0, out.filename().string().size() - 9) + ".scene.json");
  // The scene names the volume by its manifest: it is written after it, and the previous run's is
  // removed before, so an interrupted run leaves the new volume without a scene, never with the old one.
  std::error_code ec;
  if (!scene_path.empty() && fs::is_regular_file(scene_path, ec)) {
    testSignalPoint();
    fs::remove(scene_path, ec);
  }
  writeVolume(volume, out, write);
  if (!scene_path.empty()) {
    writeScene(exported.scene, scene_path);
    for (const std::string& w : exported.warnings) std::fprintf(stderr, "voxelize: warning: %s\n", w.c_str());
  }
  stats["time_write_s"] = clock.seconds();
  return scene_path;
}

}  // namespace

void voxelizeFiles(const VoxelizeOptions& o) {
  checkOptions(o);
  const Stopwatch clock;
  json stats;

  LoadedInputs loaded = loadInputs(o);
  const GridSpec grid = chooseGrid(loaded.objects, o, stats);
  std::vector<Region> regions = voxelizeObjects(loaded.objects, grid, o, stats);
  const Volume volume = buildFields(regions, grid, o, stats);
  const fs::path scene_path = writeOutputs(volume, loaded.scenes, grid, o, stats);

  stats["time_total_s"] = clock.seconds();
  stats["peak_memory_mib"] = peakMemoryMiB();
  stats["materials"] = volume.metadata.value("materials", json::array());
  json fields = json::array();
  for (const auto& [name, field] : volume.fields) fields.push_back(name);
  stats["fields"] = fields;

  if (!o.stats.empty()) writeFileAtomic(o.stats, stats.dump(2) + "\n");
  if (!o.quiet) {
    std::fprintf(stderr, "voxelize: wrote %s (%zu fields) in %.2f s, peak memory %.0f MiB\n", o.output.c_str(),
                 volume.fields.size(), stats["time_total_s"].get<double>(), stats["peak_memory_mib"].get<double>());
    if (!scene_path.empty()) std::fprintf(stderr, "voxelize: wrote %s\n", scene_path.string().c_str());
  }
}

}  // namespace eik
