// The GPU light simulator: passes, the step loop, the ledger and phase timing (see gpu_simulator.h).
#include "lightsim/gpu_simulator.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "gl/debug.h"
#include "gl/framebuffer.h"
#include "gl/handle.h"
#include "gl/shader_library.h"
#include "gl/vertex_array.h"
#include "gl/volume_textures.h"
#include "lightsim/atlas.h"
#include "lightsim/histo_pyramid.h"
#include "lightsim/patch_textures.h"
#include "lightsim/wavefront.h"

namespace eik {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

std::string bytesText(std::size_t bytes) {
  char text[64];
  std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return text;
}

// Ledger columns (shaders/lightsim/ledger.vert).
enum LedgerColumn {
  kAbsorbed = 0,
  kReflected,
  kExited,
  kKilledFlux,
  kFolded,
  kKilledDepth,
  kSplits,
  kUnfinished,
  kLedgerColumns
};

// ---------------------------------------------------------------------------------------------
// Phase timing (GpuSimulatorOptions::Timing).

struct QueryTraits {
  static void destroy(GLuint name) { glDeleteQueries(1, &name); }
};

class PhaseTimer {
 public:
  PhaseTimer(GpuSimulatorOptions::Timing mode, std::map<std::string, double>& out) : mode_(mode), out_(out) {}
  ~PhaseTimer() {
    // Leave no query active (results that are not collected are dropped).
    if (mode_ == GpuSimulatorOptions::Timing::Queries && running_) glEndQuery(GL_TIME_ELAPSED);
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

  // Ends the running phase and starts `name`.
  void start(const char* name) {
    stop();
    if (mode_ != GpuSimulatorOptions::Timing::Finish && mode_ != GpuSimulatorOptions::Timing::Queries) return;
    running_ = true;
    name_ = name;
    if (mode_ == GpuSimulatorOptions::Timing::Finish) {
      start_ = Clock::now();
    } else {
      if (free_.empty()) {
        GLuint id = 0;
        glGenQueries(1, &id);
        free_.emplace_back(id);
      }
      pending_.push_back({name_, std::move(free_.back())});
      free_.pop_back();
      glBeginQuery(GL_TIME_ELAPSED, pending_.back().query.get());
    }
  }

  void stop() {
    if (!running_) return;
    running_ = false;
    if (mode_ == GpuSimulatorOptions::Timing::Finish) {
      glFinish();
      out_[name_] += secondsSince(start_);
    } else if (mode_ == GpuSimulatorOptions::Timing::Queries) {
      glEndQuery(GL_TIME_ELAPSED);
    }
  }

  // Adds the results of finished queries (all of them, waiting, with `wait`).
  void collect(bool wait) {
    if (mode_ != GpuSimulatorOptions::Timing::Queries) return;
    std::size_t done = 0;
    for (; done < pending_.size(); ++done) {
      Pending& p = pending_[done];
      if (running_ && done + 1 == pending_.size()) break;  // the active one
      if (!wait) {
        GLint available = 0;
        glGetQueryObjectiv(p.query.get(), GL_QUERY_RESULT_AVAILABLE, &available);
        if (!available) break;
      }
      GLuint64 ns = 0;
      glGetQueryObjectui64v(p.query.get(), GL_QUERY_RESULT, &ns);
      out_[p.name] += static_cast<double>(ns) * 1e-9;
      free_.push_back(std::move(p.query));
    }
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(done));
  }

 private:
  struct Pending {
    std::string name;
    gl::GlHandle<QueryTraits> query;
  };
  GpuSimulatorOptions::Timing mode_;
  std::map<std::string, double>& out_;
  bool running_ = false;
  std::string name_;
  Clock::time_point start_;
  std::vector<Pending> pending_;
  std::vector<gl::GlHandle<QueryTraits>> free_;
};

// Sets the viewport to the live box of a list (after Framebuffer::bind set it to the whole list).
void viewportBox(glm::ivec2 box) { glViewport(0, 0, box.x, box.y); }

const gl::Sampling kNearest{gl::Filter::Nearest, gl::Wrap::ClampToEdge};

const char* integratorDefine(Integrator integrator) {
  switch (integrator) {
    case Integrator::RK4: return "INTEGRATOR_RK4";
    case Integrator::RK2: return "INTEGRATOR_RK2";
    case Integrator::Euler: break;
  }
  return "INTEGRATOR_EULER";
}

const char* depositDefine(DepositMode mode) { return mode == DepositMode::Max ? "DEPOSIT_MAX" : "DEPOSIT_ACCUMULATE"; }

}  // namespace

