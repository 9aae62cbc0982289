// The GPU light simulator's step loop (see gpu_simulator.h): GpuSimulator::Impl owns the volume
// textures, the passes (made on first use) and the ledger, and run() drives one bake through them.
#include "lightsim/gpu_simulator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "core/error.h"
#include "core/interfaces.h"
#include "core/stopwatch.h"
#include "gl/scoped_state.h"
#include "gl/shader_library.h"
#include "gl/time_query.h"
#include "gl/volume_textures.h"
#include "lightsim/analysis_pass.h"
#include "lightsim/atlas.h"
#include "lightsim/compact_pass.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/deposit_pass.h"
#include "lightsim/grid_uniforms.h"
#include "lightsim/histo_pyramid.h"
#include "lightsim/ledger_pass.h"
#include "lightsim/list_set.h"
#include "lightsim/live_count.h"
#include "lightsim/morton.h"
#include "lightsim/patch_textures.h"
#include "lightsim/quiet_texture.h"
#include "lightsim/receiver.h"
#include "lightsim/receiver_pass.h"
#include "lightsim/step_uniforms.h"
#include "lightsim/track_deposit.h"
#include "lightsim/track_deposit_pass.h"
#include "lightsim/update_pass.h"
#include "lightsim/wavefront.h"

namespace eik {

namespace {

std::string bytesText(std::size_t bytes) {
  char text[64];
  std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return text;
}

// Only the fields the simulator reads, so nothing else takes texture memory. The passes sample
// the four slot distances and (n, ∇n) as one RGBA texture each: a field of fewer distances (one per
// slot) gets the unused slots' +band, a volume without ∇n (core/interfaces.h constantSlots) zeros.
Volume simulationFields(const Volume& volume) {
  Volume v;
  v.grid = volume.grid;
  for (const char* name : {"ior", "ior_grad", "sigma_a", "interfaces"}) {
    if (const Field* f = volume.find(name)) v.fields[name] = *f;
  }
  if (const Field* d = volume.find("interfaces")) v.fields["interfaces"] = fourSlotDistances(*d, interfaceTable(volume).band);
  if (!v.has("ior_grad") && v.has("ior")) v.addField("ior_grad", 3);
  return v;
}

}  // namespace

struct GpuSimulator::Impl {
  GpuSimulatorOptions config;
  GridSpec grid;
  std::string renderer;
  AtlasLayout atlasLayout;  // planned (and the memory checked) before anything is uploaded
  int maxSide = 0;
  VolumeSampler sampler;    // the CPU twin's sampler, for initialPatches
  bool sharp = false;       // the volume has sharp interfaces (SHARP_INTERFACES in the passes)
  gl::ShaderLibrary library;
  gl::VolumeTextures volume;
  std::string volumeDefines;
  // The GPU works in grid-local coordinates, x − centre of the grid, so float positions keep their
  // precision however far the volume sits from the world origin.
  glm::dvec3 origin{0.0};
  gpu::GridUniforms gridUniforms;
  GpuRunInfo info;

  // Programs, made on first use and kept across runs.
  std::map<std::tuple<Integrator, bool, bool>, std::unique_ptr<gpu::UpdatePass>> updates;  // + flight, absorber map
  std::map<DepositMode, std::unique_ptr<gpu::DepositPass>> deposits;
  std::map<std::tuple<DepositMode, bool, bool>, std::unique_ptr<gpu::AnalysisPass>> analyses;
  std::map<int, std::unique_ptr<gpu::CompactPass>> compacts;  // by pyramid levels
  std::unique_ptr<gpu::LedgerPass> ledger;
  std::unique_ptr<gpu::ReceiverPass> receiverPass;
  std::unique_ptr<gpu::TrackDepositPass> trackPass;
  // The quiet maps' tables (free flight; straight steps in absorbing volumes), made on first use.
  gpu::QuietTexture quietTable, absorberTable;

