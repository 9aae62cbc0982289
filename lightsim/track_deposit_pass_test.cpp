// Tests of the track-length deposit pass (track_deposit_pass.h, ALGORITHM.md step 4 "Track
// deposits") on OSMesa/llvmpipe, against a CPU reference written here with forEachTrackWeight and
// trackLattice (track_deposit.h) exactly as applyTrackDeposits (cpu_simulator.cpp) uses them:
// hand-made patch-steps voxel by voxel, a random set in relative L2, flux conservation, and the
// no-deposit flag. The atlas targets are read raw (irradiance and the unnormalised direction sums).
#include "lightsim/track_deposit_pass.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "gl/context.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "lightsim/atlas.h"
#include "lightsim/grid_uniforms.h"
#include "lightsim/morton.h"
#include "lightsim/patch_textures.h"
#include "lightsim/test_scenes.h"
#include "lightsim/track_deposit.h"
#include "lightsim/wavefront.h"

namespace eik {
namespace {

using Corners = std::array<glm::dvec3, 4>;

// One patch-step as the pass sees it: corners before and after (grid frame), the flux along the
// step and the flag (< 0: nothing; ≥ 0: deposit; ≥ 1: clip at the receiver).
struct PatchStep {
  Corners before{};
  Corners after{};
  glm::dvec3 flux{1.0};
  float flag = 0.0f;
};

struct Receiver {
  bool enabled = false;
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0, 1.0, 0.0};
};

// The sums of the two atlas targets per voxel (x fastest), in double.
struct Deposits {
  std::vector<glm::dvec3> irradiance;
  std::vector<glm::dvec3> direction;
};

// Corners as the GPU gets them (float), so that the reference starts from the same numbers.
Corners asFloat(const Corners& c) {
  Corners r;
  for (std::size_t i = 0; i < 4; ++i) r[i] = glm::dvec3(glm::vec3(c[i]));
  return r;
}

// Patch::area of a corner quadrilateral: ½ |(x₂ − x₀) × (x₃ − x₁)|.
double quadArea(const Corners& x) { return 0.5 * glm::length(glm::cross(x[2] - x[0], x[3] - x[1])); }

// The irradiance of a patch-step as trackSpacing sees it: flux (max channel) over the smaller area.
double stepIrradiance(const PatchStep& s) {
  return std::max({s.flux.x, s.flux.y, s.flux.z}) / std::min(quadArea(s.before), quadArea(s.after));
}

// cpu_simulator.cpp subPathLattice: the longer u edge (x₀x₁, x₃x₂) and v edge (x₁x₂, x₀x₃), before
// or after, over h, at the spacing of track_deposit.h trackSpacing.
glm::ivec2 referenceLattice(const Corners& before, const Corners& after, double h, double spacing) {
  auto longest = [](const Corners& p, int a, int b, int c, int d) {
    return std::max(glm::length(p[static_cast<std::size_t>(b)] - p[static_cast<std::size_t>(a)]),
                    glm::length(p[static_cast<std::size_t>(c)] - p[static_cast<std::size_t>(d)]));
  };
  const double u = std::max(longest(before, 0, 1, 2, 3), longest(after, 0, 1, 2, 3));
  const double v = std::max(longest(before, 1, 2, 3, 0), longest(after, 1, 2, 3, 0));
  return {trackLattice(u / h, spacing), trackLattice(v / h, spacing)};
}

// The CPU reference: applyTrackDeposits' loop (one thread, no slabs), in double, on the corners
// as the GPU gets them (float); patch-steps under `dim_irradiance` take the dim light's lattice.
Deposits referenceDeposits(const GridSpec& grid, const std::vector<PatchStep>& steps, const Receiver& receiver,
                           double dim_irradiance = 0.0) {
  Deposits out;
  out.irradiance.assign(grid.count(), glm::dvec3(0.0));
  out.direction.assign(grid.count(), glm::dvec3(0.0));
  const glm::dvec3 hv = grid.voxelSize();
  const double h = std::min({hv.x, hv.y, hv.z});  // VolumeSampler::h, the smallest voxel edge
  const double inv_volume = 1.0 / grid.voxelVolume();
  for (const PatchStep& s : steps) {
    if (s.flag < 0.0f) continue;
    const Corners from = asFloat(s.before), to = asFloat(s.after);
    const glm::dvec3 track_flux = glm::dvec3(glm::vec3(s.flux));
    // The lattice from the corners in double, as the CPU twin has them: an edge of exactly k/2
    // voxels gets k sub-paths there, and the pass's float allowance (track_deposit.vert) is there
    // to give the same from float corners, which carry such an edge as k/2·(1 ± 1e-7).
    const double spacing = trackSpacing(std::max({track_flux.x, track_flux.y, track_flux.z}),
                                        std::min(quadArea(s.before), quadArea(s.after)), dim_irradiance);
    const glm::ivec2 lattice = referenceLattice(s.before, s.after, h, spacing);
    const bool clip = s.flag >= 1.0f && receiver.enabled;
    const glm::dvec3 flux = track_flux / static_cast<double>(lattice.x * lattice.y);
    const double lum = (flux.x + flux.y + flux.z) / 3.0;
    for (int iv = 0; iv < lattice.y; ++iv)
      for (int iu = 0; iu < lattice.x; ++iu) {
        const double u = (iu + 0.5) / lattice.x, v = (iv + 0.5) / lattice.y;
        const glm::dvec3 a = bilinear(from, u, v);
        glm::dvec3 b = bilinear(to, u, v);
        if (clip) {
          const double ha = glm::dot(a - receiver.point, receiver.normal);
          const double hb = glm::dot(b - receiver.point, receiver.normal);
          if (ha <= 0.0) continue;
          if (hb < 0.0) b = a + (ha / (ha - hb)) * (b - a);
        }
        const double length = glm::length(b - a);
        if (!(length > 0.0)) continue;
        const glm::dvec3 dir = (b - a) / length;
        const glm::dvec3 e = flux * (length * inv_volume);
        const glm::dvec3 dsum = (lum * length) * dir;
        forEachTrackWeight(grid.toVoxel(a), grid.toVoxel(b), grid.dims, [&](long long at, double w) {
          out.irradiance[static_cast<std::size_t>(at)] += e * w;
          out.direction[static_cast<std::size_t>(at)] += dsum * w;
        });
      }
  }
  return out;
}

// Largest extent of a patch-step's 8 corners along any axis, in voxels of that axis.
double extentVoxels(const GridSpec& grid, const PatchStep& s) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (std::size_t c = 0; c < 4; ++c) {
    lo = glm::min(lo, glm::min(s.before[c], s.after[c]));
    hi = glm::max(hi, glm::max(s.before[c], s.after[c]));
  }
  const glm::dvec3 e = (hi - lo) / grid.voxelSize();
  return std::max({e.x, e.y, e.z});
}

