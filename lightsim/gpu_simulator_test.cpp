// Tests of the GPU light simulator (gpu_simulator.h, atlas.h, patch_textures.h) on OSMesa/llvmpipe:
// the flat-3D atlas mapping, the patch list layout, deposits of hand-made patches, the GPU bake
// against the CPU twin (cpu_simulator.h) on small scenes, the energy ledger, and the errors.
// Timings are printed (GpuBench), never asserted (DESIGN §6).
#include "lightsim/gpu_simulator.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "gl/context.h"
#include "lightsim/atlas.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/histo_pyramid.h"
#include "lightsim/patch_textures.h"
#include "lightsim/wavefront.h"
#include "voxelize/grid_builder.h"
#include "voxelize/pipeline.h"
#include "voxelize/procedural.h"

namespace eik {
namespace {

// One headless context for the whole test program (OSMesa, or EGL when EIKONAL_GL says so).
gl::GlContext& context() {
  static gl::GlContext* ctx = [] {
    gl::ContextOptions options;
    options.backend = gl::glBackendFromEnvironment(gl::GlBackend::Auto);
    return new gl::GlContext(options);
  }();
  ctx->makeCurrent();
  return *ctx;
}

// A procedural shape on a cubic grid of `res` voxels along its longest axis plus `pad` voxels.
Volume proceduralVolume(const std::string& spec, int res, double pad = 3.0) {
  const ProceduralSpec parsed = parseProceduralSpec(spec);
  const GridSpec grid = makeGrid(proceduralBounds(parsed), res, pad);
  return buildVolume(voxelizeProcedural(parsed, grid), grid);
}

// A uniform medium (n, σa) on a grid of `dims` voxels over origin + [0, dims]·h.
Volume uniformVolume(glm::ivec3 dims, double h, double n, glm::dvec3 sigma = glm::dvec3(0.0),
                     glm::dvec3 origin = glm::dvec3(0.0)) {
  Volume v;
  v.grid.dims = dims;
  v.grid.bounds_min = origin;
  v.grid.bounds_max = origin + glm::dvec3(dims) * h;
  v.addField("ior", 1).data.assign(v.grid.count(), static_cast<float>(n));
  v.addField("ior_grad", 3);
  if (sigma != glm::dvec3(0.0)) {
    Field& s = v.addField("sigma_a", 3);
    for (std::size_t i = 0; i < v.grid.count(); ++i) {
      for (int c = 0; c < 3; ++c) s.data[i * 3 + static_cast<std::size_t>(c)] = static_cast<float>(sigma[c]);
    }
  }
  return v;
}

double relativeL2(const std::vector<float>& a, const std::vector<float>& b) {
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    num += (static_cast<double>(a[i]) - b[i]) * (static_cast<double>(a[i]) - b[i]);
    den += static_cast<double>(b[i]) * b[i];
  }
  return den > 0.0 ? std::sqrt(num / den) : std::sqrt(num);
}

double relDiff(double a, double b, double scale) { return std::fabs(a - b) / scale; }

// ---------------------------------------------------------------------------------------------
// Layouts (no GL needed).

TEST(AtlasLayoutTest, RoundTripForNonSquareTilings) {
  for (glm::ivec3 dims : {glm::ivec3(5, 3, 7), glm::ivec3(4, 9, 2), glm::ivec3(16, 16, 16), glm::ivec3(3, 2, 1),
                          glm::ivec3(7, 1, 13), glm::ivec3(1, 1, 1), glm::ivec3(33, 20, 48)}) {
    const AtlasLayout layout = AtlasLayout::plan(dims, 16384);
    SCOPED_TRACE(testing::Message() << dims.x << "x" << dims.y << "x" << dims.z << " → tiles " << layout.tiles.x
                                    << "x" << layout.tiles.y);
    EXPECT_GE(layout.tiles.x * layout.tiles.y, dims.z);
    EXPECT_LT((layout.tiles.y - 1) * layout.tiles.x, dims.z);  // no empty row
    EXPECT_EQ(layout.size, layout.tiles * glm::ivec2(dims.x, dims.y));
    std::set<std::pair<int, int>> seen;
    for (int k = 0; k < dims.z; ++k) {
      for (int j = 0; j < dims.y; ++j) {
        for (int i = 0; i < dims.x; ++i) {
          const glm::ivec2 t = layout.texel({i, j, k});
          ASSERT_GE(t.x, 0);
          ASSERT_GE(t.y, 0);
          ASSERT_LT(t.x, layout.size.x);
          ASSERT_LT(t.y, layout.size.y);
          ASSERT_EQ(layout.voxel(t), glm::ivec3(i, j, k));
          ASSERT_TRUE(seen.insert({t.x, t.y}).second) << "two voxels on one texel";
        }
      }
    }
    // Texels of the unused tiles map to no voxel.
    int unused = 0;
    for (int y = 0; y < layout.size.y; ++y) {
      for (int x = 0; x < layout.size.x; ++x) unused += layout.voxel({x, y}).x < 0 ? 1 : 0;
    }
    EXPECT_EQ(static_cast<std::size_t>(unused) + seen.size(), layout.texelCount());
  }
  // A tiling that is not the square-ish one because of the limit: 8 slices of 10x4 within 40 texels.
  const AtlasLayout narrow = AtlasLayout::plan({10, 4, 8}, 40);
  EXPECT_LE(narrow.size.x, 40);
  EXPECT_LE(narrow.size.y, 40);
  EXPECT_EQ(narrow.voxel(narrow.texel({9, 3, 7})), glm::ivec3(9, 3, 7));
}

TEST(AtlasLayoutTest, TooLargeIsAnInputError) {
  try {
    AtlasLayout::plan({4096, 4096, 4096}, 16384, "big.vol.json", "llvmpipe");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("big.vol.json"), std::string::npos) << what;
    EXPECT_NE(what.find("volume too large for the GPU"), std::string::npos) << what;
    EXPECT_NE(what.find("4096x4096x4096"), std::string::npos) << what;
    EXPECT_NE(what.find("GL_MAX_TEXTURE_SIZE (16384)"), std::string::npos) << what;
  }
}

