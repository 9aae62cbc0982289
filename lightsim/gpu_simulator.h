// The GPU light simulator (thesis §6.2, lightsim/ALGORITHM.md): the wavefront as a particle system
// of patches in textures, stepped with fragment-shader passes on OpenGL 3.3 (no compute shaders, no
// transform feedback). One step:
//
//   pass        draws                               reads                 writes
//   update      full-screen over the live box       list A, volume        list B (8 MRT)     steps 1–3
//   deposit     GL_POINTS, one per patch            list B (+ A: Δs_m)    atlas (blend/depth) step 4
//   analysis    full-screen                         list B                count, fate        step 5
//   ledger      GL_POINTS, 3 per patch              lists A, B, fate      ledger row (blend)
//   pyramid     histogram pyramid (HistoPyramid)    count                 pyramid; the total is read back
//   compact     full-screen over the new box        list B, pyramid       list A (8 MRT)     step 6
//
// The list grows by reallocating both lists at the next power of two (nothing to copy: compaction
// writes every live patch of the new list); its side is limited to max_patch_side (default 2048,
// 4 Mi patches, 512 MiB a list) and to GL_MAX_TEXTURE_SIZE; a run that would exceed it stops with
// a RuntimeError naming the step, the size and the limit.
//
// The only readback per step is the pyramid's total (one texel). The energy ledger (flux absorbed,
// reflected, exited, killed per reason, counts, splits) is summed on the GPU into one row per step
// and read back every ledger_interval steps, where it is summed in double (so float sums never run
// over more than one step); the progress callback is called then.
//
// The initial patch list is made on the CPU by the twin's initialPatches (wavefront.h) and uploaded.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include <glm/vec2.hpp>

#include "core/volume.h"
#include "gl/context.h"
#include "lightsim/simulator.h"

namespace eik {

struct GpuSimulatorOptions {
  std::string source = "volume";  // the manifest, for error messages
  // The patch list is at most max_patch_side² patches (a power of two; clamped to
  // GL_MAX_TEXTURE_SIZE). Two lists of 8 RGBA32F textures: 256 B a patch, 1 GiB at 2048.
  int max_patch_side = 2048;
  int ledger_interval = 32;       // steps between ledger readbacks (and progress reports)
  // Phase times in SimulationStats::phase_seconds:
  //   Queries  GL_TIME_ELAPSED queries, collected asynchronously (does not serialise a GPU run);
  //   Finish   glFinish after each phase and wall-clock time (exact on llvmpipe, slows a GPU);
  //   Off      none but "init", "finish" and "total".
  enum class Timing { Off, Queries, Finish };
  Timing timing = Timing::Queries;
  // Texture memory the bake may take (volume, atlas, patch lists); 0 = gl::defaultTextureBudget().
  std::size_t budget_bytes = 0;
  // Use this GL back end when no context is current at construction (the simulator then owns one).
  gl::GlBackend backend = gl::GlBackend::Auto;
};

// Figures of the last run that SimulationStats has no field for.
struct GpuRunInfo {
  int initial_patch_side = 0;
  int peak_patch_side = 0;
  glm::ivec2 atlas_size{0};
  glm::ivec2 atlas_tiles{0};
  std::size_t volume_bytes = 0;       // the uploaded fields (n, ∇n, σa)
  std::size_t atlas_bytes = 0;
  std::size_t patch_bytes_peak = 0;   // both lists, count/fate targets and pyramid, at the peak size
  std::size_t texture_bytes_peak = 0; // all of the above together
  double wall_seconds = 0.0;
};

class GpuSimulator : public Simulator {
 public:
  // Uploads n, ∇n and σa of `volume` (the only fields read) and compiles nothing yet. Uses the
  // current GL context, or creates a headless one (options.backend) and owns it when none is
  // current. InputError ("volume too large for the GPU: ...") when the grid's flat-3D atlas does
  // not fit GL_MAX_TEXTURE_SIZE, the grid GL_MAX_3D_TEXTURE_SIZE, or the textures the budget.
  explicit GpuSimulator(const Volume& volume, GpuSimulatorOptions options = {});
  ~GpuSimulator() override;
  GpuSimulator(const GpuSimulator&) = delete;
  GpuSimulator& operator=(const GpuSimulator&) = delete;

  BakeResult run(const LightSpec& light, const SimulationOptions& options) override;

  const GpuRunInfo& lastRunInfo() const;
  // "llvmpipe (LLVM 15.0.6, 256 bits), OpenGL 4.5 (Core Profile) Mesa 22.3.6, via OSMesa"
  std::string renderer() const;

 private:
  struct Impl;
  std::unique_ptr<gl::GlContext> ownedContext_;  // destroyed last
  std::unique_ptr<Impl> impl_;
};

}  // namespace eik