struct TrackFixture {
  gl::GlContext& gl = test_scenes::glContext();  // first: everything below needs it current
  GridSpec grid;
  gl::ShaderLibrary library;
  AtlasLayout layout;
  gpu::TrackDepositPass pass;

  // A grid of `dims` voxels of `voxel` size centred on the origin (the simulator's local frame).
  TrackFixture(glm::ivec3 dims, glm::dvec3 voxel)
      : grid(makeGrid(dims, voxel)),
        layout(AtlasLayout::plan(dims, gl.info().maxTextureSize)),
        pass(library, layout) {}

  static GridSpec makeGrid(glm::ivec3 dims, glm::dvec3 voxel) {
    GridSpec g;
    g.dims = dims;
    g.bounds_min = -0.5 * glm::dvec3(dims) * voxel;
    g.bounds_max = 0.5 * glm::dvec3(dims) * voxel;
    return g;
  }
  // The world point at continuous voxel coordinates p.
  glm::dvec3 world(glm::dvec3 p) const { return grid.bounds_min + p * grid.voxelSize(); }
  Corners worldCorners(const Corners& voxels) const {
    Corners c;
    for (std::size_t i = 0; i < 4; ++i) c[i] = world(voxels[i]);
    return c;
  }

  Deposits gpuDeposits(const std::vector<PatchStep>& steps, const Receiver& receiver, int maxExtent,
                       double dimIrradiance = 0.0) {
    const int side = patchSideFor(steps.size(), 2);
    std::vector<PatchTexels> before, after;
    std::vector<float> info(static_cast<std::size_t>(side) * static_cast<std::size_t>(side) * 4, 0.0f);
    for (std::size_t k = 0; k < steps.size(); ++k) {
      Patch p;
      p.x = steps[k].before;
      before.push_back(packPatch(p));
      p.x = steps[k].after;
      after.push_back(packPatch(p));
      const glm::ivec2 t = mortonTexel(static_cast<std::uint32_t>(k));
      const std::size_t at = (static_cast<std::size_t>(t.y) * static_cast<std::size_t>(side) + static_cast<std::size_t>(t.x)) * 4;
      info[at + 0] = static_cast<float>(steps[k].flux.x);
      info[at + 1] = static_cast<float>(steps[k].flux.y);
      info[at + 2] = static_cast<float>(steps[k].flux.z);
      info[at + 3] = steps[k].flag;
    }
    PatchTextures beforeList(side), afterList(side);
    beforeList.upload(before);
    afterList.upload(after);
    const gl::Texture2D trackInfo({side, side}, gl::TextureFormat::RGBA32F, info, 4,
                                  gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge});
    gpu::TrackDepositUniforms uniforms;
    uniforms.grid = gpu::GridUniforms::from(grid);
    uniforms.receiverEnabled = receiver.enabled;
    uniforms.receiverPoint = glm::vec3(receiver.point);
    uniforms.receiverNormal = glm::vec3(receiver.normal);
    uniforms.maxExtentVoxels = maxExtent;
    uniforms.dimIrradiance = static_cast<float>(dimIrradiance);
    AtlasTargets atlas(layout, DepositMode::Accumulate);
    pass.run(beforeList, afterList, trackInfo, steps.size(), atlas, uniforms);
    return readAtlas(atlas);
  }

  // The raw sums of both targets, voxel by voxel (readRGBA: row 0 first, as the atlas texels).
  Deposits readAtlas(AtlasTargets& atlas) const {
    const std::vector<float> energy = atlas.framebuffer().readRGBA(0);
    const std::vector<float> direction = atlas.framebuffer().readRGBA(1);
    Deposits out;
    out.irradiance.resize(grid.count());
    out.direction.resize(grid.count());
    for (int k = 0; k < grid.dims.z; ++k)
      for (int j = 0; j < grid.dims.y; ++j)
        for (int i = 0; i < grid.dims.x; ++i) {
          const glm::ivec2 t = layout.texel({i, j, k});
          const std::size_t at =
              (static_cast<std::size_t>(t.y) * static_cast<std::size_t>(layout.size.x) + static_cast<std::size_t>(t.x)) * 4;
          const std::size_t v = grid.index(i, j, k);
          out.irradiance[v] = glm::dvec3(energy[at], energy[at + 1], energy[at + 2]);
          out.direction[v] = glm::dvec3(direction[at], direction[at + 1], direction[at + 2]);
        }
    // Texels of no voxel (the unused tiles of the last row) must stay empty.
    double stray = 0.0;
    for (int y = 0; y < layout.size.y; ++y)
      for (int x = 0; x < layout.size.x; ++x)
        if (layout.voxel({x, y}).x < 0) {
          const std::size_t at = (static_cast<std::size_t>(y) * static_cast<std::size_t>(layout.size.x) + static_cast<std::size_t>(x)) * 4;
          for (int c = 0; c < 4; ++c) stray += std::fabs(energy[at + static_cast<std::size_t>(c)]) + std::fabs(direction[at + static_cast<std::size_t>(c)]);
        }
    EXPECT_EQ(stray, 0.0) << "deposits in atlas texels of no voxel";
    return out;
  }
};