// ---------------------------------------------------------------------------------------------
// Passes (gpu_simulator.h).

namespace gpu {

StepTargets::StepTargets(int side, const gl::ShaderLibrary& library)
    : pyramid(side, library),
      depositA({side, side}, gl::TextureFormat::RGBA32F, kNearest),
      depositB({side, side}, gl::TextureFormat::RGBA32F, kNearest),
      ledgerA({side, side}, gl::TextureFormat::RGBA32F, kNearest),
      ledgerB({side, side}, gl::TextureFormat::RGBA32F, kNearest),
      framebuffer({side, side}) {
  framebuffer.attach(0, pyramid.base());
  framebuffer.attach(1, depositA);
  framebuffer.attach(2, depositB);
  framebuffer.attach(3, ledgerA);
  framebuffer.attach(4, ledgerB);
  framebuffer.checkComplete();
}

std::size_t StepTargets::bytesFor(int side) {
  // Pyramid: R32F base + RGBA32F levels (16/3 B a slot); four RGBA32F targets.
  const std::size_t texels = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  return texels * 4 + texels * 16 / 3 + 4 * texels * 16;
}

UpdatePass::UpdatePass(const gl::ShaderLibrary& library, Integrator integrator, const std::string& volumeDefines)
    : program_(library.program("common/fullscreen.vert", "lightsim/update.frag", {{integratorDefine(integrator), "1"}},
                               volumeDefines)) {}

void UpdatePass::run(const PatchTextures& in, PatchTextures& out, std::size_t count, const gl::VolumeTextures& volume,
                     const GridUniforms& grid, const StepUniforms& step) const {
  ScopedPassBindings unbind;
  out.framebuffer().bind();
  viewportBox(mortonBox(count));
  program_.use();
  volume.bind(program_, in.bind(program_, "uPatch", 0));
  grid.set(program_);
  program_.set("uCount", static_cast<int>(count));
  program_.set("uDt", step.dt);
  program_.set("uBoundaryOn", step.boundaryOn);
  program_.set("uBoundaryOff", step.boundaryOff);
  triangle_.draw();
  gl::checkErrors("UpdatePass");
}

AnalysisPass::AnalysisPass(const gl::ShaderLibrary& library, DepositMode mode, const AtlasLayout& atlas,
                           const std::string& volumeDefines) {
  gl::ShaderDefines defines = atlas.defines();
  defines.emplace_back(depositDefine(mode), "1");
  program_ = library.program("common/fullscreen.vert", "lightsim/analysis.frag", defines, volumeDefines);
}

void AnalysisPass::run(const PatchTextures& current, const PatchTextures& previous, std::size_t count,
                       StepTargets& targets, const gl::VolumeTextures& volume, const GridUniforms& grid,
                       const StepUniforms& step) const {
  ScopedPassBindings unbind;
  targets.framebuffer.bind();
  viewportBox(mortonBox(count));
  program_.use();
  int unit = current.bind(program_, "uPatch", 0);  // 8 units
  for (int c = 0; c < 4; ++c, ++unit) {
    previous.texture(PatchTextures::kP0 + c).bind(unit);
    program_.setSampler("uPrevious[" + std::to_string(c) + "]", unit);
  }
  previous.texture(PatchTextures::kFlux).bind(unit);
  program_.setSampler("uPreviousFlux", unit++);
  volume.bind(program_, unit);  // at most 2 (optics, absorption): 15 of the 16 units GL 3.3 guarantees
  grid.set(program_);
  program_.set("uCount", static_cast<int>(count));
  program_.set("uDt", step.dt);
  program_.set("uFluxKill", step.fluxKill);
  program_.set("uSplitLength", step.splitLength);
  program_.set("uMaxDepth", step.maxDepth);
  program_.set("uAxisSplit", step.axisSplit);
  program_.set("uKillAtMaxDepth", step.killAtMaxDepth);
  triangle_.draw();
  gl::checkErrors("AnalysisPass");
}

CompactPass::CompactPass(const gl::ShaderLibrary& library, const gl::ShaderDefines& pyramidDefines,
                         const std::string& volumeDefines)
    : program_(library.program("common/fullscreen.vert", "lightsim/compact.frag", pyramidDefines, volumeDefines)) {}

void CompactPass::run(const PatchTextures& in, const StepTargets& targets, PatchTextures& out, std::size_t total,
                      const gl::VolumeTextures& volume, const GridUniforms& grid) const {
  ScopedPassBindings unbind;
  out.framebuffer().bind();
  viewportBox(mortonBox(total));
  program_.use();
  int unit = in.bind(program_, "uPatch", 0);
  targets.pyramid.bind(unit);
  program_.setSampler("uPyramid", unit++);
  targets.ledgerA.bind(unit);
  program_.setSampler("uLedgerA", unit++);
  volume.bind(program_, unit);
  grid.set(program_);
  program_.set("uTotal", static_cast<int>(total));
  triangle_.draw();
  gl::checkErrors("CompactPass");
}

}  // namespace gpu