TEST(PatchListLayoutTest, MortonOrderMatchesThePyramid) {
  for (std::uint32_t k = 0; k < 70000; k += 7) {
    const glm::ivec2 t = mortonTexel(k);
    ASSERT_EQ(mortonIndex(t), k);
    ASSERT_EQ(t, hpSlotTexel(k));
  }
  for (std::size_t n : {0u, 1u, 2u, 3u, 4u, 5u, 8u, 9u, 16u, 17u, 1000u, 4096u, 4097u}) {
    const glm::ivec2 box = mortonBox(n);
    EXPECT_EQ(box, hpLiveBox(n)) << n;
    for (std::uint32_t k = 0; k < n; ++k) {
      const glm::ivec2 t = mortonTexel(k);
      ASSERT_TRUE(t.x < box.x && t.y < box.y) << n << " " << k;
    }
    if (n > 0) {
      EXPECT_LE(static_cast<std::size_t>(box.x) * static_cast<std::size_t>(box.y), 4 * std::max<std::size_t>(n, 2));
    }
  }
  EXPECT_EQ(patchSideFor(0), 1);
  EXPECT_EQ(patchSideFor(17), 8);
  EXPECT_EQ(patchSideFor(64), 8);
  EXPECT_EQ(patchSideFor(65, 4), 16);
}

// ---------------------------------------------------------------------------------------------
// Deposits of hand-made patches.

// A square patch of edge `edge` centred at `centre`, facing +z (corners counter-clockwise seen
// from −z), in a medium of index n.
Patch squarePatch(glm::dvec3 centre, double edge, glm::dvec3 flux, double n = 1.0) {
  Patch p;
  const double a = 0.5 * edge;
  p.x = {centre + glm::dvec3(-a, -a, 0), centre + glm::dvec3(a, -a, 0), centre + glm::dvec3(a, a, 0),
         centre + glm::dvec3(-a, a, 0)};
  for (auto& w : p.w) w = glm::dvec3(0, 0, n);
  p.flux = flux;
  p.area0 = edge * edge;
  return p;
}

struct DepositFixture {
  gl::GlContext& gl = context();  // first: everything below needs it current
  Volume volume;
  gl::ShaderLibrary library;
  gl::VolumeTextures textures;
  AtlasLayout layout;
  GridUniforms grid;

  explicit DepositFixture(glm::ivec3 dims, double h = 0.1)
      : volume(uniformVolume(dims, h, 1.25)), textures(volume),
        layout(AtlasLayout::plan(dims, gl.info().maxTextureSize)), grid(GridUniforms::from(volume.grid)) {}

  // The analysis pass (which computes each patch's deposit) and the deposit pass on `patches` as
  // the updated list, with the same list as the one before the update (so m_old = m).
  void deposit(const std::vector<Patch>& patches, DepositMode mode, float dt, Field& irradiance, Field& dir) {
    std::vector<PatchTexels> packed;
    for (const Patch& p : patches) packed.push_back(packPatch(p));
    const int side = patchSideFor(packed.size(), 2);
    PatchTextures list(side);
    list.upload(packed);
    gpu::StepTargets targets(side, library);
    gpu::StepUniforms step;
    step.dt = dt;
    step.splitLength = 1.0f;
    step.maxDepth = 8.0f;
    gpu::AnalysisPass(library, mode, layout, textures.layout().glslDefines())
        .run(list, list, packed.size(), targets, textures, grid, step);
    AtlasTargets atlas(layout, mode);
    DepositPass(library, layout, mode).run(targets.depositA, targets.depositB, packed.size(), atlas, 1e-3f);
    atlas.toFields(irradiance, dir);
  }
  std::size_t index(glm::ivec3 v) const { return volume.grid.index(v.x, v.y, v.z); }
  glm::dvec3 centre(glm::ivec3 v) const { return volume.grid.center(v.x, v.y, v.z); }
};

