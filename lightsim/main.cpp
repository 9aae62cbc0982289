// lightsim: bakes a light's wavefront into a volume (thesis §4, §6.2; docs/programs.md; ALGORITHM.md).
//
//   lightsim IN.vol.json -o OUT.vol.json --light directional:DX,DY,DZ | point:X,Y,Z
//            [--power R,G,B] [--backend gl|cpu] [--deposit accumulate|max] [--stats FILE.json]
//
// The work lives in the library (make_simulator.h picks the back end; bake.h); this file reads the
// command line, runs the simulator through its interface, reports progress and writes the outputs.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/cli.h"
#include "core/error.h"
#include "core/interfaces.h"
#include "core/json_input.h"
#include "core/progress.h"
#include "core/scene.h"
#include "core/stopwatch.h"
#include "core/volume.h"
#include "lightsim/bake.h"
#include "lightsim/make_simulator.h"
#include "lightsim/receiver.h"
#include "lightsim/scene_bake.h"
#include "lightsim/spectral_bake.h"
#include "lightsim/sun_disc.h"
#include "lightsim/wavefront.h"

namespace fs = std::filesystem;

namespace eik {
namespace {

// "cpu, 2 threads, SIMD AVX3" or the GL renderer's name.
std::string rendererName(const SimulationStats& s) { return s.renderer + (s.simd.empty() ? "" : ", SIMD " + s.simd); }

// Whether `path` is a SCENE.json (a JSON object with "objects") rather than a volume's manifest.
// Anything that does not parse is left to the volume's reader, which says what is wrong with it.
bool isSceneFile(const std::string& path) {
  constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t{16} << 20;  // scenes and manifests are kilobytes
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size > kMaxSceneBytes) return false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  // As long as the file (not the limit: 16 MB of zeroed pages cost a bake command 10 ms).
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  try {
    const nlohmann::json j = parseJsonInput(text, path);
    return j.is_object() && j.contains("objects");
  } catch (const InputError&) {
    return false;
  }
}

int run(int argc, char** argv) {
  std::string input, output, light_text, power_text = "1,1,1", scene_path, backend = "auto", deposit = "accumulate",
                                         integrator = "euler", split_rule = "axis", at_max_depth = "keep", stats_path,
                                         gl_backend = "auto", kernel = "track", receiver_text, count_readback = "auto";
  bool no_receiver = false;
  SimulationOptions options;
  double options_receiver_pitch = 0.25;
  int bench_runs = 0;
  int band_count = 3;
  int sun_samples = kDefaultSunSamples;
  double smooth_irradiance = 0.0;
  bool quiet = false, raw = false;
  CLI::App app{
      "lightsim: propagate a light's wavefront through a volume as a GPU particle system of adaptive\n"
      "patches and bake irradiance and light direction into it (thesis §4, §6.2).",
      "lightsim"};
  app.add_option("input", input,
                 "the volume to bake, IN.vol.json (needs ior and ior_grad; sigma_a if absorbing), or a SCENE.json "
                 "whose objects are baked each under its placement (every light, summed; its ground)")
      ->required();
  app.add_option("-o,--output", output,
                 "the baked volume, OUT.vol.json (IN plus irradiance and light_dir); for a SCENE.json a folder "
                 "that gets each object's baked volume and a SCENE.json naming them")
      ->required();
  app.add_option("--light", light_text, "directional:DX,DY,DZ (direction of travel) or point:X,Y,Z");
  app.add_option("--power", power_text,
                 "R,G,B: irradiance in W/m² of a directional light, radiant intensity in W/sr of a point light "
                 "(default 1,1,1)");
  app.add_option("--scene", scene_path,
                 "take the lights from this SCENE.json (every one, baked in turn and summed) instead of --light, and its "
                 "ground as the receiver");
  app.add_option("--receiver", receiver_text,
                 "PX,PY,PZ:NX,NY,NZ[:HALF_EXTENT]: a receiver plane through P facing N (the light's side) that "
                 "stops the light and gets its own map of planar irradiance (default: the --scene's ground)");
  app.add_flag("--no-receiver", no_receiver, "no receiver map, even when the --scene has a ground");
  app.add_option("--receiver-pitch", options_receiver_pitch,
                 "texel edge of the receiver map in voxels of the volume (default 0.25)")
      ->check(CLI::Range(0.01, 8.0));
  app.add_option("--sun-samples", sun_samples,
                 "directions over the disc of a light with an angular size (a scene's directional light with "
                 "angular_diameter_deg, the sun's 0.53), or points in the ball of a point or spot light with a "
                 "radius: its soft shadows in that many steps, at that many times the cost (default 16)")
      ->check(CLI::Range(1, 256));
  app.add_option("--bands", band_count,
                 "spectral bands of a dispersive volume (a dispersion field or a slot with a Cauchy B), each "
                 "propagated with its own n(lambda): 3 (default: R, G, B at the viewer's 0.61, 0.55, 0.465 um), 1 "
                 "(none), or 4 to 16 (equal bands over 0.38-0.78 um, to RGB by the CIE 1931 matching functions); a "
                 "volume without dispersion is baked once")
      ->check(CLI::Range(1, kMaxSpectralBands));
  app.add_option("--bounces", options.bounces,
                 "Fresnel reflections at sharp interfaces followed as wavefronts of their own (default 1; 0: their "
                 "flux is counted as reflected)")
      ->check(CLI::Range(0, 8));
  app.add_option("--deposit-kernel", kernel,
                 "track (default: flux times path length over the patch's footprint, with each voxel's trilinear "
                 "hat: flat in free air) or point (the first release: all of it at the voxel of the patch's "
                 "midpoint; no receiver map with it on the GPU)")
      ->check(CLI::IsMember({"track", "point"}));
  std::string free_flight = "on";
  app.add_option("--free-flight", free_flight,
                 "on (default: a patch crosses quiet space, where n is constant and no interface lies, in one "
                 "straight step, and near surfaces takes the straight steps in which no corner meets one together; "
                 "the same bake in fewer steps; with volume deposits the GPU path flies only as far as its deposit "
                 "pass reaches) or off (steps of --step or --straight-step everywhere)")
      ->check(CLI::IsMember({"on", "off"}));
  options.straight_step_voxels = 2.0;
  app.add_option("--straight-step", options.straight_step_voxels,
                 "VOXELS: the step where every ray is straight between sharp interfaces and crosses "
                 "them exactly (materials of constant n, nothing absorbing within reach; with volume deposits "
                 "only where no corner meets an interface; default 2, 0: off, steps of --step)")
      ->check(CLI::Range(0.0, 64.0));
  std::string volume_deposits = "auto";
  app.add_option("--volume-deposits", volume_deposits,
                 "auto (default: on where the viewer reads the volume's baked light: a scattering or opaque "
                 "part, or no receiver map; otherwise only the receiver map is baked, several times faster for "
                 "clear glass), on (always write irradiance and light_dir) or off (never)")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  app.add_option("--backend", backend,
                 "auto (default: gl on a hardware GPU for what the GPU path does, cpu otherwise), gl (the GPU "
                 "particle system) or cpu (the CPU twin, multi-threaded)")
      ->check(CLI::IsMember({"gl", "cpu", "auto"}));
  app.add_option("--deposit", deposit,
                 "accumulate (default: sums every wavefront sheet, conserves energy) or max (the thesis: the "
                 "strongest patch per voxel)")
      ->check(CLI::IsMember({"accumulate", "max"}));
  app.add_option("--integrator", integrator, "euler (Eq. 6.1/6.2, default), rk2 or rk4")
      ->check(CLI::IsMember({"euler", "rk2", "rk4"}));
  app.add_option("--step", options.step_voxels, "time step: arc length per step in air, in voxels (default 0.5)")
      ->check(CLI::Range(0.01, 4.0));
  CLI::Option* patch = app.add_option("--patch", options.patch_voxels,
                                      "initial patch edge in voxels (default half the split length, at least 1)")
                           ->check(CLI::Range(0.05, 8.0));
  CLI::Option* split =
      app.add_option("--split", options.split_voxels,
                     "split patches with an edge longer than this, in voxels (default with sharp interfaces: the "
                     "grid's longest side / 44, clamped to 1.5-3; 1 for a smoothed n)")
          ->check(CLI::Range(0.1, 16.0));
  app.add_option("--split-rule", split_rule,
                 "axis (default: halve only the directions whose edges are too long, 1x2 or 2x2) or quad "
                 "(the thesis: always 2x2)")
      ->check(CLI::IsMember({"axis", "quad"}));
  CLI::Option* max_depth =
      app.add_option("--max-depth", options.max_depth,
                     "splits allowed per initial patch, a 1x2 split counting 1/2 (default 4 for a volume with sharp "
                     "interfaces, 6 for a smoothed one)")
          ->check(CLI::Range(0, 16));
  app.add_option("--at-max-depth", at_max_depth,
                 "keep (default: a patch that should split beyond --max-depth goes on unsplit while its edges stay "
                 "within 4 split lengths, then dies) or kill (the thesis: it dies at once)")
      ->check(CLI::IsMember({"keep", "kill"}));
  app.add_option("--smooth-irradiance", smooth_irradiance,
                 "sigma in voxels of a Gaussian reconstruction filter on the baked irradiance: it removes "
                 "the voxel-scale grain of midpoint deposits, at the cost of that much blur (default 0: none)")
      ->check(CLI::Range(0.0, 4.0));
  app.add_option("--max-steps", options.max_steps, "step limit (default: 4 grid diagonals)")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--flux-threshold", options.flux_threshold,
                 "kill patches below this fraction of the initial patch flux (default 1e-4)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--gl", gl_backend, "OpenGL back end for --backend gl: auto | osmesa | egl (default auto)");
  app.add_option("--count-readback", count_readback,
                 "--backend gl: when the CPU reads each step's patch count: overlap (a step late, the passes "
                 "drawn over a bound, so the GPU never waits), wait (every step, exact draws) or auto (default: "
                 "overlap on a hardware GPU, wait on a software rasteriser); the bake is the same")
      ->check(CLI::IsMember({"auto", "wait", "overlap"}));
  app.add_option("--stats", stats_path, "write steps, patches, splits, kills, flux ledger and phase times as JSON");
  app.add_option("--bench", bench_runs,
                 "bake N times and print the median wall time, patch-steps per second, peak patches and (gl) "
                 "texture memory; --stats gets them too; the last bake is written")
      ->check(CLI::Range(1, 1000));
  app.add_flag("--raw", raw, "write raw NRRD data instead of gzip");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.footer(
      "Examples:\n"
      "  lightsim sphere.vol.json -o sphere.baked.vol.json --light directional:0,-1,0 --power 1,1,1\n"
      "  lightsim glass.vol.json -o glass.baked.vol.json --scene glass.scene.json --backend cpu\n"
      "  lightsim sphere.vol.json -o sphere.baked.vol.json --light directional:0,-1,0 --receiver 0,0,0:0,1,0\n"
      "  lightsim museum/SCENE.json -o museum-baked\n"
      "Exit codes: 0 success, 1 runtime failure, 2 bad usage or bad input.");
  addOutsidePathsFlag(app);
  if (!parseCommandLine(app, argc, argv)) return kExitOk;

