#include "viewer/bench_mode.h"

#include <cstdio>

#include "core/atomic_file.h"
#include "core/error.h"
#include "gl/shader_library.h"
#include "viewer/bench.h"
#include "viewer/scene_renderer.h"

namespace eik {

int runBenchMode(const LoadedScene& scene, const RenderSettings& settings, const Camera& camera,
                 const BenchOptions& options) {
  if (options.frames < 1) throw InputError("--bench", std::to_string(options.frames), "give at least 1 frame");
  if (scene.objects.empty()) throw InputError(scene.source, "objects", "the scene has no object");
  gl::ContextOptions context_options;
  context_options.backend = options.backend;
  gl::GlContext context(context_options);
  gl::ShaderLibrary shaders;
  SceneRenderer renderer(shaders, scene, settings);
  // The bare march of the whole scene: every object (up to BareMarch::kMaxObjects) and the ground.
  std::vector<BareObject> bare_objects;
  for (const LoadedObject& object : scene.objects) bare_objects.push_back({&object.volume, object.object_to_world, object.source});
  if (bare_objects.size() > static_cast<std::size_t>(BareMarch::kMaxObjects))
    bare_objects.resize(static_cast<std::size_t>(BareMarch::kMaxObjects));
  BareMarch bare(shaders, bare_objects, settings.step_voxels, settings.ground ? scene.scene.ground : std::nullopt);
  BenchReport report =
      runBench([&] { renderer.draw(camera, options.size); }, bare, camera, options.size, options.frames);
  report.gl_renderer = context.info().renderer;
  report.gl_summary = context.summary();
  report.step_voxels = settings.step_voxels;
  if (!options.quiet) std::fputs(formatBenchReport(report).c_str(), stdout);
  if (!options.stats_path.empty()) {
    nlohmann::json j = benchReportJson(report);
    j["scene"] = scene.source;
    j["objects"] = static_cast<int>(scene.objects.size());
    j["integrator"] = rayIntegratorName(settings.integrator);
    j["bare_objects"] = bare.objectCount();
    j["bare_ground"] = settings.ground && scene.scene.ground.has_value();
    const LoadedObject& first = scene.objects.front();
    j["grid"] = {first.volume.grid.dims.x, first.volume.grid.dims.y, first.volume.grid.dims.z};
    writeFileAtomic(options.stats_path, j.dump(2) + "\n");
  }
  return kExitOk;
}

}  // namespace eik
