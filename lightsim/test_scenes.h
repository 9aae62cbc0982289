// The shared scaffolding of the light simulator's tests (CPU and GPU): small in-memory scenes
// (procedural volumes built with the voxelize library, uniform media), helpers that read the bake
// back (a voxel's value, planar flux through a layer of voxels), and the one GL context the GPU
// tests share.
//
// Header-only on purpose: lightsim/CMakeLists.txt globs every lightsim/*.cpp that is not a test
// into eikonal_lightsim, which does not link eikonal_voxelize; only the test binary does. Tests
// include this file and link both.
#pragma once

#include <algorithm>
#include <array>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "core/volume.h"
#include "gl/context.h"
#include "gl/shader_library.h"
#include "gl/volume_textures.h"
#include "lightsim/analysis_pass.h"
#include "lightsim/atlas.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/grid_uniforms.h"
#include "lightsim/live_count.h"
#include "lightsim/patch_textures.h"
#include "lightsim/step_targets.h"
#include "lightsim/step_uniforms.h"
#include "lightsim/update_pass.h"
#include "lightsim/wavefront.h"
#include "voxelize/grid_builder.h"
#include "voxelize/pipeline.h"
#include "voxelize/procedural.h"

namespace eik::test_scenes {

// Sets EIKONAL_THREADS for the lifetime of the object and restores it afterwards.
class ScopedThreads {
 public:
  explicit ScopedThreads(int n) {
    if (const char* old = std::getenv("EIKONAL_THREADS")) old_ = old;
    ::setenv("EIKONAL_THREADS", std::to_string(n).c_str(), 1);
  }
  ~ScopedThreads() {
    if (old_) ::setenv("EIKONAL_THREADS", old_->c_str(), 1);
    else ::unsetenv("EIKONAL_THREADS");
  }