glm::dvec3 at(const Field& f, std::size_t i) { return {f.data[i * 3], f.data[i * 3 + 1], f.data[i * 3 + 2]}; }

TEST(DepositTest, AccumulateLandsInTheRightVoxels) {
  DepositFixture fx({5, 3, 7});  // 7 slices of 5x3: a 3x3 tiling with two empty tiles
  const double n = 1.25, dt = 0.05, V = 0.001;
  const glm::ivec3 a(1, 2, 0), b(4, 0, 6), c(2, 1, 3);
  std::vector<Patch> patches = {
      squarePatch(fx.centre(a), 0.02, {1, 2, 3}, n),
      squarePatch(fx.centre(b) + glm::dvec3(0.03, -0.02, 0.04), 0.02, {0.5, 0.5, 0.5}, n),
      squarePatch(fx.centre(c), 0.02, {2, 0, 1}, n),
      squarePatch(fx.centre(c) + glm::dvec3(0.01, 0.01, -0.01), 0.02, {1, 1, 1}, n),  // same voxel as the last
      squarePatch(glm::dvec3(-0.05, 0.1, 0.1), 0.02, {9, 9, 9}, n),                   // outside: no deposit
  };
  patches[2].w = {glm::dvec3(n, 0, 0), glm::dvec3(n, 0, 0), glm::dvec3(n, 0, 0), glm::dvec3(n, 0, 0)};  // along +x
  Field e, d;
  fx.deposit(patches, DepositMode::Accumulate, static_cast<float>(dt), e, d);
  const double ds = dt / n;  // Δs_m = Δt / n(m)
  auto expectNear = [](glm::dvec3 got, glm::dvec3 want, const char* what) {
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], want[i], 1e-4 * (1.0 + std::fabs(want[i]))) << what << " [" << i << "]";
  };
  expectNear(at(e, fx.index(a)), glm::dvec3(1, 2, 3) * ds / V, "irradiance a");
  expectNear(at(d, fx.index(a)), glm::dvec3(0, 0, 1), "dir a");
  expectNear(at(e, fx.index(b)), glm::dvec3(0.5) * ds / V, "irradiance b");
  expectNear(at(e, fx.index(c)), glm::dvec3(3, 1, 2) * ds / V, "irradiance c (two patches)");
  // Direction sum lum(Φ)·Δs·d: (1·(1,0,0) + 1·(0,0,1)) normalised.
  expectNear(at(d, fx.index(c)), glm::normalize(glm::dvec3(1, 0, 1)), "dir c");
  // Nothing else anywhere.
  double rest = 0.0;
  for (std::size_t i = 0; i < fx.volume.grid.count(); ++i) {
    if (i == fx.index(a) || i == fx.index(b) || i == fx.index(c)) continue;
    rest += glm::length(at(e, i)) + glm::length(at(d, i));
  }
  EXPECT_EQ(rest, 0.0);
}