double maxNorm(const std::vector<glm::dvec3>& f) {
  double m = 0.0;
  for (const glm::dvec3& v : f) m = std::max({m, std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
  return m;
}

std::size_t nonZero(const std::vector<glm::dvec3>& f) {
  return static_cast<std::size_t>(std::count_if(f.begin(), f.end(), [](const glm::dvec3& v) { return v != glm::dvec3(0.0); }));
}

double relativeL2(const std::vector<glm::dvec3>& got, const std::vector<glm::dvec3>& want) {
  double diff = 0.0, norm = 0.0;
  for (std::size_t i = 0; i < want.size(); ++i) {
    const glm::dvec3 d = got[i] - want[i];
    diff += glm::dot(d, d);
    norm += glm::dot(want[i], want[i]);
  }
  return std::sqrt(diff / norm);
}

// Per voxel and component, |GPU − CPU| ≤ tolerance · max |CPU| of the field. The GPU works in float:
// corners within ~1e-7 relative of coordinates ≤ ~12 voxels from the grid's centre (~1e-6 voxel),
// which moves a hat weight (slope ≤ 1 per voxel) by ~1e-6 of a sub-path's share, and sums of at
// most a few hundred sub-paths in float (~1e-6 relative each); 1e-5 of the largest deposit leaves
// a margin of several times these, while a wrong voxel, weight, lattice or clip is off by a
// sizeable fraction of a sub-path's share (≥ 1e-3 of the largest deposit in these cases).
void expectSameDeposits(const Deposits& gpu, const Deposits& cpu, double tolerance, const GridSpec& grid) {
  const double maxE = maxNorm(cpu.irradiance), maxD = maxNorm(cpu.direction);
  ASSERT_GT(maxE, 0.0);
  ASSERT_GT(maxD, 0.0);
  int failures = 0;
  double worstE = 0.0, worstD = 0.0;
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const std::size_t v = grid.index(i, j, k);
        for (int c = 0; c < 3; ++c) {
          const double de = std::fabs(gpu.irradiance[v][c] - cpu.irradiance[v][c]) / maxE;
          const double dd = std::fabs(gpu.direction[v][c] - cpu.direction[v][c]) / maxD;
          worstE = std::max(worstE, de);
          worstD = std::max(worstD, dd);
          if ((de > tolerance || dd > tolerance) && ++failures <= 8) {
            ADD_FAILURE() << "voxel (" << i << ", " << j << ", " << k << ") [" << c << "]: irradiance GPU "
                          << gpu.irradiance[v][c] << " CPU " << cpu.irradiance[v][c] << ", direction GPU "
                          << gpu.direction[v][c] << " CPU " << cpu.direction[v][c];
          }
        }
      }
  EXPECT_EQ(failures, 0) << "worst irradiance difference " << worstE << ", direction " << worstD
                         << " (of the largest deposit)";
  EXPECT_LE(worstE, tolerance);
  EXPECT_LE(worstD, tolerance);
}

// A parallelogram patch in voxel coordinates: corner 0 at `origin`, u edge `eu`, v edge `ev`.
Corners quad(glm::dvec3 origin, glm::dvec3 eu, glm::dvec3 ev) {
  return {origin, origin + eu, origin + eu + ev, origin + ev};
}
Corners moved(const Corners& c, glm::dvec3 by) {
  return {c[0] + by, c[1] + by, c[2] + by, c[3] + by};
}

struct NamedCase {
  std::string name;
  std::vector<PatchStep> steps;
  Receiver receiver;
};

TEST(TrackDepositPass, MatchesTheCpuReferenceVoxelByVoxel) {
  TrackFixture fx({16, 16, 16}, glm::dvec3(0.1));
  const double pi = 3.14159265358979323846;
  std::vector<NamedCase> cases;
  auto add = [&](std::string name, Corners before, Corners after, glm::dvec3 flux, float flag = 0.0f,
                 Receiver receiver = {}) {
    cases.push_back({std::move(name), {{fx.worldCorners(before), fx.worldCorners(after), flux, flag}}, receiver});
  };
  // One voxel, axis-aligned, half a voxel along +z (the initial patches' step): a 2×2 lattice.
  {
    const Corners c = quad({5.3, 6.1, 4.2}, {1, 0, 0}, {0, 1, 0});
    add("axis-aligned", c, moved(c, {0, 0, 0.5}), {1.0, 2.0, 0.5});
  }
  // A 2-voxel square tilted and travelling at ~35° from z, 1.3 voxels a step (several planes).
  {
    const double t = 35.0 * pi / 180.0;
    const glm::dvec3 dir(std::sin(t) * std::cos(0.4), std::sin(t) * std::sin(0.4), std::cos(t));
    const glm::dvec3 eu = glm::normalize(glm::cross(dir, glm::dvec3(0, 1, 0))) * 2.0;
    const glm::dvec3 ev = glm::normalize(glm::cross(eu, dir)) * 2.0;
    const Corners c = quad(glm::dvec3(6.7, 7.2, 5.1) - 0.5 * (eu + ev), eu, ev);
    add("oblique 35°", c, moved(c, 1.3 * dir), {0.7, 0.7, 0.7});
  }
  // A stretched, sheared quad that also deforms in the step (lattice 16 × 3: the u edge ~9 voxels).
  {
    const Corners before = {glm::dvec3(2.2, 4.1, 6.0), glm::dvec3(10.9, 5.3, 6.6), glm::dvec3(11.6, 6.4, 7.1),
                            glm::dvec3(2.6, 5.2, 6.3)};
    const Corners after = {glm::dvec3(2.0, 4.3, 7.1), glm::dvec3(11.1, 5.0, 7.4), glm::dvec3(11.9, 6.6, 8.3),
                           glm::dvec3(2.5, 5.4, 7.0)};
    add("stretched and sheared", before, after, {3.0, 0.1, 1.0});
  }
  // Across the grid's −x face and +z face: the hats of voxels outside get nothing.
  {
    const Corners c = quad({-1.4, 3.3, 14.6}, {2.1, 0.3, 0}, {0.2, 1.7, 0.4});
    add("across the boundary", c, moved(c, {0.6, 0.2, 1.1}), {1.0, 1.0, 1.0});
  }
  // Slivers at the +x and +y faces (the atlas is 4 × 4 tiles): their points (side ~9) are wider
  // than their boxes and reach past the tile, into the next one or past the atlas's right or top
  // edge, all of which must be discarded; and a point whose centre were outside the atlas would be
  // dropped whole (GL clips points by their centre), which the vertex shader must avoid.
  {
    const Corners c = quad({15.6, 2.2, 11.3}, {0.3, 0, 0}, {0.1, 6.5, 0.2});
    add("sliver at the +x face", c, moved(c, {0.2, 0.3, 0.5}), {0.2, 0.4, 0.6});
    const Corners d = quad({3.1, 15.7, 14.2}, {6.4, 0.1, 0.2}, {0.1, 0.2, 0});
    add("sliver at the +y face", d, moved(d, {0.3, 0.2, 0.5}), {0.6, 0.4, 0.2});
  }
  // Clipped at a tilted receiver plane: the patch moves down across it; some of its sub-paths start
  // on the far side (skipped), others are cut where they cross.
  {
    Receiver r;
    r.enabled = true;
    r.normal = glm::normalize(glm::dvec3(0.25, 1.0, -0.15));
    r.point = fx.world({8.0, 7.0, 8.0});
    const Corners c = quad({5.2, 6.9, 6.3}, {3.1, 0.2, 0}, {0.1, 0.3, 2.6});
    add("clipped at the receiver", c, moved(c, {0.3, -1.4, 0.2}), {1.0, 0.5, 0.25}, 1.0f, r);
    // The same with flag 0 (no clip) for comparison: must differ.
    add("not clipped (flag 0)", c, moved(c, {0.3, -1.4, 0.2}), {1.0, 0.5, 0.25}, 0.0f, r);
    // Flag 1 but no receiver (its plane still in the uniforms): not clipped either.
    Receiver off = r;
    off.enabled = false;
    add("not clipped (no receiver)", c, moved(c, {0.3, -1.4, 0.2}), {1.0, 0.5, 0.25}, 1.0f, off);
  }
  Deposits clipped, unclipped;
  for (const NamedCase& nc : cases) {
    SCOPED_TRACE(nc.name);
    const int extent = static_cast<int>(std::ceil(extentVoxels(fx.grid, nc.steps[0])));
    const Deposits cpu = referenceDeposits(fx.grid, nc.steps, nc.receiver);
    const Deposits gpu = fx.gpuDeposits(nc.steps, nc.receiver, extent);
    EXPECT_GE(nonZero(cpu.irradiance), 8u);
    EXPECT_EQ(nonZero(gpu.irradiance), nonZero(cpu.irradiance));
    expectSameDeposits(gpu, cpu, 1e-5, fx.grid);
    if (nc.name == "clipped at the receiver") clipped = cpu;
    if (nc.name == "not clipped (flag 0)") unclipped = cpu;
  }
  // The clip case did clip something.
  ASSERT_FALSE(clipped.irradiance.empty());
  EXPECT_GT(relativeL2(clipped.irradiance, unclipped.irradiance), 0.05);
}

// splitmix64: a fixed, portable random sequence.
struct Random {
  std::uint64_t state;
  double next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * (1.0 / 9007199254740992.0);
  }
  double in(double lo, double hi) { return lo + (hi - lo) * next(); }
  glm::dvec3 in(glm::dvec3 lo, glm::dvec3 hi) { return {in(lo.x, hi.x), in(lo.y, hi.y), in(lo.z, hi.z)}; }
};