  Impl(const Volume& v, const GpuSimulatorOptions& o)
      : config(o),
        grid(v.grid),
        renderer(gl::detail::requireContext("the GPU light simulator").summary()),
        atlasLayout(planAtlas(v, o)),
        maxSide(patchListLimit(o)),
        sampler(v),
        sharp(sampler.sharp()),
        volume(uploadVolume(v, o)),
        volumeDefines(volume.layout().glslDefines() + (o.exact_sampling ? "#define EXACT_TRILINEAR 1\n" : "") +
                      (sharp ? "#define SHARP_INTERFACES 1\n" : "") +
                      (sampler.absorptionPerMaterial() ? "#define MATERIAL_ABSORPTION 1\n" : "") +
                      airBoxDefines(sampler, 0.5 * (grid.bounds_min + grid.bounds_max))),
        origin(0.5 * (grid.bounds_min + grid.bounds_max)),
        gridUniforms(gpu::GridUniforms::from(localGrid(grid, origin), interfaceTable(v, o.source))) {
    if (sampler.absorptionPerMaterial())
      for (int k = 0; k < gridUniforms.slotCount; ++k)
        gridUniforms.slotSigmaA[static_cast<std::size_t>(k)] = glm::vec3(sampler.materialSigmaA(k));
  }

  // The smoke's box (VolumeSampler::airBox) in grid-local coordinates, and its σa (sharp.glsl).
  static std::string airBoxDefines(const VolumeSampler& sampler, const glm::dvec3& origin) {
    if (!sampler.absorptionPerMaterial() || !sampler.airBox()) return "";
    auto vec3Of = [](const glm::dvec3& v) {
      char text[96];
      std::snprintf(text, sizeof text, "vec3(%.9g, %.9g, %.9g)", v.x, v.y, v.z);
      return std::string(text);
    };
    const AirMedium& air = *sampler.airBox();
    return "#define AIR_BOX 1\n#define AIR_BOX_LO " + vec3Of(air.lo - origin) + "\n#define AIR_BOX_HI " +
           vec3Of(air.hi - origin) + "\n#define AIR_SIGMA_A " + vec3Of(air.sigma_a) + "\n";
  }

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
        v.grid.count() *
        ((v.has("ior") || v.has("ior_grad") ? 16 : 0) + (v.has("sigma_a") ? 12 : 0) + (v.has("interfaces") ? 16 : 0));
    const std::size_t budget = o.budget_bytes ? o.budget_bytes : gl::defaultTextureBudget();
    const std::size_t needed = fields + AtlasTargets::bytesFor(layout, DepositMode::Max) + gpu::ListSet::bytesFor(64);
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