TEST(DepositTest, MaxKeepsTheStrongestPatch) {
  DepositFixture fx({4, 6, 3});
  const glm::ivec3 v(2, 3, 1);
  // E = Φ/A: 1/0.0004 = 2500 for the first, (2,2,2)/0.0009 ≈ 2222 for the second, 6/0.0001 for the
  // third (green only) — the strongest by lum(E) = (r+g+b)/3.
  std::vector<Patch> patches = {
      squarePatch(fx.centre(v), 0.02, {1, 1, 1}),
      squarePatch(fx.centre(v) + glm::dvec3(0.01, 0, 0), 0.03, {2, 2, 2}),
      squarePatch(fx.centre(v) + glm::dvec3(0, 0.01, 0.01), 0.01, {0, 6, 0}),
      squarePatch(fx.centre({0, 0, 0}), 0.02, {0, 0, 0}),  // E = 0 still records its direction
  };
  patches[2].w = {glm::dvec3(0, 1, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 1, 0)};
  Field e, d;
  fx.deposit(patches, DepositMode::Max, 0.05f, e, d);
  const glm::dvec3 got = at(e, fx.index(v));
  EXPECT_NEAR(got.x, 0.0, 1e-3);
  EXPECT_NEAR(got.y, 6.0 / 0.0001, 1.0);
  EXPECT_NEAR(got.z, 0.0, 1e-3);
  EXPECT_NEAR(at(d, fx.index(v)).y, 1.0, 1e-6);
  EXPECT_EQ(at(e, fx.index({0, 0, 0})), glm::dvec3(0.0));
  EXPECT_NEAR(at(d, fx.index({0, 0, 0})).z, 1.0, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// GPU against the CPU twin.

struct Comparison {
  BakeResult gpu, cpu;
  GpuRunInfo info;
};

double seconds(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void printPhases(const char* what, const SimulationStats& s) {
  std::printf("%s phases:", what);
  for (const auto& [name, t] : s.phase_seconds) std::printf(" %s %.3f", name.c_str(), t);
  std::printf("\n");
}

Comparison compare(const Volume& volume, const LightSpec& light, const SimulationOptions& options,
                   GpuSimulatorOptions gpuOptions = {}) {
  context();
  gpuOptions.timing = GpuSimulatorOptions::Timing::Queries;  // exercised here; Auto turns them off on llvmpipe
  Comparison c;
  auto t = std::chrono::steady_clock::now();
  GpuSimulator gpu(volume, gpuOptions);
  c.gpu = gpu.run(light, options);
  c.info = gpu.lastRunInfo();
  const double tg = seconds(t);
  t = std::chrono::steady_clock::now();
  CpuSimulator cpu(volume);
  c.cpu = cpu.run(light, options);
  std::printf("times: gpu %.2f s, cpu %.2f s\n", tg, seconds(t));
  printPhases("gpu", c.gpu.stats);
  return c;
}

void printStats(const char* what, const SimulationStats& s) {
  std::printf("%s: steps %d patches %llu peak %llu total %llu splits %llu kills exited %llu flux %llu folded %llu "
              "depth %llu\n  in %.6f out %.6f abs %.6f refl %.6f killed %.6f unfinished %.6f\n",
              what, s.steps, (unsigned long long)s.initial_patches, (unsigned long long)s.peak_patches,
              (unsigned long long)s.total_patches, (unsigned long long)s.splits, (unsigned long long)s.kills.exited,
              (unsigned long long)s.kills.flux, (unsigned long long)s.kills.folded, (unsigned long long)s.kills.depth,
              s.flux_in.x, s.flux_out.x, s.flux_absorbed.x, s.flux_reflected.x, s.flux_killed.x, s.flux_unfinished.x);
}

// Relative L2 of light_dir over the voxels whose irradiance is at least 1 % of the largest.
double lightDirDifference(const BakeResult& gpu, const BakeResult& cpu) {
  double emax = 0.0;
  for (float v : cpu.irradiance.data) emax = std::max(emax, static_cast<double>(v));
  std::vector<float> a, b;
  const std::size_t voxels = cpu.irradiance.data.size() / 3;
  for (std::size_t i = 0; i < voxels; ++i) {
    if (luminance(at(cpu.irradiance, i)) < 0.01 * emax) continue;
    for (int c = 0; c < 3; ++c) {
      a.push_back(gpu.light_dir.data[i * 3 + static_cast<std::size_t>(c)]);
      b.push_back(cpu.light_dir.data[i * 3 + static_cast<std::size_t>(c)]);
    }
  }
  return relativeL2(a, b);
}

// The ledger terms agree within `tolerance` of the flux in, and each closes.
void expectLedgersAgree(const SimulationStats& gpu, const SimulationStats& cpu, double tolerance) {
  const double in = luminance(cpu.flux_in);
  ASSERT_GT(in, 0.0);
  EXPECT_LE(relDiff(luminance(gpu.flux_in), in, in), 1e-6);
  EXPECT_LE(relDiff(luminance(gpu.flux_out), luminance(cpu.flux_out), in), tolerance);
  EXPECT_LE(relDiff(luminance(gpu.flux_absorbed), luminance(cpu.flux_absorbed), in), tolerance);
  EXPECT_LE(relDiff(luminance(gpu.flux_reflected), luminance(cpu.flux_reflected), in), tolerance);
  EXPECT_LE(relDiff(luminance(gpu.flux_killed), luminance(cpu.flux_killed), in), tolerance);
  EXPECT_LE(relDiff(luminance(gpu.flux_unfinished), luminance(cpu.flux_unfinished), in), tolerance);
  for (const SimulationStats* s : {&gpu, &cpu}) {
    const glm::dvec3 sum = s->flux_out + s->flux_absorbed + s->flux_reflected + s->flux_killed + s->flux_unfinished;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], s->flux_in[c], 1e-5 * s->flux_in[c]) << s->backend << " channel " << c;
  }
  EXPECT_EQ(gpu.initial_patches, cpu.initial_patches);
  // Patch counts, and the step at which the last patch leaves, follow split and kill decisions
  // taken in float on one side and double on the other: they agree closely, not exactly.
  EXPECT_LE(std::abs(gpu.steps - cpu.steps), std::max(2, cpu.steps / 50));
  EXPECT_LE(relDiff(static_cast<double>(gpu.total_patches), static_cast<double>(cpu.total_patches),
                    static_cast<double>(cpu.total_patches)), 0.01);
  EXPECT_LE(relDiff(static_cast<double>(gpu.splits), static_cast<double>(cpu.splits),
                    static_cast<double>(std::max<std::uint64_t>(cpu.splits, 1))), 0.01);
}

// The small glass-sphere scene of the comparisons: n = 1.5, r = 0.5 on 32 voxels (+3 of air),
// σ = 0.75 voxel pre-smoothing (the voxelizer's default); fewer splits than the default so each
// bake takes seconds on llvmpipe.
Volume glassSphere(int res = 32, const std::string& extra = "") {
  return proceduralVolume("procedural:sphere,r=0.5,ior=1.5" + extra, res);
}

SimulationOptions testOptions() {
  SimulationOptions o;
  o.max_depth = 4;
  return o;
}

// The GPU bake against the CPU twin's: relative L2 of the irradiance and of light_dir under 1 %.
void expectBakesAgree(const Comparison& c) {
  printStats("gpu", c.gpu.stats);
  printStats("cpu", c.cpu.stats);
  const double e = relativeL2(c.gpu.irradiance.data, c.cpu.irradiance.data);
  const double d = lightDirDifference(c.gpu, c.cpu);
  std::printf("relative L2: irradiance %.2e, light_dir %.2e\n", e, d);
  EXPECT_LT(e, 0.01);
  EXPECT_LT(d, 0.01);
}

TEST(GpuSimulatorTest, GlassSphereDirectionalMatchesCpu) {
  const Volume volume = glassSphere();
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  const Comparison c = compare(volume, light, testOptions());
  expectBakesAgree(c);
  expectLedgersAgree(c.gpu.stats, c.cpu.stats, 1e-3);
}

TEST(GpuSimulatorTest, AbsorbingSphereUnderAPointLightMatchesCpu) {
  // Coloured absorption (σa per channel) and a spherical wavefront (cube-map initialisation), with
  // the shader's own trilinear sampling (GpuSimulatorOptions::exact_sampling).
  const Volume volume = glassSphere(32, ",sigma_a=0.5:1:2");
  LightSpec light;
  light.type = LightSpec::Type::Point;
  light.position = glm::dvec3(0.2, 1.4, -0.3);
  light.power = glm::dvec3(1.0, 0.8, 0.6);
  GpuSimulatorOptions exact;
  exact.exact_sampling = true;
  const Comparison c = compare(volume, light, testOptions(), exact);
  expectBakesAgree(c);
  EXPECT_GT(luminance(c.gpu.stats.flux_absorbed), 0.01 * luminance(c.gpu.stats.flux_in));
  expectLedgersAgree(c.gpu.stats, c.cpu.stats, 1e-3);
}

// Voxels (with lum(irradiance) ≥ `floor`) whose GPU irradiance differs from the CPU's by more than
// `tolerance` relative.
int voxelsOff(const BakeResult& gpu, const BakeResult& cpu, double tolerance, double floor, int* considered) {
  int off = 0, n = 0;
  for (std::size_t i = 0; i < cpu.irradiance.data.size() / 3; ++i) {
    const glm::dvec3 c = at(cpu.irradiance, i), g = at(gpu.irradiance, i);
    if (std::max(luminance(c), luminance(g)) < floor) continue;
    ++n;
    off += glm::length(g - c) > tolerance * glm::length(c) ? 1 : 0;
  }
  *considered = n;
  return off;
}

TEST(GpuSimulatorTest, MaxModeAndRk4MatchCpu) {
  // The thesis' deposit (strongest patch per voxel, folded patches killed) with RK4 steps. A max
  // deposit is E = Φ/A of one patch: next to a fold A → 0, and float (GPU) and double (CPU)
  // corners give areas that differ by any factor there (measured: 8 of 27 000 voxels off by more
  // than 1 %, one of them by 45 %), so this compares voxel by voxel instead of by L2.
  const Volume volume = glassSphere(24);
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(-0.2, -1.0, 0.1));
  SimulationOptions options = testOptions();
  options.deposit = DepositMode::Max;
  options.integrator = Integrator::RK4;
  const Comparison c = compare(volume, light, options);
  printStats("gpu", c.gpu.stats);
  printStats("cpu", c.cpu.stats);
  int considered = 0;
  const int off = voxelsOff(c.gpu, c.cpu, 0.01, 0.1 /* a tenth of E_L */, &considered);
  const double d = lightDirDifference(c.gpu, c.cpu);
  std::printf("max mode: %d of %d lit voxels off by > 1 %%; light_dir relative L2 %.2e\n", off, considered, d);
  EXPECT_LE(off, considered / 200);  // ≤ 0.5 %
  EXPECT_GT(considered, 1000);
  EXPECT_LT(d, 0.01);
  expectLedgersAgree(c.gpu.stats, c.cpu.stats, 1e-3);
  EXPECT_NEAR(static_cast<double>(c.gpu.stats.kills.folded), static_cast<double>(c.cpu.stats.kills.folded),
              0.01 * static_cast<double>(c.cpu.stats.kills.folded));
}

