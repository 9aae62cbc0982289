// LedgerPass: the energy ledger (ALGORITHM.md "Bake output", energy check) summed on the GPU. Each
// step, one GL_POINTS primitive per patch (gl_VertexID = patch index) adds the patch's entries into
// one row of eight small RGBA32F targets (MRT, additive blending, gl::ScopedBlendAdd); every `rows`
// steps the rows are read back and folded into double sums, so float sums never run over more than
// one step and the only per-step readback stays the pyramid's total.
//
//   shader   shaders/lightsim/ledger.vert + ledger.frag (LEDGER_UNFINISHED: the unfinished flux)
//   step     the ledger of steps 2, 3 and 5: flux absorbed, reflected, exited, killed per reason,
//            kill and split counts; at the end the flux still alive (flux_unfinished)
//   in       addStep: StepTargets ledger A = (absorbed, fate code) and ledger B = (reflected, event)
//            from the analysis pass, and the updated list's FLUX, patches 0 .. count − 1;
//            addUnfinished: a list's FLUX
//   out      sum(column): (Φ.rgb, count) per LedgerColumn, in double, after flush()
//
// Within a row patch k adds into bin k mod kBins, so no texel sums more than count/kBins values and
// the points spread over many texels. The CPU twin keeps the same sums in its sequential deposit
// loop (CpuSimulator::run).
#pragma once

#include <array>
#include <cstddef>

#include <glm/vec4.hpp>

#include "gl/framebuffer.h"
#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/vertex_array.h"
#include "lightsim/patch_textures.h"
#include "lightsim/step_targets.h"

namespace eik::gpu {

// Ledger columns (shaders/lightsim/ledger.vert): (Φ.rgb, count) each; kAbsorbed has no count.
enum LedgerColumn {
  kAbsorbed = 0,
  kReflected,
  kExited,
  kKilledFlux,
  kFolded,
  kKilledDepth,
  kSplits,
  kUnfinished,
  // The extra entries (receivers, sharp interfaces; addStep with extra = true):
  kReceived,     // (Φ, count) that reached the receiver plane
  kBlocked,      // (Φ, count) stopped by opaque surfaces
  kSpawned,      // (0, count) reflected wavefronts followed
  kRolledBack,   // (0, count) steps undone before a crossing
  kLedgerColumns
};

// kLedgerColumns RGBA32F targets of kBins × rows texels, one row per step (or per addUnfinished).
class LedgerPass {
 public:
  static constexpr int kBins = 256;  // texels per row (patch k adds into bin k mod kBins)

  // rows: steps between readbacks (GpuSimulatorOptions::ledger_interval; at least 1).
  LedgerPass(const gl::ShaderLibrary& library, int rows);

  // All rows written: flush() (which the next add would do itself) before more are added.
  bool full() const { return row_ == rows_; }
  // Zero sums and rows, for a new run.
  void reset();

  // The entries of one step, from the analysis of the updated list `current`; `extra` adds the
  // receiver and sharp-interface entries (kReceived ..) in a second draw.
  void addStep(const StepTargets& targets, const PatchTextures& current, std::size_t count, bool extra = false);
  // The flux of the patches still alive at the end.
  void addUnfinished(const PatchTextures& list, std::size_t count);

  // Reads the rows written so far, adds them to the sums and clears them.
  void flush();

  const glm::dvec4& sum(LedgerColumn column) const { return sums_[static_cast<std::size_t>(column)]; }

 private:
  void clear();

  template <class Setup>
  void draw(const gl::Program& program, gl::Framebuffer& target, Setup&& setup, std::size_t points);

  static constexpr int kMainColumns = kReceived;  // in target_; the rest in extraTarget_
  int rows_;
  int row_ = 0;
  gl::Framebuffer target_;
  gl::Framebuffer extraTarget_;
  gl::Program step_;
  gl::Program extra_;
  gl::Program unfinished_;
  gl::VertexArray vao_;
  std::array<glm::dvec4, kLedgerColumns> sums_{};
};

}  // namespace eik::gpu
