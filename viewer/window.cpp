#include "viewer/window.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>

#include "core/error.h"
#include "core/image_io.h"
#include "core/stopwatch.h"
#include "gl/context.h"
#include "gl/framebuffer.h"
#include "gl/shader_library.h"
#include "viewer/background_bake.h"
#include "viewer/bench.h"
#include "viewer/display_pass.h"
#include "viewer/orbit_camera.h"
#include "viewer/scene_renderer.h"

namespace fs = std::filesystem;

namespace eik {

namespace {

// An orthonormal pair perpendicular to `up` (unit): the azimuth's 0° and 90° directions.
void perpendicularPair(const glm::dvec3& up, glm::dvec3& a, glm::dvec3& b) {
  const glm::dvec3 other = std::abs(up.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
  a = glm::normalize(glm::cross(glm::cross(up, other), up));  // `other` projected into the plane
  b = glm::cross(up, a);
}

glm::dvec3 unitOr(const glm::dvec3& v, const glm::dvec3& fallback) {
  return glm::length(v) > 1e-12 ? glm::normalize(v) : fallback;
}

// Dear ImGui on a GLFW window, shut down with the object.
class ImGuiLayer {
 public:
  explicit ImGuiLayer(GLFWwindow* window) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the user's directory
    ImGui::StyleColorsDark();
    if (!ImGui_ImplGlfw_InitForOpenGL(window, true)) throw RuntimeError("Dear ImGui: GLFW back end failed to start");
    if (!ImGui_ImplOpenGL3_Init("#version 330 core")) {
      ImGui_ImplGlfw_Shutdown();
      throw RuntimeError("Dear ImGui: OpenGL 3 back end failed to start");
    }
  }
  ~ImGuiLayer() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;

  void newFrame() {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
  }
  void render() {
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  }
};

// The back buffer as the display pass left it (sRGB-encoded values k/255), written as a PNG
// holding exactly those 8-bit values: writeImage encodes linear → sRGB, so decode first (the
// round trip is exact to far below half a step).
void writeScreenPng(const fs::path& path, glm::ivec2 size) {
  Image image;
  image.width = size.x;
  image.height = size.y;
  image.channels = 4;
  image.pixels = gl::readDefaultFramebufferRGBA(size, GL_BACK);
  gl::flipRows(image.pixels, size.x, 4);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    if (i % 4 == 3) continue;
    const float v = std::clamp(image.pixels[i], 0.0f, 1.0f);
    image.pixels[i] = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
  }
  ImageWriteOptions write;
  write.tonemap = ToneMapper::Linear;
  write.exposure_ev = 0.0f;
  writeImage(path, image, write);
}

struct Shot {
  fs::path exr, png;
};

Shot nextShotPaths(const fs::path& prefix) {
  for (int i = 1;; ++i) {
    char number[16];
    std::snprintf(number, sizeof number, "-%03d", i);
    Shot shot{prefix.string() + number + ".exr", prefix.string() + number + ".png"};
    if (!fs::exists(shot.exr) && !fs::exists(shot.png)) return shot;
  }
}

const char* const kToneMapperNames[] = {"linear", "reinhard", "aces"};
ToneMapper toneMapperAt(int index) {
  return index == 0 ? ToneMapper::Linear : index == 1 ? ToneMapper::Reinhard : ToneMapper::Aces;
}

// The settings the panel edits.
bool sameControls(const RenderSettings& a, const RenderSettings& b) {
  return a.step_voxels == b.step_voxels && a.integrator == b.integrator && a.refraction == b.refraction &&
         a.scattering == b.scattering && a.fresnel == b.fresnel && a.attenuation == b.attenuation &&
         a.emission == b.emission && a.dispersion == b.dispersion && a.ground == b.ground &&
         a.skip_empty_space == b.skip_empty_space && a.reflect_objects == b.reflect_objects &&
         a.interpolate_bands == b.interpolate_bands;
}

}  // namespace

float nextDragScale(float scale, double render_ms, float max_scale) {
  const float top = std::max(kMinDragScale, max_scale);  // (a slider below the minimum: the minimum)
  const float kept = std::clamp(scale, kMinDragScale, top);
  if (!(render_ms > 0.0) || !std::isfinite(render_ms)) return kept;
  const float wanted = std::clamp(static_cast<float>(scale * std::sqrt(kDragRenderBudgetMs / render_ms)), kMinDragScale, top);
  return std::abs(wanted - scale) < 0.1f * scale ? kept : wanted;
}