// One step of the CPU twin on a list (stepPatch, then compaction and expansion by prefix sum).
// `splits` counts the splits by their number of children (index 2: 1×2, index 4: 2×2).
std::vector<Patch> cpuStep(const std::vector<Patch>& patches, const StepContext& ctx,
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

void expectOneStepMatchesTheCpuTwin(SplitRule rule) {
  // A list taken mid-flight (patches in the boundary layer, inside the glass, splitting), one step
  // through the passes (update, analysis, pyramid, compaction), against the CPU twin's step: same
  // patches in the same order (the pyramid's Morton order is the prefix sum's index order), to
  // float rounding.
  gl::GlContext& gl = context();
  const Volume volume = glassSphere(24, ",sigma_a=0.5:1:2");
  VolumeSampler sampler(volume);
  SimulationOptions options = testOptions();
  options.split_rule = rule;
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  double fluxRef = 0.0;
  std::vector<Patch> patches = initialPatches(light, volume.grid, sampler, options, &fluxRef);
  const StepContext ctx{&sampler, &options, timeStep(volume.grid, options), fluxRef, volume.grid.voxelVolume()};
  for (int i = 0; i < 45; ++i) patches = cpuStep(patches, ctx);
  // Round to float first, so both sides start from the same numbers.
  for (Patch& p : patches) p = unpackPatch(packPatch(p));
  std::array<int, 5> splits{};
  const std::vector<Patch> want = cpuStep(patches, ctx, &splits);

  gl::ShaderLibrary library;
  gl::VolumeTextures textures(volume);
  const std::string defines = textures.layout().glslDefines();
  const AtlasLayout atlas = AtlasLayout::plan(volume.grid.dims, gl.info().maxTextureSize);
  const GridUniforms grid = GridUniforms::from(volume.grid);
  gpu::StepUniforms step;
  step.dt = static_cast<float>(ctx.dt);
  step.boundaryOn = static_cast<float>(options.boundary_on);
  step.boundaryOff = static_cast<float>(options.boundary_off);
  step.fluxKill = static_cast<float>(options.flux_threshold * fluxRef);
  step.splitLength = static_cast<float>(splitThreshold(volume.grid, options));
  step.maxDepth = static_cast<float>(options.max_depth);
  step.axisSplit = options.split_rule == SplitRule::Axis;
  step.killAtMaxDepth = options.at_max_depth == DepthLimit::Kill;
  const int side = patchSideFor(std::max(patches.size(), want.size()));
  PatchTextures a(side), b(side);
  std::vector<PatchTexels> packed;
  for (const Patch& p : patches) packed.push_back(packPatch(p));
  a.upload(packed);
  gpu::StepTargets targets(side, library);
  gpu::UpdatePass(library, options.integrator, defines).run(a, b, patches.size(), textures, grid, step);
  gpu::AnalysisPass(library, options.deposit, atlas, defines).run(b, a, patches.size(), targets, textures, grid, step);
  targets.pyramid.build(patches.size());
  const std::uint64_t total = targets.pyramid.readTotal();
  ASSERT_EQ(total, want.size());
  gpu::CompactPass(library, targets.pyramid.defines(), defines).run(b, targets, a, want.size(), textures, grid);
  const std::vector<PatchTexels> got = a.download(want.size());

  int inLayer = 0;
  double worstX = 0.0, worstW = 0.0, worstFlux = 0.0;
  for (std::size_t k = 0; k < want.size(); ++k) {
    const Patch g = unpackPatch(got[k]);
    const Patch& c = want[k];
    for (int i = 0; i < 4; ++i) {
      worstX = std::max(worstX, glm::length(g.x[i] - c.x[i]) / voxelEdge(volume.grid));
      worstW = std::max(worstW, glm::length(g.w[i] - c.w[i]));
    }
    worstFlux = std::max(worstFlux, glm::length(g.flux - c.flux) / glm::length(c.flux));
    ASSERT_EQ(g.depth, c.depth) << k;
    EXPECT_NEAR(g.n_in, c.n_in, 1e-4) << k;
    EXPECT_NEAR(g.area0, c.area0, 1e-5 * c.area0 + 1e-12) << k;
    inLayer += c.n_in != 0.0 ? 1 : 0;
  }
  std::printf("%zu → %zu patches, %d 1×2 and %d 2×2 splits, %d in a boundary layer; worst |Δx| %.2e voxel, "
              "|Δw| %.2e, flux %.2e relative\n", patches.size(), want.size(), splits[2], splits[4], inLayer, worstX,
              worstW, worstFlux);
  EXPECT_GT(inLayer, 0);
  // Axis: 1×2 splits (and 2×2 ones where both edges grew); Quad: 2×2 splits only.
  EXPECT_GT(splits[rule == SplitRule::Axis ? 2 : 4], 0);
  if (rule == SplitRule::Quad) {
    EXPECT_EQ(splits[2], 0);
  }
  EXPECT_LT(worstX, 1e-4);
  EXPECT_LT(worstW, 1e-4);
  EXPECT_LT(worstFlux, 1e-4);
}

TEST(GpuSimulatorTest, OneStepOfThePassesMatchesTheCpuTwinPatchForPatch) {
  expectOneStepMatchesTheCpuTwin(SplitRule::Axis);
}

TEST(GpuSimulatorTest, OneStepWithTheThesisQuadSplitMatchesTheCpuTwin) {
  expectOneStepMatchesTheCpuTwin(SplitRule::Quad);
}

class AbsorbingSlab : public testing::TestWithParam<glm::dvec3> {};

TEST_P(AbsorbingSlab, FollowsBeerLambert) {
  // A uniform absorbing medium (n = 1, σa = 2, 1, 0.5 per unit, 0.2 × 0.2 × 1) lit along +z. The
  // wavefront starts ½h before the box; step i moves the midpoints to z_i = −½h + i·Δt after
  // absorbing exp(−σa·Δt) at the old midpoint (clamp-to-edge sampling gives the box's σa there
  // too), and deposits Φ_i·Δt/V into the voxel of z_i. With Δt = h/3 no z_i falls on a voxel face,
  // so voxel layer k gets exactly three deposits: E_k = E_L·⅓·Σ exp(−σa·(z_i + ½h)), Beer–Lambert
  // sampled at the three z_i in the layer.
  context();
  const glm::dvec3 sigma(2.0, 1.0, 0.5);
  const double h = 0.025, EL = 2.0;
  // GetParam(): where the volume sits. The GPU works in grid-local coordinates, so a volume far from
  // the world origin loses nothing to float positions.
  const Volume volume = uniformVolume({8, 8, 40}, h, 1.0, sigma, GetParam());
  GpuSimulator gpu(volume);
  LightSpec light;
  light.direction = glm::dvec3(0, 0, 1);
  light.power = glm::dvec3(EL);
  SimulationOptions options;
  options.step_voxels = 1.0 / 3.0;
  const BakeResult r = gpu.run(light, options);
  const GridSpec& g = volume.grid;
  const double dt = h / 3.0;
  double worst = 0.0;
  ASSERT_EQ(r.stats.initial_patches, 64u);
  for (int k = 0; k < g.dims.z; ++k) {
    glm::dvec3 want(0.0);
    for (int i = 1; i < 200; ++i) {
      const double z = -0.5 * h + i * dt;
      if (static_cast<int>(std::floor(z / h)) == k) want += EL * glm::exp(-sigma * (z + 0.5 * h)) * (dt / h);
    }
    for (int x : {0, 3, 7}) {
      const glm::dvec3 e = at(r.irradiance, g.index(x, 5, k));
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(e[c] / want[c] - 1.0));
      EXPECT_NEAR(at(r.light_dir, g.index(x, 5, k)).z, 1.0, 1e-6);
    }
  }
  std::printf("worst relative deviation from Beer-Lambert: %.2e\n", worst);
  EXPECT_LT(worst, 1e-4);
  // The ledger closes, and the slab absorbs 1 − exp(−σa·s) of the flux, s the path from the start
  // plane to the first midpoint outside the box (where the patches are retired as exited).
  const SimulationStats& s = r.stats;
  const glm::dvec3 sum = s.flux_out + s.flux_absorbed + s.flux_reflected + s.flux_killed + s.flux_unfinished;
  const int exitStep = static_cast<int>(std::floor((1.0 + 0.5 * h) / dt)) + 1;  // first z_i > 1
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(sum[c], s.flux_in[c], 1e-5 * s.flux_in[c]);
    EXPECT_NEAR(s.flux_absorbed[c] / s.flux_in[c], 1.0 - std::exp(-sigma[c] * exitStep * dt), 1e-5) << c;
  }
  EXPECT_EQ(s.kills.exited, s.initial_patches);
  EXPECT_EQ(s.flux_reflected, glm::dvec3(0.0));
}

