// viewer: renders refractive volumes along curved rays (thesis §5, §6.3; docs/programs.md).
//
//   viewer SCENE.json | VOLUME.vol.json [--render OUT.exr|OUT.png] [--size WxH]
//          [--camera EX,EY,EZ:TX,TY,TZ:FOVY_DEG] [--env FILE | uniform:R,G,B | checker[:R,G,B] | sky]
//          [--step VOXELS] [--integrator euler|rk4] [--no-refraction] [--no-fresnel] [--no-scattering]
//          [--no-attenuation] [--no-emission] [--no-dispersion] [--no-ground] [--no-skip]
//          [--no-reflect-objects] [--bands N] [--every-band]
//
//   viewer SCENE.json | VOLUME.vol.json            (no --render: the interactive window, viewer/window.h)
//          [--window-frames N --save OUT.exr|OUT.png ...]   (scripted window, for tests)
//   viewer SCENE.json | VOLUME.vol.json --bench FRAMES [--size WxH] [--stats FILE.json]  (viewer/bench.h)
//
// Headless rendering goes through OSMesa/EGL and viewer/scene_renderer.h (the image formation of
// thesis §5 over every object of the scene, the ground and the environment).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "core/cli.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "core/scene.h"
#include "core/volume.h"
#include "gl/context.h"
#include "gl/shader_library.h"
#include "viewer/camera.h"
#include "viewer/environment.h"
#include "viewer/loaded_scene.h"
#include "viewer/render_settings.h"
#include "viewer/scene_renderer.h"
#include "viewer/bench_mode.h"
#include "viewer/window.h"

namespace fs = std::filesystem;