glm::dvec3 lightDirectionFromAngles(double azimuth_deg, double elevation_deg, glm::dvec3 up) {
  up = unitOr(up, glm::dvec3(0, 1, 0));
  glm::dvec3 a, b;
  perpendicularPair(up, a, b);
  const double az = glm::radians(azimuth_deg), el = glm::radians(elevation_deg);
  const glm::dvec3 towards_light = std::cos(el) * (std::cos(az) * a + std::sin(az) * b) + std::sin(el) * up;
  return -towards_light;
}

glm::dvec2 lightAnglesFromDirection(glm::dvec3 travel_dir, glm::dvec3 up) {
  up = unitOr(up, glm::dvec3(0, 1, 0));
  glm::dvec3 a, b;
  perpendicularPair(up, a, b);
  const glm::dvec3 l = -unitOr(travel_dir, -up);
  const double elevation = std::asin(std::clamp(glm::dot(l, up), -1.0, 1.0));
  const double azimuth = std::atan2(glm::dot(l, b), glm::dot(l, a));
  return glm::degrees(glm::dvec2(azimuth, elevation));
}

int runViewerWindow(const LoadedScene& scene, const RenderSettings& initial_settings, const Camera& initial_camera,
                    const WindowOptions& options) {
  const bool scripted = options.scripted_frames > 0;
  gl::ContextOptions context_options;
  context_options.backend = gl::GlBackend::Window;
  context_options.size = glm::max(options.size, glm::ivec2(1));
  context_options.title = options.title;
  context_options.swapInterval = scripted ? 0 : 1;
  gl::GlContext context(context_options);
  GLFWwindow* window = context.window();
  if (!options.quiet) std::fprintf(stderr, "viewer: window with %s\n", context.summary().c_str());

  gl::ShaderLibrary shaders;
  SceneRenderer renderer(shaders, scene, initial_settings);
  DisplayPass display(shaders);
  ImGuiLayer imgui(window);

  RenderSettings settings = initial_settings;
  OrbitCamera orbit(initial_camera);
  float exposure = options.exposure_ev;
  int tonemap = static_cast<int>(options.tonemap == ToneMapper::Linear     ? 0
                                 : options.tonemap == ToneMapper::Reinhard ? 1
                                                                           : 2);
  const glm::dvec3 up = unitOr(initial_camera.up, glm::dvec3(0, 1, 0));
  glm::dvec2 light_angles = lightAnglesFromDirection(renderer.lightDirection(), up);
  float light_azimuth = static_cast<float>(light_angles.x);
  float light_elevation = static_cast<float>(glm::clamp(light_angles.y, -89.0, 89.0));
  float step = static_cast<float>(settings.step_voxels);
  float resolution_scale = 1.0f;
  bool show_panel = true;

  // The background re-bake of the scene's baked objects when the light moves.
  std::unique_ptr<BackgroundBake> rebake;
  if (options.rebake) rebake = std::make_unique<BackgroundBake>(scene);
  if (rebake && !rebake->enabled()) rebake.reset();
  std::string bake_line = rebake ? "bake: as loaded" : "";
  bool scripted_light_moved = false;
  int baked_frame = 0;  // scripted light: the last frame at which its re-bake was still under way

  gl::Framebuffer hdr;
  bool dirty = true;
  double render_ms = 0.0;
  double frame_ms = 0.0;
  std::string status;
  int frame = 0;
  Stopwatch frame_clock;  // since the last frame was shown
  float drag_scale = 0.25f;  // the resolution scale while dragging (nextDragScale)
  bool was_dragging = false;
  std::vector<double> orbit_frame_ms, orbit_render_ms;  // a scripted orbit's drag frames
  glm::ivec2 orbit_size(0);

  // S: the current view at the window's full size (whatever the resolution slider says), rendered
  // as `--render` renders it; a failure to write is shown, not fatal.
  auto save_shot = [&](glm::ivec2 size) {
    try {
      const Shot shot = nextShotPaths(options.shot_prefix);
      Image image = renderer.render(orbit.camera(), size);
      writeImage(shot.exr, image);
      ImageWriteOptions write;
      write.exposure_ev = exposure;
      write.tonemap = toneMapperAt(tonemap);
      writeImage(shot.png, image, write);
      status = "saved " + shot.exr.string() + " and " + shot.png.string();
    } catch (const std::exception& e) {
      status = std::string("could not save: ") + e.what();
    }
    if (!options.quiet) std::fprintf(stderr, "viewer: %s\n", status.c_str());
  };

  while (!context.shouldClose()) {
    if (scripted || dirty || (rebake && rebake->busy()))
      gl::GlContext::pollEvents();
    else
      glfwWaitEventsTimeout(0.1);  // nothing to render: sleep until input (or a tick for the panel)
    const glm::ivec2 fb = context.framebufferSize();
    if (fb.x <= 0 || fb.y <= 0) {  // minimised
      glfwWaitEvents();
      continue;
    }
    imgui.newFrame();
    ImGuiIO& io = ImGui::GetIO();

    // Camera and keys, unless the panel has them.
    if (!io.WantCaptureMouse) {
      const double h = std::max(1.0f, io.DisplaySize.y);
      const glm::dvec2 delta(io.MouseDelta.x, io.MouseDelta.y);
      const bool moved = delta.x != 0.0 || delta.y != 0.0;
      if (io.MouseDown[0] && !io.KeyShift && moved) orbit.orbitByPixels(delta.x, delta.y, h), dirty = true;
      if ((io.MouseDown[1] || io.MouseDown[2] || (io.MouseDown[0] && io.KeyShift)) && moved)
        orbit.panByPixels(delta.x, delta.y, h), dirty = true;
      if (io.MouseWheel != 0.0f) orbit.zoomBySteps(io.MouseWheel), dirty = true;
    }
    if (!io.WantCaptureKeyboard) {
      if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false) || ImGui::IsKeyPressed(GLFW_KEY_Q, false))
        glfwSetWindowShouldClose(window, GLFW_TRUE);
      if (ImGui::IsKeyPressed(GLFW_KEY_R, false)) orbit = OrbitCamera(initial_camera), dirty = true;
      if (ImGui::IsKeyPressed(GLFW_KEY_H, false)) show_panel = !show_panel;
    }

    // The panel.
    RenderSettings wanted = settings;
    bool save_requested = !io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_S, false);
    if (show_panel) {
      ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
      ImGui::SetNextWindowBgAlpha(0.8f);
      ImGui::Begin("Eikonal", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
      ImGui::PushItemWidth(110.0f);
      ImGui::Text("render %.1f ms  (%dx%d)", render_ms, hdr ? hdr.size().x : 0, hdr ? hdr.size().y : 0);
      ImGui::Text("frame %.1f ms", frame_ms);
      ImGui::Separator();
      ImGui::SliderFloat("exposure (EV)", &exposure, -10.0f, 10.0f, "%.2f");
      ImGui::Combo("tone map", &tonemap, kToneMapperNames, 3);
      bool light_changed = ImGui::SliderFloat("light azimuth", &light_azimuth, -180.0f, 180.0f, "%.0f deg");
      bool light_dragged = ImGui::IsItemActive();
      bool light_released = ImGui::IsItemDeactivatedAfterEdit();
      light_changed |= ImGui::SliderFloat("light elevation", &light_elevation, -89.0f, 89.0f, "%.0f deg");
      light_dragged |= ImGui::IsItemActive();
      light_released |= ImGui::IsItemDeactivatedAfterEdit();
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip(rebake ? "re-bakes the scene's objects: coarse while dragging, full on release"
                                 : "the ground and the sky's sun (no re-bake: --no-rebake, or nothing baked)");
      if (light_changed || light_released) {
        const glm::dvec3 direction = lightDirectionFromAngles(light_azimuth, light_elevation, up);
        renderer.setLightDirection(direction);
        if (rebake) rebake->request(direction, light_dragged ? BakeQuality::Coarse : BakeQuality::Full);
        dirty = true;
      }
      if (rebake) {
        if (rebake->busy())
          ImGui::Text("bake: %.0f %% (%s)", 100.0 * rebake->progress(),
                      rebake->runningQuality() == BakeQuality::Coarse ? "coarse" : "full");
        else
          ImGui::TextUnformatted(bake_line.c_str());
        if (!rebake->lastError().empty()) ImGui::TextWrapped("bake failed: %s", rebake->lastError().c_str());
      }
      if (ImGui::SliderFloat("step (voxels)", &step, 0.05f, 4.0f, "%.2f", ImGuiSliderFlags_Logarithmic))
        wanted.step_voxels = step;
      int integrator = settings.integrator == RayIntegrator::RK4 ? 1 : 0;
      const char* integrators[] = {"Euler", "RK4"};
      if (ImGui::Combo("integrator", &integrator, integrators, 2))
        wanted.integrator = integrator == 1 ? RayIntegrator::RK4 : RayIntegrator::Euler;
      if (ImGui::SliderFloat("resolution", &resolution_scale, 0.125f, 1.0f, "%.3f")) dirty = true;
      ImGui::Checkbox("refraction", &wanted.refraction);
      ImGui::SameLine();
      ImGui::Checkbox("scattering", &wanted.scattering);
      ImGui::SameLine();
      ImGui::Checkbox("Fresnel", &wanted.fresnel);
      ImGui::Checkbox("attenuation", &wanted.attenuation);
      ImGui::SameLine();
      ImGui::Checkbox("emission", &wanted.emission);
      ImGui::SameLine();
      ImGui::Checkbox("dispersion", &wanted.dispersion);
      if (wanted.bands > 3) {  // trace the spectrum's ends and interpolate (off: trace every band)
        ImGui::SameLine();
        ImGui::Checkbox("interpolate bands", &wanted.interpolate_bands);
      }
      ImGui::Checkbox("ground", &wanted.ground);
      ImGui::SameLine();
      ImGui::Checkbox("reflect objects", &wanted.reflect_objects);
      ImGui::SameLine();
      ImGui::Checkbox("skip empty space", &wanted.skip_empty_space);
      ImGui::Separator();
      if (ImGui::Button("save (S)")) save_requested = true;
      ImGui::SameLine();
      if (ImGui::Button("reset camera (R)")) orbit = OrbitCamera(initial_camera), dirty = true;
      ImGui::TextDisabled("drag: orbit   right drag: pan   wheel: zoom");
      ImGui::TextDisabled("H: hide panel   Esc/Q: quit");
      if (!status.empty()) ImGui::TextWrapped("%s", status.c_str());
      ImGui::PopItemWidth();
      ImGui::End();
    }
    if (!sameControls(wanted, settings)) {
      settings = wanted;
      renderer.setSettings(settings);
      dirty = true;
    }

    // Bakes that landed: swap each object's fresh volume in.
    if (rebake) {
      for (BackgroundBake::Landed& landed : rebake->take()) {
        try {
          renderer.replaceVolume(landed.index, landed.object);
          bake_line = std::string("bake: ") + (landed.quality == BakeQuality::Coarse ? "coarse " : "full ") +
                      std::to_string(static_cast<int>(std::lround(landed.seconds * 1e3))) + " ms";
        } catch (const std::exception& e) {
          status = std::string("could not show the bake: ") + e.what();
        }
        dirty = true;
        if (!options.quiet)
          std::fprintf(stderr, "viewer: re-baked %s (%s) in %.2f s\n", landed.object.source.c_str(),
                       landed.quality == BakeQuality::Coarse ? "coarse" : "full", landed.seconds);
      }
    }
    if (scripted && options.scripted_light && frame == 1 && !scripted_light_moved) {
      light_azimuth = static_cast<float>(options.scripted_light->x);
      light_elevation = static_cast<float>(options.scripted_light->y);
      const glm::dvec3 direction = lightDirectionFromAngles(light_azimuth, light_elevation, up);
      renderer.setLightDirection(direction);
      if (rebake) rebake->request(direction, BakeQuality::Full);
      scripted_light_moved = true;
      baked_frame = frame + 1;  // this frame's render cannot show the bake yet
    }
    if (scripted && rebake && !rebake->lastError().empty())
      throw RuntimeError("the re-bake failed: " + rebake->lastError());

    // Render the HDR image when something changed (always, in scripted mode).
    // While a mouse button drags the view, a quarter of the resolution at most: llvmpipe takes about
    // a second for a full 512² frame. The full image comes back when the button is released.
    // A scripted orbit drags the camera as the left button does, on every frame but the first and last.
    const bool orbiting = scripted && options.scripted_orbit_px != 0.0 && frame >= 1 && frame + 1 < options.scripted_frames;
    if (orbiting) {
      orbit.orbitByPixels(options.scripted_orbit_px, 0.0, std::max(1, fb.y));
      dirty = true;
    }
    const bool dragging =
        orbiting || (!scripted && !io.WantCaptureMouse && (io.MouseDown[0] || io.MouseDown[1] || io.MouseDown[2]));
    // While dragging: the scale the last drag frames settled on, a quarter of the resolution at most.
    if (dragging && !was_dragging) drag_scale = std::min(drag_scale, std::min(resolution_scale, 0.25f));
    was_dragging = dragging;
    const float scale = dragging ? drag_scale : scripted ? 1.0f : resolution_scale;
    const glm::ivec2 render_size = glm::max(glm::ivec2(glm::round(glm::vec2(fb) * scale)), glm::ivec2(1));
    if (!hdr || hdr.size() != render_size) {
      hdr = gl::Framebuffer(render_size, {gl::TextureFormat::RGBA32F}, /*depth=*/true);  // two-pass dispersion
      dirty = true;
    }
    if (dirty || scripted) {
      const Stopwatch render_clock;
      hdr.bind();
      renderer.draw(orbit.camera(), render_size);
      glFinish();
      render_ms = render_clock.milliseconds();
      dirty = false;
      if (dragging) drag_scale = nextDragScale(drag_scale, render_ms, std::min(resolution_scale, 0.25f));
    }

    // Display pass into the window, then the panel on top.
    gl::Framebuffer::bindDefault(fb);
    display.draw(hdr.color(0), fb, exposure, toneMapperAt(tonemap));
    ++frame;
    bool last_scripted_frame = false;
    if (scripted) {
      const bool resize = options.scripted_resize.x > 0 && options.scripted_resize.y > 0;
      if (resize && frame == 1) glfwSetWindowSize(window, options.scripted_resize.x, options.scripted_resize.y);
      glm::ivec2 window_size(0);
      glfwGetWindowSize(window, &window_size.x, &window_size.y);
      const bool resized = !resize || (window_size == options.scripted_resize && hdr.size() == fb);
      // A scripted light move waits for its re-bake to land (and be rendered: the swap is done
      // before this frame's render, so a frame after the bake went idle shows it).
      const bool baked = !options.scripted_light || (scripted_light_moved && (!rebake || !rebake->busy()));
      if (!baked) baked_frame = frame;
      last_scripted_frame = frame >= options.scripted_frames && resized && baked && frame > baked_frame + 1;
      if (frame >= options.scripted_frames + 1000 && !(options.scripted_light && !baked))
        throw RuntimeError("the window did not take the size asked for (" + std::to_string(options.scripted_resize.x) +
                           "x" + std::to_string(options.scripted_resize.y) + ")");
    }
    if (last_scripted_frame) {
      for (const fs::path& path : options.save) {
        if (path.extension() == ".png")
          writeScreenPng(path, fb);
        else
          writeImage(path, readLinearImage(hdr));
        if (!options.quiet)
          std::fprintf(stderr, "viewer: wrote %s (%dx%d) from the window\n", path.string().c_str(), fb.x, fb.y);
      }
      if (options.scripted_shot) save_requested = true;
      glfwSetWindowShouldClose(window, GLFW_TRUE);
    }
    if (save_requested) save_shot(fb);
    gl::Framebuffer::bindDefault(fb);  // the saves may have bound their own framebuffers
    imgui.render();
    if (last_scripted_frame && !options.save_ui.empty()) writeScreenPng(options.save_ui, fb);
    context.swapBuffers();
    frame_ms = frame_clock.restart() * 1e3;
    if (orbiting) {
      orbit_frame_ms.push_back(frame_ms);
      orbit_render_ms.push_back(render_ms);
      orbit_size = render_size;
    }
  }
  if (!orbit_frame_ms.empty()) {
    if (options.report) *options.report = {orbit_frame_ms, orbit_render_ms, orbit_size};
    if (!options.quiet) {
      const double frame_median = medianOf(orbit_frame_ms);
      std::fprintf(stderr, "viewer: orbit: %zu frames at %dx%d while dragging: median frame %.1f ms (%.1f fps), render %.1f ms\n",
                   orbit_frame_ms.size(), orbit_size.x, orbit_size.y, frame_median, 1e3 / frame_median,
                   medianOf(orbit_render_ms));
    }
  }
  return kExitOk;
}

}  // namespace eik