INSTANTIATE_TEST_SUITE_P(GpuSimulatorTest, AbsorbingSlab,
                         testing::Values(glm::dvec3(0.0), glm::dvec3(1000.0, -2000.0, 500.0)));

TEST(GpuSimulatorTest, RepeatedRunsAreIdentical) {
  context();
  const Volume volume = glassSphere(16);
  GpuSimulatorOptions o;
  o.timing = GpuSimulatorOptions::Timing::Finish;
  GpuSimulator gpu(volume, o);
  LightSpec light;
  const BakeResult a = gpu.run(light, testOptions());
  const BakeResult b = gpu.run(light, testOptions());
  for (const char* phase : {"update", "analysis", "deposit", "ledger", "pyramid", "compact", "total"}) {
    EXPECT_GT(a.stats.phase_seconds.count(phase), 0u) << phase;
  }
  EXPECT_EQ(a.irradiance.data, b.irradiance.data);
  EXPECT_EQ(a.light_dir.data, b.light_dir.data);
  EXPECT_EQ(a.stats.total_patches, b.stats.total_patches);
}

TEST(GpuSimulatorTest, PatchListOverflowIsARuntimeError) {
  context();
  const Volume volume = glassSphere(32);
  GpuSimulatorOptions o;
  o.max_patch_side = 64;  // 4096 patches: the initial 2102 fit, the splits behind the sphere do not
  GpuSimulator gpu(volume, o);
  try {
    gpu.run(LightSpec{}, testOptions());
    FAIL() << "no error";
  } catch (const RuntimeError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("patch list limit of 64x64"), std::string::npos) << what;
  }
}