  gpu::UpdatePass& update(Integrator i, const gpu::UpdateMaps& maps) {
    const bool flight = maps.quiet != nullptr, absorbers = maps.absorbers != nullptr;
    auto& p = updates[{i, flight, absorbers}];
    if (!p) p = std::make_unique<gpu::UpdatePass>(library, i, volumeDefines, flight, absorbers);
    return *p;
  }
  // The maps a run of `options` reads: free flight with track deposits (with volume deposits only
  // as far as the track deposit pass reaches, StepUniforms::flightExtentVoxels), straight steps
  // where straightSteps allows them (an absorbing volume's, unless σa is per material, only where its
  // absorber map finds σa = 0).
  gpu::UpdateMaps updateMaps(const SimulationOptions& options, bool track) {
    gpu::UpdateMaps maps;
    if (options.free_flight && track) {
      if (!quietTable) quietTable = gpu::QuietTexture(sampler.quietMap());
      if (quietTable) maps.quiet = &quietTable;
    }
    if (straightSteps(sampler, options) && sampler.hasAbsorption() && !sampler.absorptionPerMaterial()) {
      if (!absorberTable) absorberTable = gpu::QuietTexture(sampler.absorberMap());
      if (absorberTable) maps.absorbers = &absorberTable;
    }
    return maps;
  }
  gpu::DepositPass& deposit(DepositMode m) {
    auto& p = deposits[m];
    if (!p) p = std::make_unique<gpu::DepositPass>(library, atlasLayout, m);
    return *p;
  }
  gpu::AnalysisPass& analyse(DepositMode m, bool track, bool receiver) {
    auto& p = analyses[{m, track, receiver}];
    if (!p) p = std::make_unique<gpu::AnalysisPass>(library, m, atlasLayout, volumeDefines, track, receiver);
    return *p;
  }
  gpu::CompactPass& compact(const HistoPyramid& pyramid) {
    auto& p = compacts[pyramid.levels()];
    if (!p) p = std::make_unique<gpu::CompactPass>(library, pyramid.defines(), volumeDefines);
    return *p;
  }
  // GpuSimulatorOptions::timing, Auto resolved for the current renderer.
  gl::PhaseTimer::Mode timingMode() const {
    switch (config.timing) {
      case GpuSimulatorOptions::Timing::Off: return gl::PhaseTimer::Mode::Off;
      case GpuSimulatorOptions::Timing::Queries: return gl::PhaseTimer::Mode::Queries;
      case GpuSimulatorOptions::Timing::Finish: return gl::PhaseTimer::Mode::Finish;
      case GpuSimulatorOptions::Timing::Auto: break;
    }
    return gl::isSoftwareRenderer(gl::GlContext::current()->info()) ? gl::PhaseTimer::Mode::Off
                                                                    : gl::PhaseTimer::Mode::Queries;
  }
  // GpuSimulatorOptions::count_readback, Auto resolved for the current renderer.
  bool overlapCounts() const {
    switch (config.count_readback) {
      case GpuSimulatorOptions::CountReadback::Wait: return false;
      case GpuSimulatorOptions::CountReadback::Overlap: return true;
      case GpuSimulatorOptions::CountReadback::Auto: break;
    }
    return !gl::isSoftwareRenderer(gl::GlContext::current()->info());
  }
  gpu::TrackDepositPass& trackPassFor() {
    if (!trackPass) trackPass = std::make_unique<gpu::TrackDepositPass>(library, atlasLayout);
    return *trackPass;
  }
  gpu::ReceiverPass& receiverPassFor() {
    if (!receiverPass) receiverPass = std::make_unique<gpu::ReceiverPass>(library);
    return *receiverPass;
  }
  gpu::LedgerPass& ledgerFor() {
    if (!ledger) ledger = std::make_unique<gpu::LedgerPass>(library, config.ledger_interval);
    return *ledger;
  }

