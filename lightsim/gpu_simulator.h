// The GPU light simulator (thesis §6.2, lightsim/ALGORITHM.md): the wavefront as a particle system
// of patches in textures, stepped with fragment-shader passes on OpenGL 3.3 (no compute shaders, no
// transform feedback). One step:
//
//   pass        draws                           reads                    writes
//   update      full-screen over the live box   list A, volume           list B (8 MRT)       steps 1–3
//   analysis    full-screen over the live box   list B (+ A: m_old, Φ),  count (pyramid base),  step 5,
//                                               volume                   deposit A/B, ledger A/B and the
//                                                                        per-patch work of 2–4
//   deposit     GL_POINTS, one per patch        deposit A/B              atlas (blend / depth)  step 4
//   ledger      GL_POINTS, one per patch        ledger A/B, list B       ledger row (blend, MRT)
//   pyramid     HistoPyramid::build             count                    pyramid; the total is read back
//   compact     full-screen over the new box    list B, pyramid, fate    list A (8 MRT)         step 6
//
// All per-patch arithmetic happens in the fragment passes; the point passes only fetch a few texels
// and scatter them (on llvmpipe vertex shading runs on one thread, fragments on all of them).
// The list grows by reallocating both lists (and the analysis targets) at the next power of two
// (nothing to copy: compaction writes every live patch of the new list). Memory: about 330 B a
// patch slot (2 lists × 8 RGBA32F, 4 RGBA32F analysis targets, the pyramid). The side is limited
// to max_patch_side (default 2048: 4 Mi patches, 1.3 GiB), GL_MAX_TEXTURE_SIZE and the texture
// budget; a run that would exceed them stops with a RuntimeError naming the step, the size and the
// limit.
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
#include "gl/framebuffer.h"
#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "gl/vertex_array.h"
#include "gl/volume_textures.h"
#include "lightsim/atlas.h"
#include "lightsim/histo_pyramid.h"
#include "lightsim/patch_textures.h"
#include "lightsim/simulator.h"

namespace eik {

struct GpuSimulatorOptions {
  std::string source = "volume";  // the manifest, for error messages
  // The patch list is at most max_patch_side² patches (rounded down to a power of two; clamped to
  // GL_MAX_TEXTURE_SIZE and 4096, the histogram pyramid's limit). About 330 B a slot: 1.3 GiB at 2048.
  int max_patch_side = 2048;
  int ledger_interval = 32;       // steps between ledger readbacks (and progress reports)
  // Phase times in SimulationStats::phase_seconds:
  //   Queries  GL_TIME_ELAPSED queries, collected asynchronously (does not serialise a GPU run);
  //   Finish   glFinish after each phase and wall-clock time (slows a GPU run);
  //   Off      only "init", "readback", "output" and "total" (wall clock);
  //   Auto     Queries on a hardware GPU, Off on a software rasteriser (llvmpipe, softpipe, swrast),
  //            where queries cut the work into small flushes (measured: 15–40 % slower bakes).
  enum class Timing { Auto, Off, Queries, Finish };
  Timing timing = Timing::Auto;
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

// ---------------------------------------------------------------------------------------------
// The passes of one step, exposed for tests (single steps on hand-made patches) and for anyone who
// drives the simulation differently. Each takes its inputs and outputs explicitly.
namespace gpu {

// Constants of a run, as uniforms.
struct StepUniforms {
  float dt = 0.0f;                                   // Δt
  float boundaryOn = 0.0f, boundaryOff = 0.0f;       // g_on, g_off
  float fluxKill = 0.0f;                             // flux_threshold · Φ_ref
  float splitLength = 0.0f;                          // split_voxels · h
  float maxDepth = 0.0f;                             // max_depth
  bool axisSplit = true;                             // SplitRule::Axis
  bool killAtMaxDepth = false;                       // DepthLimit::Kill
};

// What the analysis pass writes per patch (the patch list layout, mortonTexel(k)): the pyramid
// (whose base takes the counts), deposit A/B and ledger A/B (shaders/lightsim/analysis.frag).
struct StepTargets {
  HistoPyramid pyramid;
  gl::Texture2D depositA, depositB, ledgerA, ledgerB;  // RGBA32F
  gl::Framebuffer framebuffer;                         // base, deposit A, B, ledger A, B

  StepTargets(int side, const gl::ShaderLibrary& library);
  static std::size_t bytesFor(int side);
};

// Steps 1–3: list `in` → list `out` (INTEGRATOR_EULER / _RK2 / _RK4 variants).
class UpdatePass {
 public:
  UpdatePass(const gl::ShaderLibrary& library, Integrator integrator, const std::string& volumeDefines);
  void run(const PatchTextures& in, PatchTextures& out, std::size_t count, const gl::VolumeTextures& volume,
           const GridUniforms& grid, const StepUniforms& step) const;

 private:
  gl::Program program_;
  gl::FullscreenTriangle triangle_;
};

// Step 5 and the per-patch work of steps 2–4 (deposit values, ledger entries): `current` is the
// list after the update, `previous` the one before it.
class AnalysisPass {
 public:
  AnalysisPass(const gl::ShaderLibrary& library, DepositMode mode, const AtlasLayout& atlas,
               const std::string& volumeDefines);
  void run(const PatchTextures& current, const PatchTextures& previous, std::size_t count, StepTargets& targets,
           const gl::VolumeTextures& volume, const GridUniforms& grid, const StepUniforms& step) const;

 private:
  gl::Program program_;
  gl::FullscreenTriangle triangle_;
};

// Step 6: list `in` (+ the pyramid and fates of its analysis) → list `out` of `total` patches.
class CompactPass {
 public:
  // pyramidDefines: HistoPyramid::defines() of the pyramids it will read (their levels).
  CompactPass(const gl::ShaderLibrary& library, const gl::ShaderDefines& pyramidDefines,
              const std::string& volumeDefines);
  void run(const PatchTextures& in, const StepTargets& targets, PatchTextures& out, std::size_t total,
           const gl::VolumeTextures& volume, const GridUniforms& grid) const;

 private:
  gl::Program program_;
  gl::FullscreenTriangle triangle_;
};

}  // namespace gpu
}  // namespace eik
