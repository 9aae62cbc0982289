// The interactive viewer (thesis §6.3; docs/programs.md "viewer without --render opens a window"): a
// GLFW window (gl::GlContext's window back end) showing SceneRenderer's HDR image through the
// display pass (viewer/display_pass.h), with Dear ImGui controls on top.
//
// Controls: left drag orbits, right or middle drag (or shift + left) pans, the wheel zooms; the
// panel sets the light direction, exposure, tone mapper, step size, integrator, resolution scale
// and switches refraction, scattering, Fresnel, attenuation, emission, dispersion and the ground;
// it shows the render time. Moving the light re-bakes the scene's baked objects in the background
// (a coarse bake while dragging, the full one on release; viewer/background_bake.h) and swaps each
// in when it lands, so the caustics and shadows follow; the panel shows the bake's progress and time.
// S saves the current view as EXR (linear) and PNG (tone-mapped exactly as `--render OUT.png`),
// R resets the camera, Esc or Q quits. The image is re-rendered only when something changed
// (llvmpipe is slow), at reduced resolution while dragging; the panel stays live.
//
// Scripted mode (tests, --window-frames N): renders N frames at full resolution (optionally
// resizing the window after the first), then writes each `save` path (.exr: the window's linear HDR image; .png: the pixels the display pass put on the
// screen, before the panel) and closes.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/tonemap.h"
#include "viewer/camera.h"
#include "viewer/loaded_scene.h"
#include "viewer/render_settings.h"

namespace eik {

struct WindowOptions {
  glm::ivec2 size{800, 600};  // initial window size (screen coordinates)
  std::string title = "Eikonal viewer";
  float exposure_ev = 0.0f;
  ToneMapper tonemap = ToneMapper::Aces;
  int scripted_frames = 0;                  // > 0: scripted mode
  std::vector<std::filesystem::path> save;  // scripted mode's outputs
  std::filesystem::path save_ui;            // scripted mode: a PNG of the screen with the panel (docs)
  std::filesystem::path shot_prefix = "eikonal-shot";  // S key: PREFIX-NNN.exr and .png
  bool scripted_shot = false;  // scripted mode: also "press S" on the last frame (tests)
  glm::ivec2 scripted_resize{0};  // scripted mode: resize the window to this after the first frame
                                  // (tests), and go on until the window has taken the new size
  // The light sliders re-bake every object baked by a directional light in the background
  // (viewer/background_bake.h); off: they move only the ground's and the sun's light.
  bool rebake = true;
  // Scripted mode: after the first frame, move the light to these angles (azimuth, elevation in
  // degrees, as the sliders) and go on until its re-bake has landed (tests).
  std::optional<glm::dvec2> scripted_light;
  // Scripted mode: every frame but the first and the last drags the camera this many pixels
  // sideways, as the left mouse button does (so those frames render as while dragging: at most a
  // quarter of the resolution per axis); the last frame, released, renders at full resolution. The
  // drag frames' times go to `report` and are printed (`viewer --window-orbit`).
  double scripted_orbit_px = 0.0;
  struct Report {
    std::vector<double> orbit_frame_ms;   // each drag frame, from one shown frame to the next
    std::vector<double> orbit_render_ms;  // its render alone
    glm::ivec2 orbit_render_size{0};      // the resolution it rendered at
  };
  Report* report = nullptr;  // filled when given
  bool quiet = false;
};

// Opens the window (RuntimeError when GLFW cannot), renders `scene` until the user quits (or the
// scripted frames are done). Returns the exit code (0).
int runViewerWindow(const LoadedScene& scene, const RenderSettings& settings, const Camera& camera,
                    const WindowOptions& options);

// The resolution scale (per axis) of the next frame while the camera is dragged: the last drag
// frame's scale corrected towards a render of kDragRenderBudgetMs (pixels cost about the same each,
// so the scale goes with the square root of the time ratio), within [kMinDragScale, max_scale];
// changes under 10 % are ignored (the frame's buffer is kept). So the view stays fluid however
// heavy the scene: every DCC viewport does this.
constexpr double kDragRenderBudgetMs = 40.0;
constexpr float kMinDragScale = 1.0f / 16.0f;
float nextDragScale(float scale, double render_ms, float max_scale);

// The light's direction of travel from an azimuth and elevation (degrees) of the direction it
// comes FROM, about `up` (the azimuth's zero is the projection of a fixed perpendicular), and back.
glm::dvec3 lightDirectionFromAngles(double azimuth_deg, double elevation_deg, glm::dvec3 up);
glm::dvec2 lightAnglesFromDirection(glm::dvec3 travel_dir, glm::dvec3 up);

}  // namespace eik