  BakeResult run(const LightSpec& light, const SimulationOptions& options);
};

GpuSimulator::GpuSimulator(const Volume& volume, GpuSimulatorOptions options)
    : GpuSimulator(volume, std::move(options), nullptr) {}

GpuSimulator::GpuSimulator(const Volume& volume, GpuSimulatorOptions options, std::unique_ptr<gl::GlContext> context)
    : ownedContext_(std::move(context)) {
  if (ownedContext_ && gl::GlContext::current() != ownedContext_.get()) ownedContext_->makeCurrent();
  if (!ownedContext_ && !gl::GlContext::current()) {  // none given, none current: a headless one
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

nlohmann::json GpuSimulator::lastRunStats() const {
  const GpuRunInfo& info = impl_->info;
  nlohmann::json stats = nlohmann::json::object();
  stats["texture_bytes"] = {{"volume", info.volume_bytes},
                            {"atlas", info.atlas_bytes},
                            {"patch_lists_peak", info.patch_bytes_peak},
                            {"total_peak", info.texture_bytes_peak}};
  stats["count_readback"] = {{"mode", info.overlapped_counts ? "overlap" : "wait"},
                             {"steps_waited", info.waited_counts}};
  return stats;
}

const GpuRunInfo& GpuSimulator::lastRunInfo() const { return impl_->info; }
std::string GpuSimulator::renderer() const { return impl_->renderer; }

BakeResult GpuSimulator::Impl::run(const LightSpec& light, const SimulationOptions& options) {
  const Stopwatch runWatch;
  gl::ScopedPassBindings unbind;  // also when a step throws
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

  const bool track = options.deposit == DepositMode::Accumulate && options.deposit_kernel == DepositKernel::Track;
  if (options.receiver && !track)
    throw InputError("lightsim options", "receiver",
                     "the GPU path makes receiver maps with track deposits only (deposit accumulate, kernel track)");
  const PatchLayout layout = sharp ? PatchLayout::Sharp : PatchLayout::Smooth;

  // Initialisation (§6.2.1) on the CPU, shared with the twin; the receiver's map geometry first
  // (the initial patches cover it).
  Stopwatch phaseWatch;
  glm::dvec3 boxLo, boxHi;
  propagationBox(grid, options, boxLo, boxHi);
  ReceiverMap receiver;
  if (options.receiver) {
    receiver = options.receiver_geometry ? *options.receiver_geometry
                                         : receiverGeometry(*options.receiver, light, grid, boxLo, boxHi);
    receiver.irradiance.clear();
  }
  double fluxRef = 0.0;
  DirectCells direct;  // cells that go straight to the receiver's map: in closed form, not followed
  std::vector<Patch> initial = initialPatches(light, grid, sampler, options, &fluxRef,
                                              options.receiver ? &receiver : nullptr, &direct);
  std::vector<glm::dvec3> directFlux;
  if (direct.cells > 0) directFlux = directMapLight(receiver, light, initial).texels();
  adjustInitialPatches(initial, sampler, options, fluxRef);
  stats.initial_patches = initial.size();
  for (const Patch& p : initial) stats.flux_in += p.flux;
  if (initial.empty()) {  // the light misses the volume: an empty bake
    if (options.volume_deposits) {
      bake.irradiance.data.assign(voxels * 3, 0.0f);
      bake.light_dir.data.assign(voxels * 3, 0.0f);
    }
    if (options.receiver) {
      receiver.irradiance.assign(receiver.texelCount() * 3, 0.0f);
      const double inv_area = 1.0 / (receiver.pitch * receiver.pitch);
      for (std::size_t t = 0; t < directFlux.size(); ++t)
        for (int c = 0; c < 3; ++c)
          receiver.irradiance[3 * t + static_cast<std::size_t>(c)] = static_cast<float>(directFlux[t][c] * inv_area);
      bake.receivers.push_back(std::move(receiver));
    }
    stats.flux_in += direct.flux;
    stats.flux_received += direct.flux;
    stats.phase_seconds["init"] = phaseWatch.seconds();
    if (options.progress) options.progress(1.0);
    info.wall_seconds = runWatch.seconds();
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
    packed[i] = packPatch(local, layout);
  }

  const int firstSide = std::min(maxSide, patchSideFor(initial.size(), 64));
  std::unique_ptr<gpu::ListSet> lists = std::make_unique<gpu::ListSet>(firstSide, library);
  lists->a.upload(packed);
  info.initial_patch_side = info.peak_patch_side = firstSide;

  AtlasTargets atlas(atlasLayout, options.deposit);
  info.atlas_bytes = atlas.bytes();
  gpu::ReceiverTarget receiverTarget;
  if (options.receiver) {
    receiverTarget = gpu::ReceiverTarget(receiver.texels);
    info.atlas_bytes += receiverTarget.bytes();
  }
  gpu::LedgerPass& ledger = ledgerFor();
  ledger.reset();

  gpu::StepUniforms step = gpu::StepUniforms::from(localGrid(grid, origin), options, fluxRef);
  const gpu::UpdateMaps maps = updateMaps(options, track);
  info.volume_bytes = volume.bytes() + quietTable.bytes() + absorberTable.bytes();
  {
    // A straight step's time and reach, as the twin takes them (Δt where they do not apply).
    const StepContext twin = makeStepContext(sampler, options, fluxRef);
    step.stepDt = static_cast<float>(twin.step_dt);
    step.reflectedStepDt = static_cast<float>(twin.reflected_step_dt);
    step.straightReach = static_cast<float>(twin.straight_reach);
    step.retakeAtInterfaces = twin.retake_at_interfaces;
  }
  if (options.receiver) {
    step.receiverPoint = glm::vec3(receiver.point - origin);
    step.receiverNormal = glm::vec3(receiver.normal);
    step.passToReceiver = tornLightPassesToReceiver(sampler, options);
  }
  // E_ref of the max-mode depth mapping: a small irradiance, so that bright patches get depths near
  // 0 where Depth32F is most precise (largest initial E / 1000).
  double eRef = 0.0;
  for (const Patch& p : initial) eRef = std::max(eRef, luminance(p.irradiance()));
  const float energyRef = static_cast<float>(std::max(eRef * 1e-3, 1e-30));

  const gpu::UpdatePass& updatePass = update(options.integrator, maps);
  const gpu::DepositPass& depositPass = deposit(options.deposit);
  // Track deposits: the bound on a patch-step's extent (in voxels, any axis) that sizes the pass's
  // points. Patches are split at split_voxels and kept up to kMaxUnsplitEdge split lengths, a
  // quadrilateral spans at most twice its longest edge, and a step adds step_voxels; half as much
  // again covers patches that stretch within one step before the analysis splits them.
  gpu::TrackDepositUniforms trackUniforms;
  if (track) {
    trackUniforms.grid = gridUniforms;
    trackUniforms.receiverEnabled = options.receiver.has_value();
    trackUniforms.receiverPoint = step.receiverPoint;
    trackUniforms.receiverNormal = step.receiverNormal;
    trackUniforms.dimIrradiance = static_cast<float>(kDimTrackFraction * brightestIrradiance(light, grid));
    const double step_voxels = std::max({options.step_voxels, static_cast<double>(step.stepDt) / voxelEdge(grid),
                                         static_cast<double>(step.reflectedStepDt) / voxelEdge(grid)});
    const double extent = 2.0 * kMaxUnsplitEdge * options.split_voxels + step_voxels;
    trackUniforms.maxExtentVoxels =
        std::min(trackPassFor().maxExtentVoxels(), static_cast<int>(std::ceil(1.5 * extent)) + 2);
    if (options.volume_deposits) step.flightExtentVoxels = static_cast<float>(trackUniforms.maxExtentVoxels);
  }
  const gpu::AnalysisPass& analysisPass = analyse(options.deposit, track, options.receiver.has_value());
  const bool extraLedger = sharp || options.receiver.has_value();
  stats.phase_seconds["init"] = phaseWatch.seconds();

  const int maxSteps = eik::maxSteps(grid, options);
  const double totalIn = luminance(stats.flux_in);
  gl::PhaseTimer timer(timingMode(), stats.phase_seconds);
  auto report = [&] {
    ledger.flush();
    timer.collect(false);
    if (options.progress && totalIn > 0.0) {
      const glm::dvec4 retired = ledger.sum(gpu::kExited) + ledger.sum(gpu::kAbsorbed) +
                                 ledger.sum(gpu::kReflected) + ledger.sum(gpu::kKilledFlux) +
                                 ledger.sum(gpu::kFolded) + ledger.sum(gpu::kKilledDepth) +
                                 ledger.sum(gpu::kReceived) + ledger.sum(gpu::kBlocked) +
                                 ledger.sum(gpu::kUnfinished);  // trapped light, until the end
      options.progress(std::min(1.0, luminance(glm::dvec3(retired)) / totalIn));
    }
  };

  // The count of the live list stays on the GPU (live_count.h): each step's passes read it there
  // and are drawn over `slots` ≥ it. `known` is the count when the CPU has it (`haveCount`); with
  // Overlap the CPU collects a step's count after the next step's passes are queued
  // (GpuSimulatorOptions::CountReadback).
  const bool overlap = overlapCounts();
  info.overlapped_counts = overlap;
  gpu::LiveCount live;
  live.set(initial.size());
  std::size_t slots = initial.size();
  std::uint64_t known = initial.size();
  bool haveCount = true;
  auto collect = [&] {
    const Stopwatch readWatch;
    const std::uint64_t n = live.wait();
    stats.phase_seconds["readback"] += readWatch.seconds();
    return n;
  };
  // A list set that holds `needed` slots, within max_patch_side and the texture budget; nullptr
  // when none does (`s`: the step, for the error of a list that must grow and cannot).
  auto listFor = [&](std::uint64_t needed, int s, bool mustFit) -> std::unique_ptr<gpu::ListSet> {
    const std::uint64_t maxSlots = static_cast<std::uint64_t>(maxSide) * static_cast<std::uint64_t>(maxSide);
    if (needed > maxSlots) {
      if (!mustFit) return nullptr;
      throw RuntimeError("GPU light simulator: step " + std::to_string(s + 1) + " needs " + std::to_string(needed) +
                         " patches, over the patch list limit of " + std::to_string(maxSide) + "x" +
                         std::to_string(maxSide) + " = " + std::to_string(maxSlots) +
                         " (GpuSimulatorOptions::max_patch_side, GL_MAX_TEXTURE_SIZE); raise split_voxels or "
                         "lower max_depth");
    }
    const int side = std::min(maxSide, patchSideFor(needed, lists->side() * 2));
    const std::size_t budget = config.budget_bytes ? config.budget_bytes : gl::defaultTextureBudget();
    const std::size_t bytes = info.volume_bytes + info.atlas_bytes + gpu::ListSet::bytesFor(lists->side()) +
                              gpu::ListSet::bytesFor(side);  // the old set lives until the compaction
    if (bytes > budget) {
      if (!mustFit) return nullptr;
      throw RuntimeError("GPU light simulator: step " + std::to_string(s + 1) + " needs " + std::to_string(needed) +
                         " patches, a patch list of " + std::to_string(side) + "x" + std::to_string(side) +
                         " that takes the texture memory to " + bytesText(bytes) + ", over the budget of " +
                         bytesText(budget) + " (EIKONAL_GL_TEXTURE_BUDGET_MB); raise split_voxels or lower "
                         "max_depth");
    }
    timer.start("grow");
    auto grown = std::make_unique<gpu::ListSet>(side, library);
    timer.stop();
    return grown;
  };

  for (int s = 0; s < maxSteps && slots > 0; ++s) {
    if (options.cancel && options.cancel->load(std::memory_order_relaxed)) throw BakeCancelled();
    gpu::ListSet& L = *lists;

    timer.start("update");
    updatePass.run(L.a, L.b, live, slots, volume, gridUniforms, step, maps);
    timer.start("analysis");
    analysisPass.run(L.b, L.a, live, slots, L.targets, volume, gridUniforms, step);
    if (options.on_leave) {
      // The patches that left the box this step (a scene's light from object to object,
      // SimulationOptions::on_leave), read back in list order: exited, or received from outside the
      // box. Only scenes of several objects ask for it; it costs a read of the fate codes a step,
      // and of the patch list on the steps where one left.
      timer.start("leaving");
      const std::vector<float> codes = L.targets.ledgerA.download(4);
      const int side = L.a.side();
      std::vector<std::size_t> leaving;
      for (std::size_t k = 0; k < slots; ++k) {
        const glm::ivec2 t = mortonTexel(static_cast<std::uint32_t>(k));
        const int fate = static_cast<int>(codes[(static_cast<std::size_t>(t.y) * static_cast<std::size_t>(side) +
                                                 static_cast<std::size_t>(t.x)) * 4 + 3]) & 15;
        if (fate == gpu::kFateExited || fate == gpu::kFateReceived) leaving.push_back(k);
      }
      if (!leaving.empty()) {
        const std::vector<PatchTexels> after = L.b.download(slots);
        for (const std::size_t k : leaving) {
          Patch patch = unpackPatch(after[k], layout);
          for (glm::dvec3& x : patch.x) x += origin;
          if (!insideBox(patch.midpoint(), boxLo, boxHi)) options.on_leave(patch);
        }
      }
    }
    timer.start("deposit");
    if (!options.volume_deposits) {
      // only the receiver's map (below)
    } else if (track) {
      trackPassFor().run(L.a, L.b, L.targets.depositA, slots, atlas, trackUniforms);
    } else {
      depositPass.run(L.targets.depositA, L.targets.depositB, slots, atlas, energyRef);
    }
    if (options.receiver) {
      timer.start("receiver");
      receiverPassFor().run(L.b, L.targets.depositB, slots, receiverTarget, receiver, origin);
    }
    timer.start("ledger");
    ledger.addStep(L.targets, L.b, slots, extraLedger);
    timer.start("pyramid");
    L.targets.pyramid.build(slots);  // the analysis wrote count 0 past the live patches
    live.takeTotal(L.targets.pyramid);
    timer.stop();

    // This step's count: known, or collected now that its passes are queued behind the read.
    if (!haveCount) known = collect();
    haveCount = true;
    const std::uint64_t count = known;
    if (count == 0) break;  // the step did nothing
    stats.steps = s + 1;
    stats.total_patches += count;
    stats.peak_patches = std::max<std::uint64_t>(stats.peak_patches, count);  // live at a step's start

    live.request();  // the new count
    std::unique_ptr<gpu::ListSet> grown;
    const std::uint64_t bound = std::uint64_t{GpuSimulatorOptions::kMaxChildren} * count;
    if (overlap && (bound <= L.a.capacity() || (grown = listFor(bound, s, false)))) {
      haveCount = false;  // collected in the next step
      slots = bound;
    } else {
      ++info.waited_counts;
      known = collect();
      slots = known;
      if (slots > L.a.capacity()) grown = listFor(slots, s, true);
    }
    if (slots > 0) {
      // Compaction writes the new list (into a grown set's: nothing to copy; the old set goes).
      timer.start("compact");
      compact(L.targets.pyramid).run(L.b, L.targets, grown ? grown->a : L.a, slots, volume, gridUniforms, step.stepDt,
                                     step.reflectedStepDt);
      timer.stop();
    }
    if (grown) {
      lists = std::move(grown);
      info.peak_patch_side = std::max(info.peak_patch_side, lists->side());
    }
    if (ledger.full()) report();
  }
  if (!haveCount) {
    ++info.waited_counts;
    known = collect();
  }
  // The list left when the steps ran out (0 when the light is done).
  const auto unfinished_at_end = static_cast<std::size_t>(known);
  if (unfinished_at_end > 0) ledger.addUnfinished(lists->a, unfinished_at_end);
  report();
  timer.collect(true);

  stats.splits = static_cast<std::uint64_t>(std::llround(ledger.sum(gpu::kSplits).w));
  stats.kills.exited = static_cast<std::uint64_t>(std::llround(ledger.sum(gpu::kExited).w));
  stats.kills.flux = static_cast<std::uint64_t>(std::llround(ledger.sum(gpu::kKilledFlux).w));
  stats.kills.folded = static_cast<std::uint64_t>(std::llround(ledger.sum(gpu::kFolded).w));
  stats.kills.depth = static_cast<std::uint64_t>(std::llround(ledger.sum(gpu::kKilledDepth).w));
  stats.flux_absorbed = glm::dvec3(ledger.sum(gpu::kAbsorbed));
  stats.flux_reflected = glm::dvec3(ledger.sum(gpu::kReflected));
  stats.flux_out = glm::dvec3(ledger.sum(gpu::kExited));
  stats.flux_killed =
      glm::dvec3(ledger.sum(gpu::kKilledFlux) + ledger.sum(gpu::kFolded) + ledger.sum(gpu::kKilledDepth));
  stats.flux_unfinished = glm::dvec3(ledger.sum(gpu::kUnfinished));
  // The unfinished entry counts the trapped patches and the list left at the end.
  const double unfinished_patches = ledger.sum(gpu::kUnfinished).w;
  stats.kills.trapped =
      static_cast<std::uint64_t>(std::max(0.0, std::round(unfinished_patches) - static_cast<double>(unfinished_at_end)));
  stats.kills.received = static_cast<std::uint64_t>(std::llround(ledger.sum(gpu::kReceived).w));
  stats.kills.blocked = static_cast<std::uint64_t>(std::llround(ledger.sum(gpu::kBlocked).w));
  stats.flux_received = glm::dvec3(ledger.sum(gpu::kReceived));
  stats.flux_blocked = glm::dvec3(ledger.sum(gpu::kBlocked));
  // The direct light's cells: in, and received (after the run: the progress counts followed light).
  stats.flux_in += direct.flux;
  stats.flux_received += direct.flux;
  stats.reflections = static_cast<std::uint64_t>(std::llround(ledger.sum(gpu::kSpawned).w));
  stats.rollbacks = static_cast<std::uint64_t>(std::llround(ledger.sum(gpu::kRolledBack).w));

  phaseWatch.restart();
  if (options.volume_deposits) atlas.toFields(bake.irradiance, bake.light_dir);
  if (options.receiver) {
    receiverTarget.fill(receiver, directFlux);
    bake.receivers.push_back(std::move(receiver));
  }
  stats.phase_seconds["output"] = phaseWatch.seconds();

  info.patch_bytes_peak = gpu::ListSet::bytesFor(info.peak_patch_side);
  info.texture_bytes_peak = info.volume_bytes + info.atlas_bytes + info.patch_bytes_peak;
  info.wall_seconds = runWatch.seconds();
  stats.phase_seconds["total"] = info.wall_seconds;
  if (options.progress) options.progress(1.0);
  return bake;
}

}  // namespace eik