namespace {

// The energy ledger: kLedgerColumns RGBA32F targets of kBins × rows texels, one row per step,
// summed with additive blending (one point per patch writes all its entries, MRT), read back and
// folded into double sums every `rows` steps.
class Ledger {
 public:
  static constexpr int kBins = 256;  // texels per row (patch k adds into bin k mod kBins)

  Ledger(const gl::ShaderLibrary& library, int rows)
      : rows_(std::max(1, rows)),
        target_({kBins, rows_}, std::vector<gl::TextureFormat>(kLedgerColumns, gl::TextureFormat::RGBA32F)),
        step_(library.program("lightsim/ledger.vert", "lightsim/ledger.frag")),
        unfinished_(library.program("lightsim/ledger.vert", "lightsim/ledger.frag", {{"LEDGER_UNFINISHED", "1"}})),
        vao_(gl::VertexArray::create()) {
    clear();
  }

  bool full() const { return row_ == rows_; }
  // Zero sums and rows, for a new run.
  void reset() {
    clear();
    row_ = 0;
    sums_ = {};
  }

  // The entries of one step, from the analysis of the updated list `current`.
  void addStep(const gpu::StepTargets& targets, const PatchTextures& current, std::size_t count) {
    draw(step_, [&] {
      targets.ledgerA.bind(0);
      step_.setSampler("uLedgerA", 0);
      targets.ledgerB.bind(1);
      step_.setSampler("uLedgerB", 1);
      current.texture(PatchTextures::kFlux).bind(2);
      step_.setSampler("uFlux", 2);
    }, count);
  }
  // The flux of the patches still alive at the end.
  void addUnfinished(const PatchTextures& list, std::size_t count) {
    draw(unfinished_, [&] {
      list.texture(PatchTextures::kFlux).bind(0);
      unfinished_.setSampler("uFlux", 0);
    }, count);
  }

  // Reads the rows written so far, adds them to the sums and clears them.
  void flush() {
    if (row_ == 0) return;
    for (int c = 0; c < kLedgerColumns; ++c) {
      const std::vector<float> data = target_.readRGBA(c);
      const std::size_t used = static_cast<std::size_t>(row_) * kBins;  // rows from the bottom
      for (std::size_t i = 0; i < used; ++i) {
        sums_[static_cast<std::size_t>(c)] += glm::dvec4(data[i * 4], data[i * 4 + 1], data[i * 4 + 2], data[i * 4 + 3]);
      }
    }
    clear();
    row_ = 0;
  }

  const glm::dvec4& sum(LedgerColumn column) const { return sums_[static_cast<std::size_t>(column)]; }

 private:
  void clear() {
    for (int c = 0; c < kLedgerColumns; ++c) target_.clear(c, glm::vec4(0.0f));
  }

  template <class Setup>
  void draw(const gl::Program& program, Setup&& setup, std::size_t points) {
    if (full()) flush();
    if (points > 0) {
      ScopedPassBindings unbind;
      target_.bind();
      program.use();
      setup();
      program.set("uRow", row_);
      program.set("uBins", kBins);
      program.set("uLedgerSize", glm::vec2(static_cast<float>(kBins), static_cast<float>(rows_)));
      ScopedBlendAdd blend;
      vao_.bind();
      glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(points));
      gl::checkErrors("Ledger");
    }
    ++row_;
  }

  int rows_;
  int row_ = 0;
  gl::Framebuffer target_;
  gl::Program step_;
  gl::Program unfinished_;
  gl::VertexArray vao_;
  std::array<glm::dvec4, kLedgerColumns> sums_{};
};