  options.deposit = deposit == "max" ? DepositMode::Max : DepositMode::Accumulate;
  options.split_rule = split_rule == "quad" ? SplitRule::Quad : SplitRule::Axis;
  options.at_max_depth = at_max_depth == "kill" ? DepthLimit::Kill : DepthLimit::Keep;
  options.integrator = integrator == "rk4"   ? Integrator::RK4
                       : integrator == "rk2" ? Integrator::RK2
                                             : Integrator::Euler;
  options.deposit_kernel = kernel == "point" ? DepositKernel::Point : DepositKernel::Track;
  options.free_flight = free_flight == "on";
  // A bake of one volume (the whole of a volume's bake, or one object's of a scene) in three parts:
  // `prepare` (lightsim's defaults for the volume, the volume at world scale, the back end, one map
  // lattice for every run), `runLight` (one light: each spectral band (spectral_bake.h) for each of
  // its directions over its disc (sun_disc.h; the light itself when it has no angular size), run
  // number band × directions + direction, summed) and `write` (the lights' sums into the volume and
  // its manifest). `scale` is the object's (scene_bake.h); lights and receiver are given in its bake
  // frame.
  struct BakeLight {
    LightSpec light;                     // as the scene or the command line gives it
    std::vector<LightSpec> directions;   // what is run: sunDiscSamples(light)
  };
  // What a scene's bake does around each run of one object under one light (its chain per run).
  struct RunHooks {
    std::function<void(std::size_t run, SimulationOptions&)> before;
    std::function<void(std::size_t run, BakeResult&)> after;
  };
  struct VolumeBake {
    Volume* volume = nullptr;
    std::string source;
    double scale = 1.0;
    SimulationOptions options;
    std::optional<Volume> scaled;        // the volume at world scale, when scale ≠ 1
    SimulatorBackendOptions choice;
    std::unique_ptr<Simulator> simulator;  // one band: one simulator for every run
    const Volume& atScale() const { return scaled ? *scaled : *volume; }
  };
  // `fields_go`: the caller drops the volume's fields once the simulator is made (the command's one
  // volume: written back from their files), so the CPU twin may take the distances it keeps as they are.
  auto prepare = [&](Volume& volume, const std::string& source, const std::vector<BakeLight>& lights,
                     SimulationOptions options, double scale, const std::vector<SpectralBand>& bands,
                     bool fields_go = false) {
    auto bake = std::make_unique<VolumeBake>();
    bake->volume = &volume;
    bake->source = source;
    bake->scale = scale;
    const VolumeDefaults defaults = volumeDefaults(volume.has("interfaces"), volume.grid);
    if (max_depth->count() == 0) options.max_depth = defaults.max_depth;
    if (patch->count() == 0) options.patch_voxels = defaults.patch_voxels;
    if (split->count() == 0) options.split_voxels = defaults.split_voxels;
    options.volume_deposits = volume_deposits == "on" || (volume_deposits == "auto" &&
                                                          viewerReadsVolumeLight(volume, options.receiver.has_value()));
    if (!options.volume_deposits && !options.receiver)
      throw InputError("command line", "--volume-deposits",
                       "off needs a receiver (--receiver or a --scene with a ground): "
                       "the bake would make nothing");
    if (volume_deposits == "auto" && !options.volume_deposits && !quiet)
      std::fprintf(stderr,
                   "lightsim: --volume-deposits auto: nothing in the volume scatters or is opaque and the "
                   "receiver gets a map, so only the map is baked (no irradiance/light_dir fields)\n");
    SimulatorBackendOptions& choice = bake->choice;
    choice.backend = backend == "cpu"    ? SimulatorBackend::Cpu
                     : backend == "auto" ? SimulatorBackend::Auto
                                         : SimulatorBackend::Gl;
    choice.gl = gl_backend;
    choice.count_readback = count_readback == "wait"      ? GpuSimulatorOptions::CountReadback::Wait
                            : count_readback == "overlap" ? GpuSimulatorOptions::CountReadback::Overlap
                                                          : GpuSimulatorOptions::CountReadback::Auto;
    choice.source = source;
    if (!quiet)
      choice.report = [](const std::string& why) {
        std::fprintf(stderr, "lightsim: --backend auto: %s\n", why.c_str());
      };
    // The bake runs in the object's bake frame (scene_bake.h): the volume at world scale.
    if (scale != 1.0) bake->scaled = volumeAtWorldScale(volume, scale);
    if (bands.size() > 1 && !quiet)
      std::fprintf(stderr, "lightsim: dispersive: %zu spectral bands, %.3f to %.3f um, each with its own n(lambda)\n",
                   bands.size(), bands.front().lambda_um, bands.back().lambda_um);
    std::size_t runs = 0;
    std::vector<LightSpec> point_like;
    for (const BakeLight& l : lights) {
      runs += bands.size() * l.directions.size();
      point_like.push_back(l.light);
      point_like.back().angular_diameter_deg = 0.0;
      if (l.directions.size() > 1 && !quiet) {
        if (l.light.type == LightSpec::Type::Directional)
          std::fprintf(stderr, "lightsim: a light's disc of %.3g degrees from %zu directions (soft shadows)\n",
                       l.light.angular_diameter_deg, l.directions.size());
        else
          std::fprintf(stderr, "lightsim: a light's ball of radius %.3g from %zu points in it (soft shadows)\n",
                       l.light.radius, l.directions.size());
      }
    }
    // Runs that are summed share one map lattice: the union of the lights' own.
    if (options.receiver && runs > 1) {
      glm::dvec3 lo, hi;
      propagationBox(bake->atScale().grid, options, lo, hi);
      options.receiver_geometry = receiverGeometry(*options.receiver, point_like, bake->atScale().grid, lo, hi);
    }
    if (bands.size() == 1) {
      SimulatorBackendOptions made = choice;
      const auto interfaces = volume.fields.find("interfaces");
      if (fields_go && !bake->scaled && interfaces != volume.fields.end() && volume.field_files.count("interfaces") > 0)
        made.cpu_takes_interfaces = &interfaces->second.data;
      bake->simulator = makeSimulator(bake->atScale(), made, &options);
    }
    bake->options = options;
    return bake;
  };
  // One light's runs, summed; `progress` gets the fraction of them done.
  auto runLight = [&](VolumeBake& bake, const BakeLight& light, const std::vector<SpectralBand>& bands,
                      const RunHooks& hooks, const ProgressFn& progress) {
    const std::vector<LightSpec>& directions = light.directions;
    const std::size_t runs = bands.size() * directions.size();
    BandSum sum;
    for (std::size_t b = 0; b < bands.size(); ++b) {
      // Several bands (spectral_bake.h): the volume at each band's wavelength, a simulator each,
      // made in turn, the band's share of the light's power.
      std::unique_ptr<Simulator> band_simulator;
      if (bands.size() > 1) {
        const Volume band_volume = volumeAtWavelength(bake.atScale(), bands[b].lambda_um);
        band_simulator = makeSimulator(band_volume, bake.choice, &bake.options);
        bake.choice.report = nullptr;  // the back end's choice is said once
      }
      Simulator& sim = band_simulator ? *band_simulator : *bake.simulator;
      for (std::size_t d = 0; d < directions.size(); ++d) {
        const std::size_t r = b * directions.size() + d;
        LightSpec run_light = directions[d];
        run_light.power *= bands[b].rgb;
        SimulationOptions run_options = bake.options;
        if (progress)
          run_options.progress = [&, r](double f) { progress((static_cast<double>(r) + f) / static_cast<double>(runs)); };
        if (hooks.before) hooks.before(r, run_options);
        BakeResult one = sim.run(run_light, run_options);
        if (hooks.after) hooks.after(r, one);
        sum.add(std::move(one));
      }
      if (b + 1 == bands.size() && band_simulator) bake.simulator = std::move(band_simulator);  // for lastRunStats
    }
    return sum.finish();
  };
  // The lights' summed bake into the volume, written to `out` (and the stats to `stats_path`).
  auto write = [&](VolumeBake& bake, BakeResult result, const std::vector<BakeLight>& lights,
                   const std::vector<SpectralBand>& bands, const std::string& output, const std::string& stats_path,
                   nlohmann::json stats_json) {
    Volume& volume = *bake.volume;
    stats_json.update(result.stats.toJson());
    stats_json.update(bake.simulator->lastRunStats());
    if (lightMissedVolume(result.stats))
      std::fprintf(stderr, "lightsim: warning: the light misses the volume; the bake is empty\n");
    if (smooth_irradiance > 0.0) smoothIrradiance(result, volume.grid, smooth_irradiance);
    // Back in the volume's own coordinates: the maps and every light (the first is the one whose
    // direct light the maps' readers take off: docs/volume-format.md).
    std::vector<LightSpec> baked_lights;
    for (const BakeLight& l : lights) baked_lights.push_back(l.light);
    bakeToVolumeFrame(result, baked_lights.front(), bake.scale);
    for (std::size_t k = 1; k < baked_lights.size(); ++k) {
      BakeResult none;
      bakeToVolumeFrame(none, baked_lights[k], bake.scale);
    }
    const SimulationStats stats = result.stats;
    applyBake(volume, std::move(result), baked_lights);
    volume.metadata["bake_options"] = bakeOptionsToJson(bake.options);
    if (bands.size() > 1) volume.metadata["bake_bands"] = bands.size();
    if (smooth_irradiance > 0.0) volume.metadata["irradiance_smoothing_sigma_voxels"] = smooth_irradiance;
    VolumeWriteOptions write_options;
    write_options.gzip = !raw;
    // The input's fields are written back as they were read (their encoded samples copied), all but
    // the two a bake makes.
    write_options.unchanged_fields = volume.field_files;
    write_options.unchanged_fields.erase("irradiance");
    write_options.unchanged_fields.erase("light_dir");
    writeVolume(volume, output, write_options);
    if (!stats_path.empty()) writeFileAtomic(stats_path, stats_json.dump(2) + "\n");
    if (!quiet) {
      const SimulationStats& s = stats;
      std::fprintf(stderr, "lightsim: %d steps, %llu initial / %llu peak patches, %llu splits on %s\n", s.steps,
                   static_cast<unsigned long long>(s.initial_patches), static_cast<unsigned long long>(s.peak_patches),
                   static_cast<unsigned long long>(s.splits), rendererName(s).c_str());
      for (const ReceiverMap& map : volume.receivers)
        std::fprintf(stderr, "lightsim: receiver '%s': %d x %d texels of %.4g, %.4g W of %.4g W received\n",
                     map.name.c_str(), map.texels.x, map.texels.y, map.pitch, luminance(s.flux_received),
                     luminance(s.flux_in));
      std::fprintf(stderr, "lightsim: wrote %s\n", output.c_str());
    }
  };
  auto bakeLights = [&](const std::vector<LightSpec>& lights) {
    std::vector<BakeLight> out;
    for (const LightSpec& l : lights) out.push_back({l, sunDiscSamples(l, sun_samples)});
    return out;
  };