 private:
  std::optional<std::string> old_;
};


// One headless context for the whole test program (OSMesa, or EGL when EIKONAL_GL says so), made
// current. It is never destroyed: GL objects of any test may outlive their test.
inline gl::GlContext& glContext() {
  static gl::GlContext* ctx = [] {
    gl::ContextOptions options;
    options.backend = gl::glBackendFromEnvironment(gl::GlBackend::Auto);
    return new gl::GlContext(options);
  }();
  ctx->makeCurrent();
  return *ctx;
}

// How much further the GPU path's float arithmetic may stray from the CPU twin than on llvmpipe: a
// factor on the patch-for-patch bounds, which were measured on llvmpipe. A software rasterizer
// rounds every float operation as IEEE single precision does; a hardware GLSL compiler may fuse
// a·b + c into one FMA and use the approximate division (2.5 ULP), inversesqrt (2 ULP) and
// exp2/log2 ((3 + 2·|x|) ULP) that GLSL allows (the figures of GLSL 4.60 §4.7.1; 3.30 leaves
// precision open), and a value that passes through a grazing refraction or a nearly folded patch
// magnifies the difference. Measured on an NVIDIA H200 (driver 580.159, EGL): up to 9.3× the
// llvmpipe bounds (UpdatePassTest's |Δw| 9.3e-4 against 1e-4), hence 30 with a margin of 3.
inline double gpuArithmeticSlack() { return gl::isSoftwareRenderer(glContext().info()) ? 1.0 : 30.0; }

// The pre-smoothing every scene here assumes unless it says otherwise (docs/physics.md: tests state the
// σ they assume): the voxelizer's default, 0.75 voxel.
constexpr double kSmoothSigmaVoxels = 0.75;

// Voxelises a procedural spec ("procedural:sphere,r=0.5,ior=1.5") like `voxelize` does: on the
// explicit `bounds` when given (h = longest extent / res), otherwise on the shape's bounds with
// `pad_voxels` of air and `res` voxels across the longest axis of the shape.
inline Volume proceduralVolume(const std::string& spec_text, int res, std::optional<Bounds> bounds = std::nullopt,
                               double smooth_sigma_voxels = kSmoothSigmaVoxels, double pad_voxels = kDefaultPadVoxels) {
  const ProceduralSpec spec = parseProceduralSpec(spec_text);
  const GridSpec grid = makeGrid(proceduralBounds(spec), res, pad_voxels, bounds);
  PipelineOptions options;
  options.interfaces = InterfaceMode::Smooth;
  options.smooth_sigma_voxels = smooth_sigma_voxels;
  return buildVolume(voxelizeProcedural(spec, grid), grid, options);
}

// The same with sharp interfaces (voxelize --interfaces sharp): per-material signed distances, n
// unblended and unsmoothed (core/interfaces.h).
// Several specs make several objects, composited as voxelize does (the innermost wins).
inline Volume sharpVolume(const std::vector<std::string>& spec_texts, int res,
                          std::optional<Bounds> bounds = std::nullopt, double pad_voxels = kDefaultPadVoxels) {
  std::vector<ProceduralSpec> specs;
  Bounds all;
  for (const std::string& text : spec_texts) {
    specs.push_back(parseProceduralSpec(text));
    all.extend(proceduralBounds(specs.back()));
  }
  const GridSpec grid = makeGrid(all, res, pad_voxels, bounds);
  ProceduralOptions procedural;
  procedural.distance_band = interfaceBand(grid);
  std::vector<Region> regions;
  for (const ProceduralSpec& spec : specs)
    for (Region& r : voxelizeProcedural(spec, grid, procedural)) regions.push_back(std::move(r));
  PipelineOptions options;
  options.interfaces = InterfaceMode::Sharp;
  return buildVolume(regions, grid, options);
}
inline Volume sharpVolume(const std::string& spec_text, int res, std::optional<Bounds> bounds = std::nullopt,
                          double pad_voxels = kDefaultPadVoxels) {
  return sharpVolume(std::vector<std::string>{spec_text}, res, bounds, pad_voxels);
}

// The box [−a, a]³.
inline Bounds cube(double half) {
  Bounds b;
  b.min = glm::dvec3(-half);
  b.max = glm::dvec3(half);
  return b;
}

// A floor y = height facing up, as a receiver of half extent `half_extent` (its map).
inline ReceiverSpec floorAt(double height, double half_extent) {
  ReceiverSpec floor;
  floor.point = {0.0, height, 0.0};
  floor.half_extent = half_extent;
  return floor;
}

inline Bounds box(const glm::dvec3& lo, const glm::dvec3& hi) {
  Bounds b;
  b.min = lo;
  b.max = hi;
  return b;
}

// A homogeneous volume: n everywhere, ∇n = 0, σa everywhere (no sigma_a field when zero).
inline Volume uniformVolume(const GridSpec& grid, double n, const glm::dvec3& sigma_a = glm::dvec3(0.0)) {
  Volume v;
  v.grid = grid;
  Field& ior = v.addField("ior", 1);
  std::fill(ior.data.begin(), ior.data.end(), static_cast<float>(n));
  v.addField("ior_grad", 3);
  if (sigma_a != glm::dvec3(0.0)) {
    Field& sa = v.addField("sigma_a", 3);
    for (std::size_t i = 0; i < grid.count(); ++i)
      for (int c = 0; c < 3; ++c) sa.voxel(i)[c] = static_cast<float>(sigma_a[c]);
  }
  return v;
}

// A grid of `dims` voxels of edge h over origin + [0, dims]·h.
inline GridSpec boxGrid(glm::ivec3 dims, double h, const glm::dvec3& origin = glm::dvec3(0.0)) {
  GridSpec g;
  g.dims = dims;
  g.bounds_min = origin;
  g.bounds_max = origin + glm::dvec3(dims) * h;
  return g;
}

inline GridSpec cubicGrid(int res, double half) {
  GridSpec g;
  g.dims = glm::ivec3(res);
  g.bounds_min = glm::dvec3(-half);
  g.bounds_max = glm::dvec3(half);
  return g;
}

// A graded index n = n0 + g·x on `grid` (∇n = (g, 0, 0) exactly), filling its box.
inline Volume linearIorVolume(const GridSpec& grid, double n0, double g) {
  Volume v;
  v.grid = grid;
  Field& ior = v.addField("ior", 1);
  Field& grad = v.addField("ior_grad", 3);
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const std::size_t index = grid.index(i, j, k);
        ior.data[index] = static_cast<float>(n0 + g * grid.center(i, j, k).x);
        grad.voxel(index)[0] = static_cast<float>(g);
      }
  return v;
}

// ---------------------------------------------------------------------------------------------
// The scenes of the tests.

// A glass sphere of radius r and index n centred at the origin in the box `bounds`.
inline Volume glassSphere(int res, const Bounds& bounds, double r = 0.5, double n = 1.5) {
  return proceduralVolume("procedural:sphere,r=" + std::to_string(r) + ",ior=" + std::to_string(n), res, bounds);
}

// A Luneburg lens of radius r (n = sqrt(2 − (ρ/r)²)) in the box `bounds`.
inline Volume luneburgLens(int res, const Bounds& bounds, double r = 0.5) {
  return proceduralVolume("procedural:luneburg,r=" + std::to_string(r), res, bounds);
}