TEST(TrackDepositPass, RandomPatchStepsMatchTheCpuReference) {
  // Anisotropic voxels, so that h (the lattice) and the voxel coordinates differ by axis.
  TrackFixture fx({20, 16, 12}, glm::dvec3(0.1, 0.12, 0.09));
  Random rng{20240611};
  Receiver receiver;
  receiver.enabled = true;
  receiver.normal = glm::normalize(glm::dvec3(-0.1, 1.0, 0.2));
  receiver.point = fx.world({10.0, 5.0, 6.0});
  std::vector<PatchStep> steps;
  double extent = 0.0;
  for (int n = 0; n < 500; ++n) {
    PatchStep s;
    // In the box grown by a voxel (propagationBox), any orientation, edges ¼–3 voxels, sheared,
    // a step of ⅕–2 voxels in any direction, and a deformation of up to ¼ voxel per corner.
    const glm::dvec3 origin = rng.in(glm::dvec3(-1.0), glm::dvec3(fx.grid.dims) + 1.0);
    const glm::dvec3 eu = rng.in(glm::dvec3(-1.0), glm::dvec3(1.0)) * rng.in(0.25, 3.0);
    const glm::dvec3 ev = rng.in(glm::dvec3(-1.0), glm::dvec3(1.0)) * rng.in(0.25, 3.0);
    const glm::dvec3 step = glm::normalize(rng.in(glm::dvec3(-1.0), glm::dvec3(1.0))) * rng.in(0.2, 2.0);
    Corners before = quad(origin, eu, ev), after = moved(before, step);
    for (auto& c : after) c += rng.in(glm::dvec3(-0.25), glm::dvec3(0.25));
    s.before = fx.worldCorners(before);
    s.after = fx.worldCorners(after);
    s.flux = rng.in(glm::dvec3(0.1), glm::dvec3(2.0));
    const double kind = rng.next();
    s.flag = kind < 0.1 ? -1.0f : kind < 0.3 ? 1.0f : 0.0f;  // 10 % none, 20 % clipped
    extent = std::max(extent, extentVoxels(fx.grid, s));
    steps.push_back(s);
  }
  const int maxExtent = static_cast<int>(std::ceil(extent));
  ASSERT_LE(maxExtent, fx.pass.maxExtentVoxels());
  // Without the dim light's lattice, and with it for the dimmer half of the patch-steps (the
  // median irradiance as the bound), which changes the lattice of most of those.
  std::vector<double> irradiance;
  for (const PatchStep& s : steps) irradiance.push_back(stepIrradiance(s));
  std::nth_element(irradiance.begin(), irradiance.begin() + irradiance.size() / 2, irradiance.end());
  std::ostringstream text;
  for (const double dim : {0.0, irradiance[irradiance.size() / 2]}) {
    const Deposits cpu = referenceDeposits(fx.grid, steps, receiver, dim);
    const Deposits gpu = fx.gpuDeposits(steps, receiver, maxExtent, dim);
    EXPECT_GT(nonZero(cpu.irradiance), fx.grid.count() / 2);
    const double errE = relativeL2(gpu.irradiance, cpu.irradiance);
    const double errD = relativeL2(gpu.direction, cpu.direction);
    EXPECT_LE(errE, 1e-4) << "irradiance, dim bound " << dim;
    EXPECT_LE(errD, 1e-4) << "direction sum, dim bound " << dim;
    text << std::scientific << std::setprecision(2) << errE << " " << errD << " ";
    if (dim > 0.0) {
      // The two lattices give different sums (so the comparison above sees the GPU's choice).
      EXPECT_GT(relativeL2(cpu.irradiance, referenceDeposits(fx.grid, steps, receiver).irradiance), 1e-3);
    }
  }
  RecordProperty("relative_l2_irradiance_direction", text.str());
}

