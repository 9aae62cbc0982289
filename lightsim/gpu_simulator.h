// The GPU light simulator (thesis §6.2, lightsim/ALGORITHM.md): the wavefront as a particle system
// of patches in textures, stepped with fragment-shader passes on OpenGL 3.3 (no compute shaders, no
// transform feedback). One step, each pass in a file of its own:
//
//   pass      file             draws                      reads                    writes               step
//   update    update_pass.h    full-screen, live box      list A, volume           list B (8 MRT)       1–3
//   analysis  analysis_pass.h  full-screen, live box      list B (+ A: m_old, Φ),  StepTargets: counts  5, and the
//                                                         volume                   (pyramid base),      per-patch
//                                                                                  deposit A/B,         work of
//                                                                                  ledger A/B           2–4
//   deposit   deposit_pass.h   GL_POINTS, one per patch   deposit A/B              atlas (blend/depth)  4
//     or track  track_deposit_  GL_POINTS, one per patch   lists A and B (corners   atlas (blend)        4
//               pass.h           and atlas z-slice          before, after), dep. A
//   receiver  receiver_pass.h  GL_TRIANGLES, two quads    list B, deposit B        receiver map (blend) 4
//                              per received patch         (flux received)
//   ledger    ledger_pass.h    GL_POINTS, one per patch   ledger A/B, list B       ledger row (blend)   ledger
//   pyramid   histo_pyramid.h  HistoPyramid::build        counts                   pyramid; the total   6
//                                                                                  is read back
//   compact   compact_pass.h   full-screen, new live box  list B, pyramid, fate    list A (8 MRT)       6
//
// With sharp interfaces (an `interfaces` field) the update, analysis and compaction passes are
// compiled with SHARP_INTERFACES (shaders/lightsim/sharp.glsl; ALGORITHM.md "Sharp interfaces").
// (Lists A and B and the step targets: list_set.h, step_targets.h; the uniforms: grid_uniforms.h,
// step_uniforms.h; the atlas: atlas.h.) All per-patch arithmetic happens in the fragment passes;
// the point passes only fetch a few texels and scatter them (on llvmpipe vertex shading runs on one
// thread, fragments on all of them).
//
// The list grows by reallocating both lists (and the analysis targets) at the next power of two
// (nothing to copy: compaction writes every live patch of the new list). Memory: about 330 B a
// patch slot (2 lists × 8 RGBA32F, 4 RGBA32F analysis targets, the pyramid). The side is limited
// to max_patch_side (default 2048: 4 Mi patches, 1.3 GiB), GL_MAX_TEXTURE_SIZE and the texture
// budget; a run that would exceed them stops with a RuntimeError naming the step, the size and the
// limit.
//
// The only readback per step is the pyramid's total (one texel), and with CountReadback::Overlap
// the CPU collects it a step late, so it never stalls the GPU. The energy ledger (flux absorbed,
// reflected, exited, killed per reason, counts, splits) is summed on the GPU into one row per step
// and read back every ledger_interval steps, where it is summed in double (so float sums never run
// over more than one step); the progress callback is called then. Phases are timed with
// gl::PhaseTimer (gl/time_query.h).
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
  // The patch list is at most max_patch_side² patches (rounded down to a power of two; clamped to
  // GL_MAX_TEXTURE_SIZE and 4096, the histogram pyramid's limit). About 330 B a slot: 1.3 GiB at 2048.
  int max_patch_side = 2048;
  int ledger_interval = 32;       // steps between ledger readbacks (and progress reports)
  // Phase times in SimulationStats::phase_seconds (gl::PhaseTimer, gl/time_query.h):
  //   Queries  GL_TIME_ELAPSED queries, collected asynchronously (does not serialise a GPU run);
  //   Finish   glFinish after each phase and wall-clock time (slows a GPU run);
  //   Off      only "init", "readback", "output" and "total" (wall clock);
  //   Auto     Queries on a hardware GPU, Off on a software rasteriser (llvmpipe, softpipe, swrast),
  //            where queries cut the work into small flushes (measured: 15–40 % slower bakes).
  enum class Timing { Auto, Off, Queries, Finish };
  Timing timing = Timing::Auto;
  // When the CPU learns each step's new patch count (the pyramid's total; ALGORITHM.md "The count
  // stays on the GPU"). The passes read the count on the GPU (live_count.h) either way:
  //   Wait     read back after the step's pyramid is built, before its compaction is queued: every
  //            pass is drawn over exactly the live patches, but the GPU runs dry while the CPU
  //            waits for the texel and queues the next passes;
  //   Overlap  read back one step later, after the compaction and the next step's passes are
  //            queued: those are drawn over a bound, kMaxChildren × the last count known, and skip
  //            the slots past the count on the GPU; the lists are sized for the bound (up to
  //            kMaxChildren × the memory). A step whose bound would exceed max_patch_side or the
  //            texture budget waits as in Wait;
  //   Auto     Overlap on a hardware GPU, Wait on a software rasteriser (llvmpipe, softpipe,
  //            swrast), which shades every fragment of the bound in full and has no GPU to keep busy.
  // The bake is the same in every mode, to the bit (GpuSimulatorTest.OverlappedCountReadback...).
  enum class CountReadback { Auto, Wait, Overlap };
  CountReadback count_readback = CountReadback::Auto;
  // The most slots one patch takes in the next list: a 2×2 split and a followed reflection.
  static constexpr int kMaxChildren = 5;
  // Sample n, ∇n and σa with trilinear interpolation done in the shader (8 texelFetch a lookup,
  // float weights) instead of the texture units' filtering, whose weights GPUs quantise (8 bits of
  // sub-texel position on NVIDIA). Agrees with the CPU twin to float rounding; slower on GPUs.
  bool exact_sampling = false;
  // Texture memory the bake may take (volume, atlas, patch lists, checked at construction and when
  // the list grows); 0 = gl::defaultTextureBudget() (EIKONAL_GL_TEXTURE_BUDGET_MB, else 4 GiB).
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
  bool overlapped_counts = false;     // CountReadback resolved to Overlap
  int waited_counts = 0;              // steps whose new count the CPU waited for before queuing on
                                      // (every step with Wait; with Overlap only where the bound did
                                      // not fit, and the last)
  double wall_seconds = 0.0;
};

