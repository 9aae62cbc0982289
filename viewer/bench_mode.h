// `viewer SCENE --bench N [--size WxH] [--stats FILE.json]`: runs viewer/bench.h's benchmark of
// the full renderer against the bare march headless, prints the figures and writes them as JSON.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "gl/context.h"
#include "viewer/camera.h"
#include "viewer/loaded_scene.h"
#include "viewer/render_settings.h"

namespace eik {

struct BenchOptions {
  int frames = 10;
  glm::ivec2 size{512, 512};
  std::string stats_path;  // empty: none
  gl::GlBackend backend = gl::GlBackend::Auto;  // headless
  bool quiet = false;
};

// Returns the exit code (0). The bare march runs on the first object only (docs/testing.md scenes for
// the benchmark hold one volume).
int runBenchMode(const LoadedScene& scene, const RenderSettings& settings, const Camera& camera,
                 const BenchOptions& options);

}  // namespace eik