TEST(TrackDepositPass, ConservesTheFluxOfAPatchInsideTheGrid) {
  // A translated patch (every sub-path as long as the step) well inside the grid, where the hats
  // sum to 1: Σ_v irradiance·V = Φ·L and Σ_v direction = lum(Φ)·(b − a), to float rounding.
  TrackFixture fx({12, 12, 12}, glm::dvec3(0.05));
  const glm::dvec3 eu(1.7, 0.4, -0.3), ev(-0.2, 1.3, 0.6), step(0.8, -0.5, 1.1);
  PatchStep s;
  s.before = fx.worldCorners(quad({4.1, 4.4, 3.6}, eu, ev));
  s.after = fx.worldCorners(moved(quad({4.1, 4.4, 3.6}, eu, ev), step));
  s.flux = {1.5, 0.75, 0.3};
  const Deposits gpu = fx.gpuDeposits({s}, {}, 4);
  glm::dvec3 energy(0.0), direction(0.0);
  for (std::size_t v = 0; v < fx.grid.count(); ++v) {
    energy += gpu.irradiance[v] * fx.grid.voxelVolume();
    direction += gpu.direction[v];
  }
  const glm::dvec3 travel = step * fx.grid.voxelSize();  // b − a of every sub-path (world)
  const glm::dvec3 wantEnergy = s.flux * glm::length(travel);
  const glm::dvec3 wantDirection = ((s.flux.x + s.flux.y + s.flux.z) / 3.0) * travel;
  EXPECT_GT(nonZero(gpu.irradiance), 27u);
  for (int c = 0; c < 3; ++c) {
    // Float: ~100 voxels summed by the test in double, each within ~1e-6 relative.
    EXPECT_NEAR(energy[c], wantEnergy[c], 1e-5 * wantEnergy[c]) << "channel " << c;
    EXPECT_NEAR(direction[c], wantDirection[c], 1e-5 * glm::length(wantDirection)) << "component " << c;
  }
}