// A horizontal slab (procedural box, y from y0 to y0 + thickness) wider than the grid in x and z,
// so that it fills the grid's whole cross-section: index n and absorption σa (per world unit).
inline Volume slab(int res, const Bounds& bounds, double y0, double thickness, double n, const glm::dvec3& sigma_a) {
  const glm::dvec3 e = bounds.extent();
  const std::string size = std::to_string(4.0 * e.x) + ":" + std::to_string(thickness) + ":" + std::to_string(4.0 * e.z);
  const glm::dvec3 c(bounds.center().x, y0 + 0.5 * thickness, bounds.center().z);
  const std::string spec = "procedural:box,size=" + size + ",center=" + std::to_string(c.x) + ":" + std::to_string(c.y) +
                           ":" + std::to_string(c.z) + ",ior=" + std::to_string(n) + ",sigma_a=" +
                           std::to_string(sigma_a.x) + ":" + std::to_string(sigma_a.y) + ":" + std::to_string(sigma_a.z);
  return proceduralVolume(spec, res, bounds);
}

// A sphere of index n = 1 (no refraction) and absorption σa: a pure occluder for shadow tests.
inline Volume absorbingSphere(int res, const Bounds& bounds, double r, double sigma_a) {
  const std::string s = std::to_string(sigma_a);
  return proceduralVolume("procedural:sphere,r=" + std::to_string(r) + ",ior=1,sigma_a=" + s + ":" + s + ":" + s, res, bounds);
}

// ---------------------------------------------------------------------------------------------
// The GPU tests' scene, and a patch list in mid-flight through it.

// The small glass-sphere scene of the GPU comparisons: n = 1.5, r = 0.5 on `res` voxels (+3 of
// air), σ = 0.75 voxel pre-smoothing (the voxelizer's default); `extra` is appended to the spec
// (",sigma_a=0.5:1:2").
inline Volume gpuGlassSphere(int res = 32, const std::string& extra = "") {
  return proceduralVolume("procedural:sphere,r=0.5,ior=1.5" + extra, res);
}

// The first release's deposits at patch midpoints (DepositKernel::Point), which the GPU path
// still makes (make_simulator.h gpuPathLacks) and the tests written for them assume.
inline SimulationOptions pointDepositOptions() {
  SimulationOptions o;
  o.deposit_kernel = DepositKernel::Point;
  return o;
}

// Fewer splits than the default (max_depth 4), so each GPU bake takes seconds on llvmpipe; point
// deposits, as the GPU path.
inline SimulationOptions gpuTestOptions() {
  SimulationOptions o = pointDepositOptions();
  o.max_depth = 4;
  return o;
}

// One step of the CPU twin on a list (stepPatch, then compaction and expansion by prefix sum).
// `splits` counts the splits by their number of children (index 2: 1×2, index 4: 2×2).
inline std::vector<Patch> cpuStep(const std::vector<Patch>& patches, const StepContext& ctx,
                           std::array<int, 5>* splits = nullptr) {
  std::vector<Patch> next;
  for (Patch p : patches) {
    const PatchStepResult r = stepPatch(p, ctx);
    if (r.fate == PatchFate::Keep) next.push_back(p);
    if (r.fate == PatchFate::Split) {
      if (splits) ++(*splits)[static_cast<std::size_t>(r.split.count())];
      std::array<Patch, 4> children;
      const int count = splitPatch(p, *ctx.sampler, r.split, children);
      next.insert(next.end(), children.begin(), children.begin() + count);
    }
  }
  return next;
}

// A list taken mid-flight: 45 steps of the CPU twin into the absorbing glass sphere (24 voxels,
// σa = 0.5, 1, 2), lit along (0.3, −1, 0.2), with gpuTestOptions() and `rule` — patches in the
// boundary layer, inside the glass, splitting. The patches are rounded to float (packPatch), so
// that a GPU pass and the twin start from the same numbers. Not copyable: ctx points into it.
struct MidFlightList {
  Volume volume;
  VolumeSampler sampler;
  SimulationOptions options;
  double fluxRef = 0.0;
  StepContext ctx;
  std::vector<Patch> patches;

  explicit MidFlightList(SplitRule rule = SplitRule::Axis)
      : volume(gpuGlassSphere(24, ",sigma_a=0.5:1:2")), sampler(volume), options(gpuTestOptions()) {
    options.split_rule = rule;
    LightSpec light;
    light.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
    patches = initialPatches(light, volume.grid, sampler, options, &fluxRef);
    ctx = makeStepContext(sampler, options, fluxRef);
    for (int i = 0; i < 45; ++i) patches = cpuStep(patches, ctx);
    // Round to float first, so both sides start from the same numbers.
    for (Patch& p : patches) p = unpackPatch(packPatch(p));
  }
  MidFlightList(const MidFlightList&) = delete;
  MidFlightList& operator=(const MidFlightList&) = delete;
};