TEST(GpuSimulatorTest, VolumeTooLargeForTheGpuIsAnInputError) {
  context();
  const Volume volume = uniformVolume({40, 40, 40}, 0.1, 1.0);
  GpuSimulatorOptions o;
  o.source = "big.vol.json";
  o.budget_bytes = 2u << 20;  // the fields (1 MiB) fit, fields + atlas + lists do not
  try {
    GpuSimulator gpu(volume, o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("big.vol.json"), std::string::npos) << what;
    EXPECT_NE(what.find("volume too large for the GPU"), std::string::npos) << what;
    EXPECT_NE(what.find("40x40x40"), std::string::npos) << what;
  }
}

TEST(GpuSimulatorTest, MissingFieldIsAnInputError) {
  context();
  Volume volume = uniformVolume({4, 4, 4}, 0.1, 1.0);
  volume.fields.erase("ior_grad");
  EXPECT_THROW(GpuSimulator{volume}, InputError);
}

TEST(GpuSimulatorTest, LightThatMissesTheVolumeGivesAnEmptyBake) {
  context();
  // A point light so far away that the volume falls between the centre rays of its finest cube
  // map (2048² cells a face): no initial patch.
  const Volume volume = uniformVolume({6, 6, 6}, 1e-4, 1.5);
  GpuSimulator gpu(volume);
  LightSpec light;
  light.type = LightSpec::Type::Point;
  light.position = glm::dvec3(100.0, 37.0, -55.0);
  const BakeResult r = gpu.run(light, SimulationOptions{});
  EXPECT_EQ(r.stats.initial_patches, 0u);
  EXPECT_EQ(r.stats.steps, 0);
  EXPECT_EQ(r.irradiance.data, std::vector<float>(volume.grid.count() * 3, 0.0f));
  EXPECT_EQ(r.light_dir.data, std::vector<float>(volume.grid.count() * 3, 0.0f));
  // And a light with no power: patches, but nothing deposited and nothing broken.
  const BakeResult dark = gpu.run(LightSpec{.power = glm::dvec3(0.0)}, SimulationOptions{});
  EXPECT_GT(dark.stats.initial_patches, 0u);
  EXPECT_EQ(dark.irradiance.data, std::vector<float>(volume.grid.count() * 3, 0.0f));
}