TEST(TrackDepositPass, NegativeFlagDepositsNothing) {
  TrackFixture fx({8, 8, 8}, glm::dvec3(0.1));
  PatchStep s;
  const Corners c = quad({2.5, 3.2, 2.9}, {1.5, 0.2, 0}, {0.1, 1.2, 0.3});
  s.before = fx.worldCorners(c);
  s.after = fx.worldCorners(moved(c, {0.4, 0.3, 0.9}));
  s.flux = {1.0, 1.0, 1.0};
  // Deposits with a ≥ 0 ...
  const Deposits on = fx.gpuDeposits({s}, {}, 4);
  EXPECT_GT(nonZero(on.irradiance), 8u);
  // ... and nothing at all with a < 0, alone or next to a patch that deposits elsewhere.
  s.flag = -1.0f;
  const Deposits off = fx.gpuDeposits({s}, {}, 4);
  EXPECT_EQ(nonZero(off.irradiance), 0u);
  EXPECT_EQ(nonZero(off.direction), 0u);
  PatchStep other = s;
  other.flag = 0.0f;
  other.before = fx.worldCorners(moved(c, {0, 0, -2.5}));
  other.after = fx.worldCorners(moved(c, {0, 0, -2.0}));
  const Deposits mixed = fx.gpuDeposits({s, other}, {}, 4);
  const Deposits alone = fx.gpuDeposits({other}, {}, 4);
  EXPECT_GT(nonZero(alone.irradiance), 8u);
  for (std::size_t v = 0; v < fx.grid.count(); ++v) {
    EXPECT_EQ(mixed.irradiance[v], alone.irradiance[v]) << "voxel " << v;
    EXPECT_EQ(mixed.direction[v], alone.direction[v]) << "voxel " << v;
  }
}

TEST(TrackDepositPass, RefusesAnExtentBeyondThePointSizeRange) {
  TrackFixture fx({8, 8, 8}, glm::dvec3(0.1));
  // GL only promises points of 1 texel, but implementations draw far larger ones (llvmpipe: 255);
  // the simulator's patches need about 10.
  EXPECT_GE(fx.pass.maxExtentVoxels(), 8);
  RecordProperty("max_extent_voxels", fx.pass.maxExtentVoxels());
  PatchStep s;
  const Corners c = quad({2.5, 3.2, 2.9}, {1.0, 0, 0}, {0, 1.0, 0});
  s.before = fx.worldCorners(c);
  s.after = fx.worldCorners(moved(c, {0, 0, 0.5}));
  EXPECT_THROW(fx.gpuDeposits({s}, {}, fx.pass.maxExtentVoxels() + 1), RuntimeError);
  EXPECT_THROW(fx.gpuDeposits({s}, {}, -1), RuntimeError);
  EXPECT_NO_THROW(fx.gpuDeposits({s}, {}, fx.pass.maxExtentVoxels()));
}

}  // namespace
}  // namespace eik
