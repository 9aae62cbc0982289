// viewer: renders refractive volumes along curved rays (thesis §5, §6.3; DESIGN §4.2).
//
//   viewer SCENE.json | VOLUME.vol.json [--render OUT.exr|OUT.png] [--size WxH]
//          [--camera EX,EY,EZ:TX,TY,TZ:FOVY_DEG] [--env uniform:R,G,B | checker:R,G,B]
//
// This is the viewer's first form: headless rendering through OSMesa/EGL of one object with
// refraction, attenuation, emission and opaque embeddings. The interactive window, Fresnel,
// scattering, dispersion and several objects come with the viewer issue.
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "core/cli.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/scene.h"
#include "core/volume.h"
#include "gl/context.h"
#include "gl/shader_library.h"
#include "viewer/camera.h"
#include "viewer/refractive_renderer.h"

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

// "uniform:R,G,B" or "checker:R,G,B" (bright cells); a bare "checker" is white.
void parseEnvironment(const std::string& text, RenderSettings& settings) {
  const auto colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  if (kind != "uniform" && kind != "checker")
    throw InputError("--env", text, "expected uniform:R,G,B or checker:R,G,B (environment maps come with the viewer issue)");
  settings.environment_checker = kind == "checker";
  settings.environment = glm::vec3(1.0f);
  if (colon == std::string::npos) return;
  std::istringstream in(text.substr(colon + 1));
  char c1 = 0, c2 = 0;
  glm::vec3 v;
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() || v.x < 0 ||
      v.y < 0 || v.z < 0)
    throw InputError("--env", text, "the colour must be three non-negative numbers R,G,B");
  settings.environment = v;
}

glm::dmat4 objectToWorld(const SceneObjectSpec& o) {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), o.translate);
  m = glm::rotate(m, glm::radians(o.rotate_deg.z), glm::dvec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(o.rotate_deg.y), glm::dvec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(o.rotate_deg.x), glm::dvec3(1, 0, 0));
  return glm::scale(m, glm::dvec3(o.scale));
}

int run(int argc, char** argv) {
  std::string input, output, size_text, camera_text, env_text, tonemap_text, gl_backend = "auto";
  double step = 0.5, exposure = 0.0;
  bool quiet = false;
  CLI::App app{"viewer: render refractive volumes along curved rays (thesis §5, §6.3)", "viewer"};
  app.add_option("input", input, "SCENE.json or VOLUME.vol.json")->required();
  app.add_option("--render", output, "render headless into OUT.exr (linear) or OUT.png (tone-mapped)");
  app.add_option("--size", size_text, "image size WxH (default: the scene's render.size, else 512x512)");
  app.add_option("--camera", camera_text, "EX,EY,EZ:TX,TY,TZ:FOVY_DEG (default: the scene's camera, or framing the volume)");
  app.add_option("--env", env_text, "uniform:R,G,B or checker:R,G,B (default: the scene's uniform environment, else white)");
  app.add_option("--step", step, "ray step in voxels (default: the scene's render.step_voxels, else 0.5)")->check(CLI::Range(0.01, 4.0));
  app.add_option("--exposure", exposure, "exposure in EV for PNG output (default: the scene's render.exposure, else 0)");
  app.add_option("--tonemap", tonemap_text, "aces | reinhard | linear, for PNG output (default: the scene's render.tonemap, else aces)");
  app.add_option("--gl", gl_backend, "OpenGL back end: auto | osmesa | egl (default auto: OSMesa, then EGL)");
  app.add_flag("-q,--quiet", quiet, "print nothing but errors");
  app.footer("Exit codes: 0 success, 1 runtime failure, 2 bad usage or bad input.");
  if (!parseCommandLine(app, argc, argv)) return kExitOk;
  if (output.empty())
    throw InputError("command line", "--render",
                     "the interactive window is not built yet: give --render OUT.png (or OUT.exr)");
  {
    std::string ext = fs::path(output).extension().string();
    if (ext != ".png" && ext != ".exr") throw InputError("--render", output, "the output must end in .png or .exr");
    fs::path dir = fs::absolute(output).parent_path();
    if (!fs::is_directory(dir)) throw InputError("--render", output, "directory " + dir.string() + " does not exist");
  }

  // The scene: a SCENE.json, or a volume alone with a camera that frames it.
  Scene scene;
  fs::path volume_path;
  const bool is_scene = input.size() < 9 || input.substr(input.size() - 9) != ".vol.json";
  if (is_scene) {
    scene = readScene(input);
    if (scene.objects.empty()) throw InputError(input, "objects", "the scene has no object");
    if (scene.objects.size() > 1 && !quiet)
      std::fprintf(stderr, "viewer: warning: %s: rendering only objects[0] (several objects come with the viewer issue)\n",
                   input.c_str());
    volume_path = scene.resolve(scene.objects[0].volume);
  } else {
    volume_path = input;
    scene.objects.push_back(SceneObjectSpec{input});
  }
  const ToneMapper tonemap =
      parseToneMapper(!tonemap_text.empty() ? tonemap_text : is_scene ? scene.render.tonemap : "aces");
  Volume volume = readVolume(volume_path);
  volume.require("ior", 1, volume_path.string());
  volume.require("ior_grad", 3, volume_path.string());

  Camera camera;
  if (!camera_text.empty()) {
    camera = parseCamera(camera_text);
  } else if (is_scene) {
    camera = Camera::fromSpec(scene.camera);
  } else {
    const glm::dvec3 center = 0.5 * (volume.grid.bounds_min + volume.grid.bounds_max);
    const double radius = 0.5 * glm::length(volume.grid.extent());
    camera.target = center;
    camera.eye = center + glm::dvec3(0.0, 0.35, 1.0) * (radius / std::sin(glm::radians(camera.fov_y_deg / 2)));
  }
  glm::ivec2 size = size_text.empty() ? (is_scene ? scene.render.size : glm::ivec2(512, 512)) : parseSize(size_text);

  RenderSettings settings;
  settings.step_voxels = is_scene && app.count("--step") == 0 ? scene.render.step_voxels : step;
  if (!env_text.empty())
    parseEnvironment(env_text, settings);
  else if (is_scene && scene.environment.uniform)
    settings.environment = glm::vec3(*scene.environment.uniform * scene.environment.intensity);

  gl::ContextOptions context_options;
  context_options.backend = gl::parseGlBackend(gl_backend);
  gl::GlContext context(context_options);
  gl::ShaderLibrary shaders;
  RefractiveRenderer renderer(shaders, volume, settings, volume_path.string());
  Image image = renderer.render(camera, size, objectToWorld(scene.objects[0]));
  ImageWriteOptions write;
  write.exposure_ev = static_cast<float>(is_scene && app.count("--exposure") == 0 ? scene.render.exposure : exposure);
  write.tonemap = tonemap;
  writeImage(output, image, write);
  if (!quiet) std::fprintf(stderr, "viewer: wrote %s (%dx%d) with %s\n", output.c_str(), size.x, size.y, context.summary().c_str());
  return kExitOk;
}

}  // namespace
}  // namespace eik

int main(int argc, char** argv) { return eik::runMain("viewer", eik::run, argc, argv); }
