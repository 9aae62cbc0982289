#include "viewer/bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/interfaces.h"
#include "core/stopwatch.h"
#include "gl/framebuffer.h"
#include "viewer/scene_renderer.h"

namespace eik {

double medianOf(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  if (values.size() % 2 == 1) return values[mid];
  const double upper = values[mid];
  const double lower = *std::max_element(values.begin(), values.begin() + mid);
  return 0.5 * (lower + upper);
}

std::vector<double> timeFrames(const std::function<void()>& draw, int frames, bool warm_up) {
  glFinish();  // nothing earlier in the timings
  if (warm_up) {
    draw();  // shader compilation, first texture use
    glFinish();
  }
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(std::max(frames, 0)));
  for (int i = 0; i < frames; ++i) {
    const Stopwatch frame_clock;
    draw();
    glFinish();
    ms.push_back(frame_clock.milliseconds());
  }
  return ms;
}

BareMarch::BareMarch(const gl::ShaderLibrary& shaders, const std::vector<BareObject>& objects, double step_voxels,
                     const std::optional<SceneGroundSpec>& ground)
    : ground_(ground) {
  if (objects.empty() || objects.size() > static_cast<std::size_t>(kMaxObjects))
    throw InputError("--bench", std::to_string(objects.size()) + " objects",
                     "the bare march crosses 1 to " + std::to_string(kMaxObjects) + " objects");
  for (const BareObject& object : objects) {
    Packed p;
    p.grid = object.volume->grid;
    p.object_to_world = object.object_to_world;
    const Field& ior = object.volume->require("ior", 1, object.source);
    // ∇n, or 0 where the volume leaves it out (core/interfaces.h iorGradient).
    const Field* grad = iorGradient(*object.volume, interfaceTable(*object.volume, object.source), object.source);
    const std::size_t count = p.grid.count();
    std::vector<float> packed(4 * count);
    for (std::size_t i = 0; i < count; ++i) {
      if (grad) {
        packed[4 * i + 0] = grad->data[3 * i + 0];
        packed[4 * i + 1] = grad->data[3 * i + 1];
        packed[4 * i + 2] = grad->data[3 * i + 2];
      }
      packed[4 * i + 3] = ior.data[i];
    }
    gl::checkTexture3DSize(p.grid.dims, object.source + " (packed n, grad n)");
    p.texture = gl::Texture3D(p.grid.dims, gl::TextureFormat::RGBA32F, packed, 4);
    const glm::dvec3 h = p.grid.voxelSize();
    p.step = step_voxels * std::min({h.x, h.y, h.z});
    // The same bound as the renderers: four box diagonals of arc length, and some.
    p.max_steps = static_cast<int>(std::ceil(4.0 * glm::length(p.grid.extent()) / p.step)) + 16;
    objects_.push_back(std::move(p));
  }
  gl::ShaderDefines defines = {{"OBJECTS", std::to_string(objects_.size())}};
  if (ground_) defines.emplace_back("GROUND", "1");
  program_ = shaders.program("common/fullscreen.vert", "viewer/bare_march.frag", defines);
}

BareMarch::BareMarch(const gl::ShaderLibrary& shaders, const Volume& volume, const glm::dmat4& object_to_world,
                     double step_voxels, const std::string& source)
    : BareMarch(shaders, std::vector<BareObject>{BareObject{&volume, object_to_world, source}}, step_voxels) {}

void BareMarch::draw(const Camera& camera, glm::ivec2 size) const {
  glViewport(0, 0, size.x, size.y);
  const double aspect = static_cast<double>(size.x) / static_cast<double>(size.y);
  program_.use();
  program_.set("uInvViewProj", glm::mat4(camera.inverseViewProjection(aspect)));
  program_.set("uEye", glm::vec3(camera.eye));
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    const Packed& p = objects_[i];
    const std::string at = "[" + std::to_string(i) + "]";
    program_.set("uWorldToVolume" + at, glm::mat4(glm::inverse(p.object_to_world)));
    program_.set("uVolumeToWorld" + at, glm::mat4(p.object_to_world));
    program_.set("uBoundsMin" + at, glm::vec3(p.grid.bounds_min));
    program_.set("uBoundsMax" + at, glm::vec3(p.grid.bounds_max));
    program_.set("uStep" + at, static_cast<float>(p.step));
    program_.set("uMaxSteps" + at, p.max_steps);
    p.texture.bind(static_cast<int>(i));
    program_.setSampler("uPacked" + at, static_cast<int>(i));
  }
  if (ground_) {
    program_.set("uGroundPoint", glm::vec3(ground_->point));
    program_.set("uGroundNormal", glm::vec3(glm::normalize(ground_->normal)));
  }
  triangle_.draw();
}

