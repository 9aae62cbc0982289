// `viewer --bench N` (docs/programs.md, docs/testing.md "timings belong in benchmarks"): N frames of the full
// renderer headless, and N frames of a bare refractive march of the same scene (BareMarch, the
// cost floor of curved-ray casting: through every object's box in the order the ray meets them,
// Euler steps with ONE fetch a step of a packed n+∇n texture, then the ground's hit test; no
// shading), each frame ended by glFinish, the median ms/frame of each, and their ratio.
//
// Samples per second = ray steps per second. The bare march counts its steps exactly (each pixel
// writes its step count; one untimed extra frame is read back and summed). The full renderer's
// figure divides that SAME count by the full renderer's time: the same rays at the same step
// size, so it is a step-equivalent throughput (the full renderer may take fewer real steps, by
// early termination and empty-space skipping, or more, by dispersion's three rays).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/image_io.h"
#include "core/scene.h"
#include "core/volume.h"
#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "gl/vertex_array.h"
#include "viewer/camera.h"

namespace eik {

// The median (mean of the middle two for an even count); 0 for none.
double medianOf(std::vector<double> values);

// Times `frames` calls of `draw` (each followed by glFinish), after one untimed warm-up call
// unless `warm_up` is false. Milliseconds a frame, in call order.
std::vector<double> timeFrames(const std::function<void()>& draw, int frames, bool warm_up = true);

// One object of a bare march: its volume (ior and ior_grad), placed by object_to_world.
struct BareObject {
  const Volume* volume = nullptr;
  glm::dmat4 object_to_world{1.0};
  std::string source = "volume";  // named in errors
};

class BareMarch {
 public:
  // The most objects one bare march crosses (a sampler each).
  static constexpr int kMaxObjects = 8;

  // Needs a current GL context. Packs each volume's ior and ior_grad (InputError naming its
  // `source` when missing) into one RGBA32F 3D texture; `object_to_world` places it (thesis
  // §6.3.1). A ray crosses the objects' boxes in the order it meets them, straight between them,
  // and ends with the ground's hit test when there is a ground: the cost floor of the scene.
  // InputError for none or more than kMaxObjects objects.
  BareMarch(const gl::ShaderLibrary& shaders, const std::vector<BareObject>& objects, double step_voxels,
            const std::optional<SceneGroundSpec>& ground = std::nullopt);
  // One volume, no ground.
  BareMarch(const gl::ShaderLibrary& shaders, const Volume& volume, const glm::dmat4& object_to_world,
            double step_voxels, const std::string& source = "volume");

  // Into the bound framebuffer, viewport (0, 0, size): RGB the exit direction, A the steps taken.
  void draw(const Camera& camera, glm::ivec2 size) const;
  // Offscreen RGBA32F and readback (rows top to bottom).
  Image render(const Camera& camera, glm::ivec2 size) const;
  // The total number of steps of every pixel's ray (the sum of render()'s alpha).
  double countSteps(const Camera& camera, glm::ivec2 size) const;

  double stepLength() const { return objects_.front().step; }  // the first volume's, in its own units
  int maxSteps() const { return objects_.front().max_steps; }
  int objectCount() const { return static_cast<int>(objects_.size()); }

 private:
  struct Packed {
    GridSpec grid;
    glm::dmat4 object_to_world{1.0};
    double step = 0.0;
    int max_steps = 0;
    gl::Texture3D texture;
  };
  std::vector<Packed> objects_;
  std::optional<SceneGroundSpec> ground_;
  gl::Program program_;
  gl::FullscreenTriangle triangle_;
};

struct BenchFigures {
  std::vector<double> frame_ms;
  double median_ms = 0.0;
  double steps_per_frame = 0.0;  // see the header comment
  double samples_per_s = 0.0;    // steps_per_frame / median
};

struct BenchReport {
  int frames = 0;
  glm::ivec2 size{0};
  std::string gl_renderer;  // GL_RENDERER
  std::string gl_summary;   // renderer, version and back end
  double step_voxels = 0.0;
  BenchFigures full;        // the viewer's renderer with the given settings
  BenchFigures bare;        // BareMarch of the whole scene
  double ratio_full_over_bare = 0.0;  // of the medians
};

// Runs both benchmarks at `size`, interleaved (a full frame, then a bare one, N times, after one
// untimed frame of each): `draw_full` must draw one frame of the full renderer into the bound
// framebuffer with viewport (0, 0, size) (runBench binds an RGBA32F target of that size).
BenchReport runBench(const std::function<void()>& draw_full, const BareMarch& bare, const Camera& camera,
                     glm::ivec2 size, int frames);

// Human-readable lines, e.g. "full: 12.3 ms/frame (median of 20), 1.2e8 samples/s".
std::string formatBenchReport(const BenchReport& report);
// The --stats FILE.json object.
nlohmann::json benchReportJson(const BenchReport& report);

}  // namespace eik