// The two patch lists of one side and the targets of their analysis.
struct ListSet {
  PatchTextures a, b;  // a: the current list; b: the updated one
  gpu::StepTargets targets;

  ListSet(int side, const gl::ShaderLibrary& library) : a(side), b(side), targets(side, library) {}
  int side() const { return a.side(); }
  static std::size_t bytesFor(int side) {
    const std::size_t texels = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
    return 2 * texels * PatchTextures::kAttachments * 16 + gpu::StepTargets::bytesFor(side);
  }
};

// Only the fields the simulator reads, so nothing else takes texture memory.
Volume simulationFields(const Volume& volume) {
  Volume v;
  v.grid = volume.grid;
  for (const char* name : {"ior", "ior_grad", "sigma_a"}) {
    if (const Field* f = volume.find(name)) v.fields[name] = *f;
  }
  return v;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

struct GpuSimulator::Impl {
  GpuSimulatorOptions config;
  GridSpec grid;
  std::string renderer;
  AtlasLayout atlasLayout;  // planned (and the memory checked) before anything is uploaded
  int maxSide = 0;
  VolumeSampler sampler;    // the CPU twin's sampler, for initialPatches
  gl::ShaderLibrary library;
  gl::VolumeTextures volume;
  std::string volumeDefines;
  // The GPU works in grid-local coordinates, x − centre of the grid, so float positions keep their
  // precision however far the volume sits from the world origin.
  glm::dvec3 origin{0.0};
  GridUniforms gridUniforms;
  GpuRunInfo info;

  // Programs, made on first use and kept across runs.
  std::map<Integrator, std::unique_ptr<gpu::UpdatePass>> updates;
  std::map<DepositMode, std::unique_ptr<DepositPass>> deposits;
  std::map<DepositMode, std::unique_ptr<gpu::AnalysisPass>> analyses;
  std::map<int, std::unique_ptr<gpu::CompactPass>> compacts;  // by pyramid levels
  std::unique_ptr<Ledger> ledger;

  Impl(const Volume& v, const GpuSimulatorOptions& o)
      : config(o),
        grid(v.grid),
        renderer(gl::detail::requireContext("the GPU light simulator").summary()),
        atlasLayout(planAtlas(v, o)),
        maxSide(patchListLimit(o)),
        sampler(v),
        volume(uploadVolume(v, o)),
        volumeDefines(volume.layout().glslDefines() + (o.exact_sampling ? "#define EXACT_TRILINEAR 1\n" : "")),
        origin(0.5 * (grid.bounds_min + grid.bounds_max)),
        gridUniforms(GridUniforms::from(localGrid(grid, origin))) {}

  static GridSpec localGrid(GridSpec g, const glm::dvec3& origin) {
    g.bounds_min -= origin;
    g.bounds_max -= origin;
    return g;
  }

  // The atlas layout; InputError "volume too large for the GPU" when it does not fit
  // GL_MAX_TEXTURE_SIZE, or when the fields, the atlas and the smallest patch lists do not fit the
  // texture budget (checked before uploading anything).
  static AtlasLayout planAtlas(const Volume& v, const GpuSimulatorOptions& o) {
    const gl::GlContext& context = *gl::GlContext::current();
    const AtlasLayout layout = AtlasLayout::plan(v.grid.dims, context.info().maxTextureSize, o.source,
                                                 context.info().renderer);
    // Optics (n, ∇n) RGBA32F, absorption (σa) RGB32F: gl/volume_textures.h.
    const std::size_t fields =
        v.grid.count() * ((v.has("ior") || v.has("ior_grad") ? 16 : 0) + (v.has("sigma_a") ? 12 : 0));
    const std::size_t budget = o.budget_bytes ? o.budget_bytes : gl::defaultTextureBudget();
    const std::size_t needed = fields + AtlasTargets::bytesFor(layout, DepositMode::Max) + ListSet::bytesFor(64);
    if (needed > budget) {
      throw InputError(o.source, "dims",
                       "volume too large for the GPU: the light simulator needs at least " + bytesText(needed) +
                           " of texture memory for a grid of " + std::to_string(v.grid.dims.x) + "x" +
                           std::to_string(v.grid.dims.y) + "x" + std::to_string(v.grid.dims.z) +
                           " voxels (fields, flat-3D atlas, patch lists), over the budget of " + bytesText(budget) +
                           " (EIKONAL_GL_TEXTURE_BUDGET_MB)");
    }
    return layout;
  }

  // The largest power-of-two list side allowed: max_patch_side, GL_MAX_TEXTURE_SIZE and the
  // pyramid's limit.
  static int patchListLimit(const GpuSimulatorOptions& o) {
    const int limit = std::min({std::max(1, o.max_patch_side), gl::GlContext::current()->info().maxTextureSize,
                                HistoPyramidLimits::kMaxBaseSize});
    int side = 1;
    while (side * 2 <= limit) side *= 2;
    return side;
  }

  static gl::VolumeTextures uploadVolume(const Volume& v, const GpuSimulatorOptions& o) {
    gl::VolumeTextureOptions vo;
    vo.source = o.source;
    vo.budgetBytes = o.budget_bytes;
    return gl::VolumeTextures(simulationFields(v), vo);
  }

  gpu::UpdatePass& update(Integrator i) {
    auto& p = updates[i];
    if (!p) p = std::make_unique<gpu::UpdatePass>(library, i, volumeDefines);
    return *p;
  }
  DepositPass& deposit(DepositMode m) {
    auto& p = deposits[m];
    if (!p) p = std::make_unique<DepositPass>(library, atlasLayout, m);
    return *p;
  }
  gpu::AnalysisPass& analyse(DepositMode m) {
    auto& p = analyses[m];
    if (!p) p = std::make_unique<gpu::AnalysisPass>(library, m, atlasLayout, volumeDefines);
    return *p;
  }
  gpu::CompactPass& compact(const HistoPyramid& pyramid) {
    auto& p = compacts[pyramid.levels()];
    if (!p) p = std::make_unique<gpu::CompactPass>(library, pyramid.defines(), volumeDefines);
    return *p;
  }
  GpuSimulatorOptions::Timing timingMode() const {
    if (config.timing != GpuSimulatorOptions::Timing::Auto) return config.timing;
    const std::string& r = gl::GlContext::current()->info().renderer;
    const bool software = r.find("llvmpipe") != std::string::npos || r.find("softpipe") != std::string::npos ||
                          r.find("swrast") != std::string::npos;
    return software ? GpuSimulatorOptions::Timing::Off : GpuSimulatorOptions::Timing::Queries;
  }
  Ledger& ledgerFor() {
    if (!ledger) ledger = std::make_unique<Ledger>(library, config.ledger_interval);
    return *ledger;
  }

  BakeResult run(const LightSpec& light, const SimulationOptions& options);
};

GpuSimulator::GpuSimulator(const Volume& volume, GpuSimulatorOptions options) {
  if (!gl::GlContext::current()) {
    gl::ContextOptions co;
    co.backend = options.backend;
    ownedContext_ = std::make_unique<gl::GlContext>(co);
  }
  impl_ = std::make_unique<Impl>(volume, options);
}

GpuSimulator::~GpuSimulator() {
  if (ownedContext_) ownedContext_->makeCurrent();
  impl_.reset();
}

BakeResult GpuSimulator::run(const LightSpec& light, const SimulationOptions& options) {
  if (ownedContext_ && gl::GlContext::current() != ownedContext_.get()) ownedContext_->makeCurrent();
  return impl_->run(light, options);
}

const GpuRunInfo& GpuSimulator::lastRunInfo() const { return impl_->info; }
std::string GpuSimulator::renderer() const { return impl_->renderer; }

BakeResult GpuSimulator::Impl::run(const LightSpec& light, const SimulationOptions& options) {
  const auto runStart = Clock::now();
  ScopedPassBindings unbind;  // also when a step throws
  BakeResult bake;
  SimulationStats& stats = bake.stats;
  stats.backend = "gl";
  stats.renderer = renderer;
  info = GpuRunInfo{};
  info.atlas_size = atlasLayout.size;
  info.atlas_tiles = atlasLayout.tiles;
  info.volume_bytes = volume.bytes();
  const std::size_t voxels = grid.count();
  bake.irradiance.components = 3;
  bake.light_dir.components = 3;

  // Initialisation (§6.2.1) on the CPU, shared with the twin.
  auto t0 = Clock::now();
  double fluxRef = 0.0;
  const std::vector<Patch> initial = initialPatches(light, grid, sampler, options, &fluxRef);
  stats.initial_patches = initial.size();
  for (const Patch& p : initial) stats.flux_in += p.flux;
  if (initial.empty()) {  // the light misses the volume: an empty bake
    bake.irradiance.data.assign(voxels * 3, 0.0f);
    bake.light_dir.data.assign(voxels * 3, 0.0f);
    stats.phase_seconds["init"] = secondsSince(t0);
    if (options.progress) options.progress(1.0);
    info.wall_seconds = secondsSince(runStart);
    stats.phase_seconds["total"] = info.wall_seconds;
    return bake;
  }
  if (initial.size() > static_cast<std::size_t>(maxSide) * static_cast<std::size_t>(maxSide)) {
    throw RuntimeError("GPU light simulator: " + std::to_string(initial.size()) +
                       " initial patches exceed the patch list limit of " + std::to_string(maxSide) + "x" +
                       std::to_string(maxSide) + " (raise patch_voxels, or GpuSimulatorOptions::max_patch_side)");
  }
  std::vector<PatchTexels> packed(initial.size());
  for (std::size_t i = 0; i < initial.size(); ++i) {
    Patch local = initial[i];
    for (glm::dvec3& x : local.x) x -= origin;
    packed[i] = packPatch(local);
  }

  const int firstSide = std::min(maxSide, patchSideFor(initial.size(), 64));
  std::unique_ptr<ListSet> lists = std::make_unique<ListSet>(firstSide, library);
  lists->a.upload(packed);
  info.initial_patch_side = info.peak_patch_side = firstSide;

  AtlasTargets atlas(atlasLayout, options.deposit);
  info.atlas_bytes = atlas.bytes();
  Ledger& ledger = ledgerFor();
  ledger.reset();

  const double dt = timeStep(grid, options);
  gpu::StepUniforms step;
  step.dt = static_cast<float>(dt);
  step.boundaryOn = static_cast<float>(options.boundary_on);
  step.boundaryOff = static_cast<float>(options.boundary_off);
  step.fluxKill = static_cast<float>(options.flux_threshold * fluxRef);
  step.splitLength = static_cast<float>(splitThreshold(grid, options));  // split_voxels·h·(1 + margin)
  step.maxDepth = static_cast<float>(options.max_depth);
  step.axisSplit = options.split_rule == SplitRule::Axis;
  step.killAtMaxDepth = options.at_max_depth == DepthLimit::Kill;
  // E_ref of the max-mode depth mapping: a small irradiance, so that bright patches get depths near
  // 0 where Depth32F is most precise (largest initial E / 1000).
  double eRef = 0.0;
  for (const Patch& p : initial) eRef = std::max(eRef, luminance(p.irradiance()));
  const float energyRef = static_cast<float>(std::max(eRef * 1e-3, 1e-30));

  const gpu::UpdatePass& updatePass = update(options.integrator);
  const DepositPass& depositPass = deposit(options.deposit);
  const gpu::AnalysisPass& analysisPass = analyse(options.deposit);
  stats.phase_seconds["init"] = secondsSince(t0);

  const int maxSteps = eik::maxSteps(grid, options);
  const double totalIn = luminance(stats.flux_in);
  std::size_t count = initial.size();
  stats.peak_patches = count;
  PhaseTimer timer(timingMode(), stats.phase_seconds);
  auto report = [&] {
    ledger.flush();
    timer.collect(false);
    if (options.progress && totalIn > 0.0) {
      const glm::dvec4 retired = ledger.sum(kExited) + ledger.sum(kAbsorbed) + ledger.sum(kReflected) +
                                 ledger.sum(kKilledFlux) + ledger.sum(kFolded) + ledger.sum(kKilledDepth);
      options.progress(std::min(1.0, luminance(glm::dvec3(retired)) / totalIn));
    }
  };

  for (int s = 0; s < maxSteps && count > 0; ++s) {
    stats.steps = s + 1;
    stats.total_patches += count;
    stats.peak_patches = std::max<std::uint64_t>(stats.peak_patches, count);  // live at a step's start
    ListSet& L = *lists;

    timer.start("update");
    updatePass.run(L.a, L.b, count, volume, gridUniforms, step);
    timer.start("analysis");
    analysisPass.run(L.b, L.a, count, L.targets, volume, gridUniforms, step);
    timer.start("deposit");
    depositPass.run(L.targets.depositA, L.targets.depositB, count, atlas, energyRef);
    timer.start("ledger");
    ledger.addStep(L.targets, L.b, count);
    timer.start("pyramid");
    L.targets.pyramid.build(count);
    timer.stop();
    const auto readStart = Clock::now();
    const std::uint64_t total = L.targets.pyramid.readTotal();
    stats.phase_seconds["readback"] += secondsSince(readStart);

    if (total > L.a.capacity()) {
      // Grow: a new pair of lists of the side that holds `total`; compaction writes the new list
      // from the old updated list (nothing to copy), then the old set goes.
      if (total > static_cast<std::uint64_t>(maxSide) * static_cast<std::uint64_t>(maxSide)) {
        throw RuntimeError("GPU light simulator: step " + std::to_string(s + 1) + " needs " + std::to_string(total) +
                           " patches, over the patch list limit of " + std::to_string(maxSide) + "x" +
                           std::to_string(maxSide) + " = " + std::to_string(maxSide * maxSide) +
                           " (GpuSimulatorOptions::max_patch_side, GL_MAX_TEXTURE_SIZE); raise split_voxels or "
                           "lower max_depth");
      }
      const int side = std::min(maxSide, patchSideFor(total, L.side() * 2));
      const std::size_t budget = config.budget_bytes ? config.budget_bytes : gl::defaultTextureBudget();
      const std::size_t needed = info.volume_bytes + info.atlas_bytes + ListSet::bytesFor(L.side()) +
                                 ListSet::bytesFor(side);  // the old set lives until the compaction
      if (needed > budget) {
        throw RuntimeError("GPU light simulator: step " + std::to_string(s + 1) + " needs " + std::to_string(total) +
                           " patches, a patch list of " + std::to_string(side) + "x" + std::to_string(side) +
                           " that takes the texture memory to " + bytesText(needed) + ", over the budget of " +
                           bytesText(budget) + " (EIKONAL_GL_TEXTURE_BUDGET_MB); raise split_voxels or lower "
                           "max_depth");
      }
      timer.start("grow");
      auto grown = std::make_unique<ListSet>(side, library);
      timer.start("compact");
      compact(L.targets.pyramid).run(L.b, L.targets, grown->a, total, volume, gridUniforms);
      timer.stop();
      lists = std::move(grown);
      info.peak_patch_side = std::max(info.peak_patch_side, lists->side());
    } else if (total > 0) {
      timer.start("compact");
      compact(L.targets.pyramid).run(L.b, L.targets, L.a, total, volume, gridUniforms);
      timer.stop();
    }
    count = static_cast<std::size_t>(total);
    if (ledger.full()) report();
  }
  if (count > 0) ledger.addUnfinished(lists->a, count);
  report();
  timer.collect(true);

  stats.splits = static_cast<std::uint64_t>(std::llround(ledger.sum(kSplits).w));
  stats.kills.exited = static_cast<std::uint64_t>(std::llround(ledger.sum(kExited).w));
  stats.kills.flux = static_cast<std::uint64_t>(std::llround(ledger.sum(kKilledFlux).w));
  stats.kills.folded = static_cast<std::uint64_t>(std::llround(ledger.sum(kFolded).w));
  stats.kills.depth = static_cast<std::uint64_t>(std::llround(ledger.sum(kKilledDepth).w));
  stats.flux_absorbed = glm::dvec3(ledger.sum(kAbsorbed));
  stats.flux_reflected = glm::dvec3(ledger.sum(kReflected));
  stats.flux_out = glm::dvec3(ledger.sum(kExited));
  stats.flux_killed = glm::dvec3(ledger.sum(kKilledFlux) + ledger.sum(kFolded) + ledger.sum(kKilledDepth));
  stats.flux_unfinished = glm::dvec3(ledger.sum(kUnfinished));

  t0 = Clock::now();
  atlas.toFields(bake.irradiance, bake.light_dir);
  stats.phase_seconds["output"] = secondsSince(t0);

  info.patch_bytes_peak = ListSet::bytesFor(info.peak_patch_side);
  info.texture_bytes_peak = info.volume_bytes + info.atlas_bytes + info.patch_bytes_peak;
  info.wall_seconds = secondsSince(runStart);
  stats.phase_seconds["total"] = info.wall_seconds;
  if (options.progress) options.progress(1.0);
  return bake;
}

}  // namespace eik