// The GPU passes of one step on a MidFlightList's patches, set up as GpuSimulator does it (but in
// world coordinates): the volume uploaded, the run's uniforms, the list uploaded into `a` (of a
// side that holds `capacity` patches, and at least the list), `b` and the step targets, and its
// count into a LiveCount. update() and analyse() run those passes in the simulator's order (a → b,
// then b with a as the list before), drawn over `slots` (the count, unless a test sets more: the
// bound of GpuSimulatorOptions::CountReadback::Overlap).
struct GpuStep {
  gl::GlContext& gl = glContext();  // first: everything below needs it current
  gl::ShaderLibrary library;
  gl::VolumeTextures textures;
  std::string defines;
  AtlasLayout atlas;
  gpu::GridUniforms grid;
  gpu::StepUniforms step;
  std::size_t count;
  std::size_t slots;
  PatchTextures a, b;
  gpu::StepTargets targets;
  gpu::LiveCount live;

  explicit GpuStep(const MidFlightList& list, std::size_t capacity = 0)
      : textures(list.volume),
        defines(textures.layout().glslDefines()),
        atlas(AtlasLayout::plan(list.volume.grid.dims, gl.info().maxTextureSize)),
        grid(gpu::GridUniforms::from(list.volume.grid)),
        step(gpu::StepUniforms::from(list.volume.grid, list.options, list.fluxRef)),
        count(list.patches.size()),
        slots(count),
        a(patchSideFor(std::max(count, capacity))),
        b(a.side()),
        targets(a.side(), library) {
    std::vector<PatchTexels> packed;
    for (const Patch& p : list.patches) packed.push_back(packPatch(p));
    a.upload(packed);
    live.set(count);
  }

  void update(Integrator integrator) {
    gpu::UpdatePass(library, integrator, defines).run(a, b, live, slots, textures, grid, step);
  }
  void analyse(DepositMode mode) {
    gpu::AnalysisPass(library, mode, atlas, defines).run(b, a, live, slots, targets, textures, grid, step);
  }
};

// ---------------------------------------------------------------------------------------------
// Reading a bake.

// The RGB value of voxel `i` (flat index) of a 3-component field.
inline glm::dvec3 voxelValue(const Field& f, std::size_t i) {
  return {f.data[i * 3], f.data[i * 3 + 1], f.data[i * 3 + 2]};
}

inline glm::dvec3 voxelValue(const Field& f, const GridSpec& g, int i, int j, int k) {
  const float* p = f.voxel(g.index(i, j, k));
  return glm::dvec3(p[0], p[1], p[2]);
}

// Flux (per channel, W) crossing the y-layers [j0, j1) downwards (towards −y), averaged over the
// layers: Σ E·(light_dir·(−ŷ))·h_x·h_z·h_y / (thickness). In accumulate mode a patch of flux Φ that
// crosses a layer of thickness Δy at angle θ deposits Φ·(Δy/cos θ)/V in it, so
// Σ_layer E·cos θ·V/Δy = Φ (ALGORITHM.md step 4). Where patches of different directions share a
// voxel, light_dir is their mean and the cosine is that of the mean: exact only for parallel light.
inline glm::dvec3 downwardFlux(const Field& irradiance, const Field& light_dir, const GridSpec& g, int j0, int j1) {
  const glm::dvec3 h = g.voxelSize();
  glm::dvec3 sum(0.0);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = j0; j < j1; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::dvec3 e = voxelValue(irradiance, g, i, j, k);
        const double cos_down = -voxelValue(light_dir, g, i, j, k).y;
        sum += e * cos_down;
      }
  return sum * (h.x * h.z) / static_cast<double>(j1 - j0);
}

// Net flux (per channel, W) leaving the grid through its six faces, each measured like
// downwardFlux over the `layers` voxel layers next to the face, along the face's outward normal.
inline glm::dvec3 outwardFlux(const Field& irradiance, const Field& light_dir, const GridSpec& g, int layers = 2) {
  const glm::dvec3 h = g.voxelSize();
  glm::dvec3 total(0.0);
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? -1.0 : 1.0;
      glm::dvec3 sum(0.0);
      for (int l = 0; l < layers; ++l) {
        const int i = side == 0 ? l : g.dims[axis] - 1 - l;
        for (int u = 0; u < g.dims[a1]; ++u)
          for (int v = 0; v < g.dims[a2]; ++v) {
            glm::ivec3 c;
            c[axis] = i;
            c[a1] = u;
            c[a2] = v;
            const glm::dvec3 e = voxelValue(irradiance, g, c.x, c.y, c.z);
            sum += e * (sign * voxelValue(light_dir, g, c.x, c.y, c.z)[axis]);
          }
      }
      total += sum * (h[a1] * h[a2]) / static_cast<double>(layers);
    }
  }
  return total;
}

}  // namespace eik::test_scenes