// Measurements for the report (not assertions): run with --gtest_also_run_disabled_tests
// --gtest_filter='*GpuBench*'. BENCH_RES (default 64) sets the sphere's resolution, BENCH_CPU=1
// also times the CPU twin, BENCH_TIMINGS=1 repeats the bake with every phase-timing mode.
TEST(GpuBench, DISABLED_GlassSphere) {
  const int res = std::getenv("BENCH_RES") ? std::atoi(std::getenv("BENCH_RES")) : 64;
  const Volume volume = proceduralVolume("procedural:sphere,r=0.5,ior=1.5", res);
  context();
  std::printf("renderer: %s\ngrid %dx%dx%d\n", context().summary().c_str(), volume.grid.dims.x, volume.grid.dims.y,
              volume.grid.dims.z);
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  std::vector<GpuSimulatorOptions::Timing> timings = {GpuSimulatorOptions::Timing::Auto};
  if (std::getenv("BENCH_TIMINGS")) {
    timings = {GpuSimulatorOptions::Timing::Off, GpuSimulatorOptions::Timing::Queries,
               GpuSimulatorOptions::Timing::Finish};
  }
  for (auto timing : timings) {
    GpuSimulatorOptions o;
    o.timing = timing;
    GpuSimulator gpu(volume, o);
    const BakeResult r = gpu.run(light, SimulationOptions{});
    const GpuRunInfo& info = gpu.lastRunInfo();
    const SimulationStats& s = r.stats;
    std::printf("timing %d: wall %.2f s, %d steps, %llu patch-steps (%.2f M/s), peak %llu patches (list side %d), "
                "textures %.1f MiB (volume %.1f, atlas %.1f %dx%d, lists+pyramid %.1f)\n",
                static_cast<int>(timing), info.wall_seconds, s.steps, (unsigned long long)s.total_patches,
                static_cast<double>(s.total_patches) / info.wall_seconds * 1e-6, (unsigned long long)s.peak_patches,
                info.peak_patch_side, info.texture_bytes_peak / 1048576.0, info.volume_bytes / 1048576.0,
                info.atlas_bytes / 1048576.0, info.atlas_size.x, info.atlas_size.y, info.patch_bytes_peak / 1048576.0);
    printPhases("  ", s);
  }
  if (std::getenv("BENCH_CPU")) {
    auto t = std::chrono::steady_clock::now();
    CpuSimulator cpu(volume);
    const BakeResult r = cpu.run(light, SimulationOptions{});
    std::printf("cpu twin: %.2f s, %llu patch-steps\n", seconds(t), (unsigned long long)r.stats.total_patches);
  }
}

}  // namespace
}  // namespace eik