namespace eik {
namespace {

glm::ivec2 parseSize(const std::string& text) {
  int w = 0, h = 0;
  char x = 0;
  std::istringstream in(text);
  if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || !(in >> std::ws).eof() || w < 1 || h < 1 || w > 16384 ||
      h > 16384)
    throw InputError("--size", text, "expected WxH with 1..16384 pixels per axis, e.g. 512x512");
  return {w, h};
}

int run(int argc, char** argv) {
  std::string input, output, size_text, camera_text, env_text, tonemap_text, gl_backend = "auto";
  std::string integrator_text = "euler", output_text = "radiance";
  double step = 0.5, exposure = 0.0;
  bool quiet = false;
  bool no_refraction = false, no_scattering = false, no_fresnel = false, no_attenuation = false,
       no_emission = false, no_dispersion = false, no_ground = false, no_skip = false, bricks = false,
       no_reflect_objects = false;
  CLI::App app{"viewer: render refractive volumes along curved rays (thesis §5, §6.3)", "viewer"};
  app.add_option("input", input, "SCENE.json or VOLUME.vol.json")->required();
  app.add_option("--render", output, "render headless into OUT.exr (linear) or OUT.png (tone-mapped)");
  app.add_option("--size", size_text, "image size WxH (default: the scene's render.size, else 512x512)");
  app.add_option("--camera", camera_text, "EX,EY,EZ:TX,TY,TZ:FOVY_DEG (default: the scene's camera, or framing the volume)");
  app.add_option("--env", env_text,
                 "FILE (equirectangular .exr, .hdr or .png) | uniform:R,G,B | checker[:R,G,B] | sky "
                 "(default: the scene's environment, else white)");
  app.add_option("--step", step, "ray step in voxels (default: the scene's render.step_voxels, else 0.5)")->check(CLI::Range(0.01, 4.0));
  app.add_option("--integrator", integrator_text, "ray integrator: euler | rk4 (default euler)");
  app.add_option("--output", output_text,
                 "radiance (default) | exit-position | exit-direction: where (world) and in which direction "
                 "each pixel's ray left the last volume, alpha 1 where it went through one (EXR)")
      ->check(CLI::IsMember({"radiance", "exit-position", "exit-direction"}));
  app.add_flag("--no-refraction", no_refraction, "straight viewing rays");
  app.add_flag("--no-scattering", no_scattering, "leave out in-scattering of the baked light");
  app.add_flag("--no-fresnel", no_fresnel, "leave out Fresnel reflection and transmission at boundaries");
  app.add_flag("--no-attenuation", no_attenuation, "leave out Beer-Lambert absorption");
  app.add_flag("--no-emission", no_emission, "leave out emission");
  app.add_flag("--no-dispersion", no_dispersion, "one ray for R, G and B even where a dispersion field exists");
  int bands = 0;
  app.add_option("--bands", bands,
                 "spectral bands of the dispersion, 3 (R, G, B) or 4..16 weighted by the CIE 1931 functions, as "
                 "lightsim --bands (default: the bands the objects were baked with, else 3)")
      ->check(CLI::Range(3, 16));
  bool every_band = false;
  app.add_flag("--every-band", every_band,
               "with 4..16 bands, trace every band (default: trace the spectrum's two ends and interpolate the "
               "bands between them where both took the same way through the glass)");
  app.add_flag("--no-ground", no_ground, "leave out the scene's ground plane");
  app.add_flag("--no-reflect-objects", no_reflect_objects,
               "reflections see the ground and the environment only (default: the first reflection off an "
               "object's outside is traced through the other objects and onto the ground)");
  app.add_flag("--no-skip", no_skip, "no empty-space skipping: march the whole box of every volume, and at most a voxel a step between sharp surfaces");
  app.add_flag("--bricks", bricks, "cross homogeneous 4x4x4-voxel bricks in one step (off: on llvmpipe it rarely pays)");
  app.add_option("--exposure", exposure, "exposure in EV for PNG output (default: the scene's render.exposure, else 0)");
  app.add_option("--tonemap", tonemap_text, "aces | reinhard | linear, for PNG output (default: the scene's render.tonemap, else aces)");
  app.add_option("--gl", gl_backend, "OpenGL back end: auto | osmesa | egl (default auto: OSMesa, then EGL)");
  int bench_frames = 0, window_frames = 0;
  std::string stats_path;
  std::vector<std::string> save_paths;
  app.add_option("--bench", bench_frames,
                 "time FRAMES frames headless at --size, and a bare refractive march of the same volume")
      ->check(CLI::Range(1, 100000));
  app.add_option("--stats", stats_path, "with --bench: write the figures as JSON");
  app.add_option("--window-frames", window_frames, "window: render N frames, write --save and close (tests)")
      ->check(CLI::Range(1, 100000))
      ->group("Scripted window (tests, screenshots)");
  app.add_option("--save", save_paths,
                 "with --window-frames: OUT.exr (the window's linear image) or OUT.png (its screen pixels); repeatable")
      ->allow_extra_args(false)
      ->group("Scripted window (tests, screenshots)");
  std::vector<double> window_light;
  app.add_option("--window-light", window_light,
                 "with --window-frames: after the first frame, move the light to AZ,EL degrees (as the panel's "
                 "sliders do) and save once its re-bake has landed")
      ->delimiter(',')
      ->expected(2)
      ->group("Scripted window (tests, screenshots)");
  double window_orbit = 0.0;
  app.add_option("--window-orbit", window_orbit,
                 "with --window-frames: every frame but the first and last drags the camera PIXELS sideways (as the "
                 "mouse does: rendered at a quarter of the resolution per axis), then prints the drag frames' median "
                 "frame time and fps (the orbit's frame rate)")
      ->check(CLI::Range(-1000.0, 1000.0))
      ->group("Scripted window (tests, screenshots)");
  bool no_rebake = false;
  app.add_flag("--no-rebake", no_rebake,
               "window: the light sliders move only the unbaked light (ground, sun), no background re-bake");
  std::string save_ui;
  app.add_option("--save-ui", save_ui, "with --window-frames: OUT.png of the screen with the controls panel")
      ->group("Scripted window (tests, screenshots)");
  app.add_flag("-q,--quiet", quiet, "print nothing but errors");
  app.footer(
      "Without --render or --bench the viewer opens a window (needs a display): drag to orbit, right-drag to\n"
      "pan, wheel to zoom, S saves EXR + PNG, R resets the camera,\n"
      "H hides the panel, Esc or Q quits.\n"
      "Examples:\n"
      "  viewer scene.json                                  (the window)\n"
      "  viewer scene.json --render out.png --size 800x600  (headless)\n"
      "  viewer glass.baked.vol.json --render out.exr --env sky\n"
      "  viewer scene.json --bench 20 --size 512x512 --stats bench.json\n"
      "Exit codes: 0 success, 1 runtime failure, 2 bad usage or bad input.");
  addOutsidePathsFlag(app);
  if (!parseCommandLine(app, argc, argv)) return kExitOk;
  const bool bench = app.count("--bench") > 0;
  const bool window_mode = output.empty() && !bench;
  if (bench && !output.empty())
    throw InputError("command line", "--bench", "--bench and --render are separate runs: give one");
  if (!stats_path.empty() && !bench)
    throw InputError("command line", "--stats", "the viewer writes --stats with --bench only");
  if ((window_frames > 0) != !save_paths.empty())
    throw InputError("command line", "--save", "--window-frames N and --save OUT go together");
  if (window_frames > 0 && !window_mode)
    throw InputError("command line", "--window-frames", "is for the window: leave out --render and --bench");
  if (window_orbit != 0.0 && window_frames < 3)
    throw InputError("command line", "--window-orbit", "goes with --window-frames N (N >= 3) and --save OUT");
  if (!window_light.empty() && window_frames == 0)
    throw InputError("command line", "--window-light", "goes with --window-frames N and --save OUT");
  if (!window_light.empty() && (!std::isfinite(window_light[0]) || !(std::fabs(window_light[1]) <= 89.0)))
    throw InputError("command line", "--window-light", "expected AZ,EL in degrees with |EL| <= 89");
  if (!window_light.empty() && no_rebake)
    throw InputError("command line", "--window-light", "needs the re-bake: leave out --no-rebake");
  for (const std::string& path : save_paths) {
    std::string ext = fs::path(path).extension().string();
    if (ext != ".png" && ext != ".exr") throw InputError("--save", path, "the output must end in .png or .exr");
    if (!fs::is_directory(fs::absolute(path).parent_path()))
      throw InputError("--save", path, "its directory does not exist");
  }
  if (!stats_path.empty() && !fs::is_directory(fs::absolute(stats_path).parent_path()))
    throw InputError("--stats", stats_path, "its directory does not exist");
  if (window_mode && !gl::displayAvailable())
    throw InputError("command line", "--render",
                     "no display for the viewer's window (DISPLAY and WAYLAND_DISPLAY are unset): give --render OUT.png "
                     "(or OUT.exr) to render headless");
  if (!output.empty()) {
    std::string ext = fs::path(output).extension().string();
    if (ext != ".png" && ext != ".exr") throw InputError("--render", output, "the output must end in .png or .exr");
    fs::path dir = fs::absolute(output).parent_path();
    if (!fs::is_directory(dir)) throw InputError("--render", output, "directory " + dir.string() + " does not exist");
  }

  // The scene: a SCENE.json, or a volume alone with a camera that frames it.
  RenderSettings settings;
  settings.integrator = parseRayIntegrator(integrator_text);
  // Rendering headless, the OpenGL driver loads while the scene is read.
  gl::ContextOptions context_options;
  context_options.backend = gl::parseGlBackend(gl_backend);
  std::optional<gl::DriverPreload> preload;
  if (!window_mode) {
    startWorkerThreads();  // before the driver's load, which would hold up their start (parallel.h)
    preload.emplace(context_options);
  }
  SceneLoadOptions load_options;
  load_options.leave_constant_optics_unread = !output.empty() && !bench;  // a headless render
  LoadedScene scene = loadScene(input, load_options);
  const bool is_scene = !scene.bare_volume;
  const ToneMapper tonemap =
      parseToneMapper(!tonemap_text.empty() ? tonemap_text : is_scene ? scene.scene.render.tonemap : "aces");
  if (!env_text.empty()) {
    applyEnvironmentFlag(env_text, scene.scene.environment);
    if (!scene.scene.environment.file.empty())
      scene.scene.environment.file = fs::absolute(scene.scene.environment.file).string();
  }

  Camera camera = camera_text.empty() ? scene.camera() : parseCamera(camera_text);
  glm::ivec2 size = size_text.empty() ? scene.scene.render.size : parseSize(size_text);

  settings.step_voxels = is_scene && app.count("--step") == 0 ? scene.scene.render.step_voxels : step;
  settings.refraction = !no_refraction;
  settings.scattering = !no_scattering;
  settings.fresnel = !no_fresnel;
  settings.attenuation = !no_attenuation;
  settings.emission = !no_emission;
  settings.dispersion = !no_dispersion;
  // The bands the bake used (its manifest's bake_bands), so that the glass shows the spectrum its
  // caustic was baked in; 3 when none says more.
  settings.bands = 3;
  for (const LoadedObject& object : scene.objects)
    if (const auto it = object.volume.metadata.find("bake_bands"); it != object.volume.metadata.end() && it->is_number_integer())
      settings.bands = std::clamp(std::max(settings.bands, it->get<int>()), 3, 16);
  if (app.count("--bands")) settings.bands = bands;
  settings.interpolate_bands = !every_band;
  settings.ground = !no_ground;
  settings.reflect_objects = !no_reflect_objects;
  settings.skip_empty_space = !no_skip;
  settings.homogeneous_bricks = bricks;
  settings.output = output_text == "exit-position"    ? RenderOutput::ExitPosition
                    : output_text == "exit-direction" ? RenderOutput::ExitDirection
                                                      : RenderOutput::Radiance;

  const float exposure_ev =
      static_cast<float>(is_scene && app.count("--exposure") == 0 ? scene.scene.render.exposure : exposure);
  if (bench) {
    BenchOptions options;
    options.frames = bench_frames;
    options.size = size;
    options.stats_path = stats_path;
    options.backend = gl::parseGlBackend(gl_backend);
    options.quiet = quiet;
    return runBenchMode(scene, settings, camera, options);
  }
  if (window_mode) {
    WindowOptions options;
    options.size = size;
    options.title = "Eikonal viewer: " + input;
    options.exposure_ev = exposure_ev;
    options.tonemap = tonemap;
    options.scripted_frames = window_frames;
    options.save.assign(save_paths.begin(), save_paths.end());
    options.save_ui = save_ui;
    if (!window_light.empty()) options.scripted_light = glm::dvec2(window_light[0], window_light[1]);
    options.rebake = !no_rebake;
    options.scripted_orbit_px = window_orbit;
    options.quiet = quiet;
    return runViewerWindow(scene, settings, camera, options);
  }

  // The ground's texels on the CPU while the driver may still be loading, then the context.
  SceneRenderer::Preparation prepared = SceneRenderer::prepare(scene);
  SceneRenderer::releasePrepared(scene, prepared);
  gl::GlContext context(context_options);
  gl::ShaderLibrary shaders;
  SceneRenderer renderer(shaders, scene, settings, &prepared);
  prepared = {};  // uploaded: the render's own memory reuses it
  Image image = renderer.render(camera, size);
  ImageWriteOptions write;
  write.exposure_ev = exposure_ev;
  write.tonemap = tonemap;
  writeImage(output, image, write);
  if (!quiet) std::fprintf(stderr, "viewer: wrote %s (%dx%d) with %s\n", output.c_str(), size.x, size.y, context.summary().c_str());
  return kExitOk;
}

}  // namespace
}  // namespace eik

int main(int argc, char** argv) { return eik::runMain("viewer", eik::run, argc, argv); }
