// voxelize: meshes (glTF 2.0, OBJ) and procedural shapes -> a material volume (DESIGN §4.1, §4.2).
//
//   voxelize INPUT... -o OUT.vol.json [--res N] [--bounds ...] [--pad VOXELS] [--smooth SIGMA]
//            [--material KEY=VALUE,...] [--stats FILE.json] [--quiet]
//
// The work itself lives in the library (procedural.h, mesh_voxelizer.h, pipeline.h); this file
// only reads the command line, reports progress and writes the outputs.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/cli.h"
#include "core/error.h"
#include "core/progress.h"
#include "core/scene.h"
#include "core/volume.h"
#include "voxelize/grid_builder.h"
#include "voxelize/material_spec.h"
#include "voxelize/mesh_scene.h"
#include "voxelize/mesh_voxelizer.h"
#include "voxelize/pipeline.h"
#include "voxelize/procedural.h"
#include "voxelize/scene_export.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace eik {
namespace {

struct Options {
  std::vector<std::string> inputs;
  std::string output;
  int res = 128;
  std::string bounds;
  double pad = kDefaultPadVoxels;
  double smooth = kDefaultSmoothSigmaVoxels;
  std::vector<std::string> materials;
  int supersample = 4;
  std::string surface = "auto";
  bool raw = false;
  bool detached = false;
  bool quiet = false;
  std::string stats;
  std::string scene;
  bool list_shapes = false;
};

// One object to voxelise: a mesh from a file, or a procedural shape.
struct Input {
  std::string source;  // the argument as given
  std::optional<ProceduralSpec> procedural;
  std::optional<TriangleMesh> mesh;
};

std::string shapeHelp() {
  std::string out = "Procedural shapes (procedural:NAME[,key=value...]):\n";
  for (const auto& shape : proceduralShapes()) {
    out += "  " + shape.name + ": " + shape.description + "\n";
    for (const auto& p : shape.params)
      out += "      " + p.key + "=" + p.default_value + "  " + p.meaning + "\n";
    if (!shape.material_keys.empty()) {
      out += "      material keys:";
      for (const auto& k : shape.material_keys) out += " " + k;
      out += "\n";
    }
  }
  return out;
}

double peakMemoryMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// The i-th --material applies to the i-th OBJ/procedural input; a single one applies to all.
const std::string* materialFor(const Options& o, std::size_t overridable_index) {
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

int run(int argc, char** argv) {
  Options o;
  CLI::App app{
      "voxelize: turn meshes (glTF 2.0, OBJ) and procedural shapes into a material volume\n"
      "(refractive index n pre-smoothed with a Gaussian, its gradient, absorption, emission,\n"
      "scattering, opaque parts) for lightsim and viewer. Thesis §3.1 and §6.1.",
      "voxelize"};
  app.add_option("inputs", o.inputs,
                 "mesh.gltf | mesh.glb | mesh.obj | procedural:NAME[,key=value...] (several allowed; "
                 "see --list-shapes)");
  app.add_option("-o,--output", o.output, "output manifest, must end in .vol.json");
  app.add_option("--res", o.res, "voxels along the longest axis of the objects (default 128)")
      ->check(CLI::Range(1, kMaxGridDim));
  app.add_option("--bounds", o.bounds, "explicit world box MINX,MINY,MINZ,MAXX,MAXY,MAXZ (no padding added)");
  app.add_option("--pad", o.pad, "voxels of air around the objects (default 3)");
  app.add_option("--smooth", o.smooth, "sigma of the Gaussian pre-smoothing of n, in voxels (default 0.75; 0: none)");
  app.add_option("--material", o.materials,
                 "material of OBJ and procedural inputs: KEY=VALUE[,KEY=VALUE...] with keys ior, "
                 "sigma_a=R:G:B, emission=R:G:B, albedo=R:G:B (opaque), scatter, g, abbe, name. Given once "
                 "it applies to all of them, given several times the i-th applies to the i-th such input");
  app.add_option("--supersample", o.supersample, "sub-samples per voxel and axis for anti-aliased occupancy (default 4)")
      ->check(CLI::Range(1, 16));
  app.add_option("--surface", o.surface,
                 "how meshes are read: auto (open sheets become thin opaque receivers), solid, surface")
      ->check(CLI::IsMember({"auto", "solid", "surface"}));
  app.add_flag("--raw", o.raw, "write raw NRRD data instead of gzip");
  app.add_flag("--detached", o.detached, "write detached NRRD headers (.nhdr + .raw[.gz])");
  app.add_option("--scene", o.scene,
                 "also write a SCENE.json for the volume (default: OUT.scene.json when a glTF input has "
                 "lights or cameras)");
  app.add_option("--stats", o.stats, "write timings, voxel counts, volume per material, peak memory as JSON");
  app.add_flag("-q,--quiet", o.quiet, "no progress bar");
  app.add_flag("--list-shapes", o.list_shapes, "list the procedural shapes and their parameters");
  app.footer(
      "Examples:\n"
      "  voxelize procedural:sphere,r=0.5,ior=1.5 -o sphere.vol.json --res 128\n"
      "  voxelize glass.glb -o glass.vol.json --res 256\n"
      "  voxelize bunny.obj --material ior=1.55,sigma_a=0.2:0.6:1.4 -o bunny.vol.json\n"
      "Exit codes: 0 success, 1 runtime failure, 2 bad usage or bad input.");
  if (!parseCommandLine(app, argc, argv)) return kExitOk;
  if (o.list_shapes) {
    std::printf("%s", shapeHelp().c_str());
    return kExitOk;
  }
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

  const auto t_start = std::chrono::steady_clock::now();
  auto seconds_since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  json stats;

  // 1. Read every input; validate everything before any heavy work.
  std::vector<Input> inputs;
  std::vector<MeshScene> scenes;  // glTF lights and cameras for the SCENE.json
  std::size_t overridable = 0;
  for (const std::string& arg : o.inputs) {
    if (isProceduralSpec(arg)) {
      Input in{arg, parseProceduralSpec(arg), std::nullopt};
      if (const std::string* m = materialFor(o, overridable++)) in.procedural = withMaterial(*in.procedural, *m);
      inputs.push_back(std::move(in));
      continue;
    }
    fs::path path(arg);
    std::string ext = path.extension().string();
    for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    MeshScene scene = loadMeshFile(path);
    for (const std::string& w : scene.warnings) std::fprintf(stderr, "voxelize: warning: %s: %s\n", arg.c_str(), w.c_str());
    const bool is_obj = ext == ".obj";
    const std::string* material = is_obj ? materialFor(o, overridable++) : nullptr;
    for (TriangleMesh& mesh : scene.meshes) {
      if (material) mesh.material = parseMaterialSpec(*material, mesh.material);
      inputs.push_back(Input{arg, std::nullopt, std::move(mesh)});
    }
    scene.meshes.clear();
    scenes.push_back(std::move(scene));
  }
  if (!o.materials.empty() && o.materials.size() != 1 && o.materials.size() != overridable)
    throw InputError("--material", "", "given " + std::to_string(o.materials.size()) + " times for " +
                                          std::to_string(overridable) + " OBJ/procedural inputs (give it once, or once per such input)");

  // 2. The grid.
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

  // 3. Occupancy of every object.
  const auto t_regions = std::chrono::steady_clock::now();
  std::vector<Region> regions;
  json objects_stats = json::array();
  {
    ProgressBar bar("voxelize", !o.quiet);
    const double share = 1.0 / static_cast<double>(inputs.size());
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const Input& in = inputs[i];
      ProgressFn progress = [&bar, i, share](double f) { bar.update((static_cast<double>(i) + f) * share); };
      if (in.procedural) {
        ProceduralOptions options;
        options.supersample = o.supersample;
        for (Region& r : voxelizeProcedural(*in.procedural, grid, options, progress)) {
          objects_stats.push_back({{"input", in.source}, {"region", r.name}, {"enclosed_volume", r.enclosed_volume}});
          regions.push_back(std::move(r));
        }
      } else {
        MeshVoxelizeOptions options;
        options.supersample = o.supersample;
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
                                 {"enclosed_volume", r.enclosed_volume},
                                 {"seconds", ms.seconds}});
        regions.push_back(std::move(r));
      }
    }
    bar.finish();
  }
  stats["objects"] = objects_stats;
  stats["time_occupancy_s"] = seconds_since(t_regions);

  // 4. Composite, smooth n, take its gradient.
  const auto t_fields = std::chrono::steady_clock::now();
  PipelineOptions pipeline;
  pipeline.smooth_sigma_voxels = o.smooth;
  ProgressBar fields_bar("n and grad n", !o.quiet);
  pipeline.progress = fields_bar.callback();
  Volume volume = buildVolume(regions, grid, pipeline);
  fields_bar.finish();
  regions.clear();
  stats["time_fields_s"] = seconds_since(t_fields);
  json sources = json::array();
  for (const std::string& s : o.inputs) sources.push_back(s);
  volume.metadata["source"] = {{"program", "voxelize"},
                               {"inputs", sources},
                               {"res", o.res},
                               {"pad_voxels", o.pad},
                               {"supersample", o.supersample}};

  // 5. Write the volume (atomically) and, if wanted, its scene.
  const auto t_write = std::chrono::steady_clock::now();
  VolumeWriteOptions write;
  write.gzip = !o.raw;
  write.detached = o.detached;
  fs::path out(o.output);
  fs::path scene_path = o.scene;
  const SceneExport exported = exportScene(scenes, out, grid);
  if (scene_path.empty() && exported.from_gltf)
    scene_path = out.parent_path() / (out.filename().string().substr(0, out.filename().string().size() - 9) + ".scene.json");
  writeVolume(volume, out, write);
  if (!scene_path.empty()) {
    writeScene(exported.scene, scene_path);
    for (const std::string& w : exported.warnings) std::fprintf(stderr, "voxelize: warning: %s\n", w.c_str());
  }
  stats["time_write_s"] = seconds_since(t_write);
  stats["time_total_s"] = seconds_since(t_start);
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
  return kExitOk;
}

}  // namespace
}  // namespace eik

int main(int argc, char** argv) { return eik::runMain("voxelize", eik::run, argc, argv); }