Image BareMarch::render(const Camera& camera, glm::ivec2 size) const {
  gl::Framebuffer target(size, {gl::TextureFormat::RGBA32F});
  target.bind();
  draw(camera, size);
  return readLinearImage(target);
}

double BareMarch::countSteps(const Camera& camera, glm::ivec2 size) const {
  const Image image = render(camera, size);
  double total = 0.0;
  for (std::size_t p = 3; p < image.pixels.size(); p += 4) total += image.pixels[p];
  return total;
}

namespace {
BenchFigures figures(std::vector<double> frame_ms, double steps_per_frame) {
  BenchFigures f;
  f.frame_ms = std::move(frame_ms);
  f.median_ms = medianOf(f.frame_ms);
  f.steps_per_frame = steps_per_frame;
  f.samples_per_s = f.median_ms > 0 ? steps_per_frame / (f.median_ms * 1e-3) : 0.0;
  return f;
}
}  // namespace

BenchReport runBench(const std::function<void()>& draw_full, const BareMarch& bare, const Camera& camera,
                     glm::ivec2 size, int frames) {
  BenchReport report;
  report.frames = frames;
  report.size = size;
  gl::Framebuffer target(size, {gl::TextureFormat::RGBA32F}, /*depth=*/true);  // as render() draws (two-pass dispersion)
  const double steps = bare.countSteps(camera, size);
  // Interleaved, full then bare in every round, so that both see the same machine load (a busy
  // machine otherwise biases whichever runs second).
  auto full_frame = [&] {
    target.bind();
    draw_full();
  };
  auto bare_frame = [&] {
    target.bind();
    bare.draw(camera, size);
  };
  std::vector<double> full_ms, bare_ms;
  full_frame();  // warm-up of both, untimed
  bare_frame();
  glFinish();
  for (int i = 0; i < frames; ++i) {
    full_ms.push_back(timeFrames(full_frame, 1, false).front());
    bare_ms.push_back(timeFrames(bare_frame, 1, false).front());
  }
  report.full = figures(std::move(full_ms), steps);
  report.bare = figures(std::move(bare_ms), steps);
  report.ratio_full_over_bare = report.bare.median_ms > 0 ? report.full.median_ms / report.bare.median_ms : 0.0;
  return report;
}

std::string formatBenchReport(const BenchReport& r) {
  char buffer[1024];
  std::snprintf(buffer, sizeof buffer,
                "bench: %dx%d, %d frames (median), step %.3g voxels, %s\n"
                "  full: %9.2f ms/frame  %.3g samples/s (step-equivalent)\n"
                "  bare: %9.2f ms/frame  %.3g samples/s (%.0f ray steps a frame, counted)\n"
                "  full/bare: %.2f\n",
                r.size.x, r.size.y, r.frames, r.step_voxels, r.gl_summary.c_str(), r.full.median_ms,
                r.full.samples_per_s, r.bare.median_ms, r.bare.samples_per_s, r.bare.steps_per_frame,
                r.ratio_full_over_bare);
  return buffer;
}

nlohmann::json benchReportJson(const BenchReport& r) {
  auto figuresJson = [](const BenchFigures& f) {
    return nlohmann::json{{"median_ms", f.median_ms},
                          {"steps_per_frame", f.steps_per_frame},
                          {"samples_per_s", f.samples_per_s},
                          {"frame_ms", f.frame_ms}};
  };
  return nlohmann::json{
      {"frames", r.frames},
      {"size", {r.size.x, r.size.y}},
      {"gl_renderer", r.gl_renderer},
      {"gl", r.gl_summary},
      {"step_voxels", r.step_voxels},
      {"full", figuresJson(r.full)},
      {"bare", figuresJson(r.bare)},
      {"ratio_full_over_bare", r.ratio_full_over_bare},
      {"samples_note",
       "samples = ray steps; bare: counted exactly (each pixel's step count, summed); full: the bare march's "
       "count for the same rays and step size divided by the full renderer's median time (step-equivalent)"}};
}

}  // namespace eik