class GpuSimulator : public Simulator {
 public:
  // Uploads n, ∇n, σa and the interface distances of `volume` (the only fields read) and compiles
  // nothing yet. Uses the current GL context, or creates a headless one (options.backend) and owns
  // it when none is current. InputError ("volume too large for the GPU: ...") when the grid's flat-3D atlas does
  // not fit GL_MAX_TEXTURE_SIZE, the grid GL_MAX_3D_TEXTURE_SIZE, or the textures the budget.
  explicit GpuSimulator(const Volume& volume, GpuSimulatorOptions options = {});
  // The same in `context` when it is not null, which the simulator then owns (and makes current):
  // e.g. the context makeSimulator probed the renderer with.
  GpuSimulator(const Volume& volume, GpuSimulatorOptions options, std::unique_ptr<gl::GlContext> context);
  ~GpuSimulator() override;
  GpuSimulator(const GpuSimulator&) = delete;
  GpuSimulator& operator=(const GpuSimulator&) = delete;

  BakeResult run(const LightSpec& light, const SimulationOptions& options) override;
  // {"texture_bytes": {"volume", "atlas", "patch_lists_peak", "total_peak"}} of the last run.
  nlohmann::json lastRunStats() const override;

  const GpuRunInfo& lastRunInfo() const;
  // "llvmpipe (LLVM 15.0.6, 256 bits), OpenGL 4.5 (Core Profile) Mesa 22.3.6, via OSMesa"
  std::string renderer() const;

 private:
  struct Impl;
  std::unique_ptr<gl::GlContext> ownedContext_;  // destroyed last
  std::unique_ptr<Impl> impl_;
};

}  // namespace eik