  if (isSceneFile(input)) {
    for (const auto& [given, flag] : {std::pair{!light_text.empty(), "--light"},
                                      {power_text != "1,1,1", "--power"},
                                      {!scene_path.empty(), "--scene"},
                                      {!receiver_text.empty(), "--receiver"},
                                      {no_receiver, "--no-receiver"},
                                      {!stats_path.empty(), "--stats"},
                                      {bench_runs > 0, "--bench"}})
      if (given)
        throw InputError("command line", flag,
                         std::string("not with a SCENE.json input: the scene gives the light and the ground, and each "
                                     "baked manifest holds its bake's stats"));
    Scene scene = readScene(input);
    const fs::path out_dir = fs::absolute(output).lexically_normal();
    if (!fs::is_directory(out_dir.parent_path()))
      throw InputError("-o", output, "directory " + out_dir.parent_path().string() + " does not exist");
    if (fs::exists(out_dir) && !fs::is_directory(out_dir))
      throw InputError("-o", output, "with a SCENE.json input -o names a folder, and this is a file");
    if (fs::exists(out_dir / "SCENE.json") && fs::equivalent(out_dir / "SCENE.json", fs::path(input)))
      throw InputError("-o", output, "the baked SCENE.json would overwrite the input scene: choose another folder");
    const std::vector<LightSpec> world_lights = lightsFromScene(input);
    std::optional<ReceiverSpec> ground = receiverFromScene(input);
    if (ground) ground->pitch_voxels = options_receiver_pitch;
    // Every object's volume is read and checked before anything is baked or written.
    std::vector<Volume> volumes;
    std::vector<std::string> sources, names;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
      const std::string key = "objects[" + std::to_string(i) + "].volume";
      const fs::path path = scene.resolve(key, scene.objects[i].volume);
      volumes.push_back(readVolume(path));
      sources.push_back(path.string());
      volumes.back().require("ior", 1, sources.back());
      iorGradient(volumes.back(), interfaceTable(volumes.back(), sources.back()), sources.back());
      // Scaled differently along its axes: baked (and written) as the volume at world scale along
      // each axis, placed with scale 1 in the baked SCENE.json (scene_bake.h takeInAxisScale); the
      // maps it held are baked anew.
      takeInAxisScale(volumes.back(), scene.objects[i]);
      std::string stem = path.filename().string();
      for (const char* suffix : {".vol.json", ".json"})
        if (stem.size() > std::strlen(suffix) && stem.ends_with(suffix)) {
          stem.resize(stem.size() - std::strlen(suffix));
          break;
        }
      if (stem.ends_with(".baked")) stem.resize(stem.size() - 6);
      std::string name = stem + ".baked.vol.json";
      for (int k = 2; std::find(names.begin(), names.end(), name) != names.end(); ++k)
        name = stem + "-" + std::to_string(k) + ".baked.vol.json";
      names.push_back(name);
    }
    // The objects in the order the light meets them, each handing on what leaves its box
    // (scene_bake.h SceneLightChain).
    std::vector<SceneLightChain::Object> boxes;
    for (std::size_t i = 0; i < volumes.size(); ++i) {
      SceneLightChain::Object box;
      box.frame = BakeFrame::of(scene.objects[i]);
      GridSpec grid = volumes[i].grid;
      grid.bounds_min *= box.frame.scale;
      grid.bounds_max *= box.frame.scale;
      propagationBox(grid, options, box.lo, box.hi);
      box.h = voxelEdge(grid);
      boxes.push_back(box);
    }
    // A dispersive object anywhere: every object is baked band by band (what it hands on differs
    // per band), a chain per band.
    const bool dispersive = std::any_of(volumes.begin(), volumes.end(), [](const Volume& v) { return isDispersive(v); });
    const std::vector<SpectralBand> bands = dispersive ? spectralBands(band_count) : spectralBands(1);
    // Every light in turn, each with the objects in the order it meets them and a chain per run
    // (band × direction of its disc); each object's bakes under the lights summed, and written
    // (its volume, simulator and sums let go) after the last light's run: with one light, one object
    // at a time holds its memory, as before several lights were baked.
    const std::vector<BakeLight> lights = bakeLights(world_lights);
    std::vector<std::vector<BakeLight>> object_lights(volumes.size());  // in each object's bake frame
    std::vector<SimulationOptions> object_options(volumes.size(), options);
    std::vector<std::unique_ptr<VolumeBake>> bakes(volumes.size());  // made at an object's first run
    for (std::size_t i = 0; i < volumes.size(); ++i) {
      const BakeFrame frame = BakeFrame::of(scene.objects[i]);
      for (const BakeLight& l : lights) {
        BakeLight in_frame{frame.light(l.light), {}};
        for (const LightSpec& direction : l.directions) in_frame.directions.push_back(frame.light(direction));
        object_lights[i].push_back(in_frame);
      }
      if (ground) object_options[i].receiver = frame.receiver(*ground);
    }
    fs::create_directories(out_dir);
    Scene baked = scene;
    std::vector<BandSum> sums(volumes.size());
    for (std::size_t l = 0; l < lights.size(); ++l) {
      std::vector<SceneLightChain> chains;
      for (std::size_t b = 0; b < bands.size(); ++b)
        for (const LightSpec& direction : lights[l].directions)
          chains.emplace_back(boxes, direction, ground, lights[l].light);
      const SceneLightChain& chain = chains.front();
      for (std::size_t step = 0; step < volumes.size(); ++step) {
        const std::size_t i = chain.order()[step];
        if (!quiet) {
          const std::string which =
              lights.size() > 1 ? "light " + std::to_string(l + 1) + "/" + std::to_string(lights.size()) + ", " : "";
          std::fprintf(stderr, "lightsim: [%sobject %zu/%zu] %s\n", which.c_str(), step + 1, volumes.size(),
                       sources[i].c_str());
        }
        RunHooks hooks;
        hooks.before = [&](std::size_t run, SimulationOptions& o) { chains[run].attach(i, o); };
        hooks.after = [&](std::size_t run, BakeResult& result) {
          chains[run].correctMap(i, result);
          if (run + 1 < chains.size() || quiet) return;
          SceneLightChain::Exchange x;  // over the bands
          for (const SceneLightChain& c : chains) x += c.exchange(i);
          if (x.taken_in > 0)
            std::fprintf(stderr, "lightsim: from the objects before it: %zu patches (%.4g W) taken in\n", x.taken_in,
                         luminance(x.flux_in));
          if (x.passed > 0)
            std::fprintf(stderr, "lightsim: %zu patches (%.4g W) sent on too dim to follow: they pass unchanged\n",
                         x.passed, luminance(x.flux_passed));
          if (x.left_out > 0)
            std::fprintf(stderr, "lightsim: %zu of the light's cells (%.4g W) in their shade\n", x.left_out,
                         luminance(x.flux_left_out));
        };
        if (!bakes[i])
          bakes[i] = prepare(volumes[i], sources[i], object_lights[i], object_options[i],
                             BakeFrame::of(scene.objects[i]).scale, bands);
        ProgressBar bar("lightsim", !quiet);
        sums[i].add(runLight(*bakes[i], object_lights[i][l], bands, hooks, bar.callback()));
        bar.finish();
        if (l + 1 < lights.size()) continue;
        write(*bakes[i], sums[i].finish(), object_lights[i], bands, (out_dir / names[i]).string(), "", nlohmann::json());
        bakes[i].reset();
        sums[i] = BandSum();
        volumes[i] = Volume();
        baked.objects[i].volume = names[i];
      }
    }
    if (!scene.environment.file.empty()) {
      const fs::path from = scene.resolve("environment.file", scene.environment.file);
      const fs::path to = out_dir / from.filename();
      if (!fs::exists(to) || !fs::equivalent(from, to)) fs::copy_file(from, to, fs::copy_options::overwrite_existing);
      baked.environment.file = from.filename().string();
    }
    writeScene(baked, out_dir / "SCENE.json");
    if (!quiet) std::fprintf(stderr, "lightsim: wrote %s\n", (out_dir / "SCENE.json").string().c_str());
    return kExitOk;
  }
  if (output.size() < 9 || output.substr(output.size() - 9) != ".vol.json")
    throw InputError("-o", output, "the output manifest must end in .vol.json");
  for (const std::string* path : {&output, &stats_path}) {
    if (path->empty()) continue;
    fs::path dir = fs::absolute(*path).parent_path();
    if (!fs::is_directory(dir)) throw InputError(*path, "", "directory " + dir.string() + " does not exist");
  }
  if (light_text.empty() == scene_path.empty())
    throw InputError("command line", "--light", "give either --light (with --power) or --scene");
  // --light, or every light of the --scene (summed).
  const std::vector<LightSpec> lights_to_bake =
      scene_path.empty() ? std::vector<LightSpec>{parseLight(light_text, power_text)} : lightsFromScene(scene_path);
  if (!receiver_text.empty() && no_receiver)
    throw InputError("command line", "--no-receiver", "give --receiver or --no-receiver, not both");
  if (!receiver_text.empty()) {
    options.receiver = parseReceiver(receiver_text);
  } else if (!scene_path.empty() && !no_receiver) {
    options.receiver = receiverFromScene(scene_path);
  }
  if (options.receiver) options.receiver->pitch_voxels = options_receiver_pitch;
  // The CPU twin reads no n or ∇n where every material is sharp with a constant n (VolumeSampler):
  // then those fields stay in their files, copied into the output as they are.
  VolumeReadOptions read_options;
  {
    const Volume header = readVolumeHeader(input);
    const InterfaceTable table = interfaceTable(header, input);
    SimulatorBackendOptions twin;
    twin.backend = backend == "cpu" ? SimulatorBackend::Cpu : backend == "auto" ? SimulatorBackend::Auto : SimulatorBackend::Gl;
    twin.gl = gl_backend;
    const bool constant_n = constantSlots(table) && std::none_of(table.slots.begin(), table.slots.end(),
                                                                 [](const InterfaceSlot& s) { return s.dispersion_b != 0.0; });
    if (constant_n && !header.has("dispersion") && takesCpuTwinUnprobed(twin))
      for (const char* name : {"ior", "ior_grad"})
        if (header.has(name)) read_options.leave_unread.push_back(name);  // ∇n may be left out (voxelize)
  }
  Volume volume = readVolume(input, read_options);
  if (const auto unread = volume.unread_fields.find("ior"); unread == volume.unread_fields.end()) {
    volume.require("ior", 1, input);  // read, or named as missing
  } else if (unread->second != 1) {
    throw InputError(input, "ior", std::to_string(unread->second) + " components, expected 1");
  }
  // A malformed table is named with the file, before any work; ∇n read, left unread, or left out
  // where the table says it is 0 throughout.
  iorGradient(volume, interfaceTable(volume, input), input);
  const std::vector<SpectralBand> bands = isDispersive(volume) ? spectralBands(band_count) : spectralBands(1);
  const std::vector<BakeLight> lights = bakeLights(lights_to_bake);
  std::unique_ptr<VolumeBake> bake = prepare(volume, input, lights, options, 1.0, bands, true);
  // The simulator (one band: made once) holds its own copy of every field it samples (the CPU twin
  // took the distances' data itself). The volume's fields go now, as if left unread: writeVolume carries their files into the output as they are,
  // and the bake's own memory reuses theirs instead of fresh pages (at 128³ the sphere's distances,
  // 9 MB).
  if (bake->simulator)
    for (auto it = volume.fields.begin(); it != volume.fields.end();) {
      if (volume.field_files.count(it->first) == 0) {
        ++it;
        continue;
      }
      volume.unread_fields[it->first] = it->second.components;
      it = volume.fields.erase(it);
    }
  BakeResult result;
  std::vector<double> seconds;
  for (int run = 0; run < std::max(1, bench_runs); ++run) {
    ProgressBar bar("lightsim", !quiet && bench_runs == 0);
    const ProgressFn progress = bar.callback();
    const Stopwatch watch;
    BandSum sum;
    for (std::size_t l = 0; l < lights.size(); ++l) {
      ProgressFn light_progress;
      if (progress)
        light_progress = [&, l](double f) { progress((static_cast<double>(l) + f) / static_cast<double>(lights.size())); };
      sum.add(runLight(*bake, lights[l], bands, {}, light_progress));
    }
    result = sum.finish();
    seconds.push_back(watch.seconds());
    bar.finish();
    if (bench_runs > 0 && !quiet)
      std::fprintf(stderr, "lightsim: bench run %d of %d: %.3f s\n", run + 1, bench_runs, seconds.back());
  }
  nlohmann::json stats_json = nlohmann::json::object();
  if (bench_runs > 0) {
    std::vector<double> sorted = seconds;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted.size() % 2 ? sorted[sorted.size() / 2]
                                            : 0.5 * (sorted[sorted.size() / 2 - 1] + sorted[sorted.size() / 2]);
    const double rate = static_cast<double>(result.stats.total_patches) / median;
    stats_json["bench"] = {{"runs", bench_runs},
                           {"seconds", seconds},
                           {"median_s", median},
                           {"patch_steps_per_s", rate},
                           {"grid", {volume.grid.dims.x, volume.grid.dims.y, volume.grid.dims.z}}};
    const nlohmann::json backend_stats = bake->simulator->lastRunStats();
    std::printf(
        "lightsim bench: %dx%dx%d, %s: median %.3f s of %d runs (min %.3f, max %.3f); %llu patch-steps, "
        "%.3g patch-steps/s; peak %llu patches",
        volume.grid.dims.x, volume.grid.dims.y, volume.grid.dims.z, rendererName(result.stats).c_str(), median,
        bench_runs, sorted.front(), sorted.back(), static_cast<unsigned long long>(result.stats.total_patches), rate,
        static_cast<unsigned long long>(result.stats.peak_patches));
    if (backend_stats.contains("texture_bytes"))
      std::printf("; %.1f MiB of textures at the peak",
                  static_cast<double>(backend_stats["texture_bytes"]["total_peak"].get<std::size_t>()) / (1 << 20));
    std::printf("\n");
  }
  write(*bake, std::move(result), lights, bands, output, stats_path, stats_json);
  return kExitOk;
}

}  // namespace
}  // namespace eik

int main(int argc, char** argv) { return eik::runMain("lightsim", eik::run, argc, argv); }
