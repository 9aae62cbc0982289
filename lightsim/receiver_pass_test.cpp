// Tests of the receiver-map deposit pass (receiver_pass.h; ALGORITHM.md "Receivers") on
// OSMesa/llvmpipe, against the CPU's patchFootprint + depositFootprint (receiver.h) as the
// reference: hand-made footprints one by one (texel-aligned, oblique, concave, twisted, partly off
// the map, not received, degenerate, parallel to the plane), a thousand random patches, and a
// wavefront tiling the plane under an oblique light (uniform planar irradiance E·cos θ, flux kept).
//
// The reference runs on the patches as the GPU sees them (packed to float and back), so the two
// differ only by the float arithmetic of the shaders.
#include "lightsim/receiver_pass.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "gl/context.h"
#include "gl/shader_library.h"
#include "lightsim/patch_textures.h"
#include "lightsim/receiver.h"
#include "lightsim/test_scenes.h"
#include "lightsim/wavefront.h"

namespace eik {
namespace {

// A map on the plane through `point` with normal `normal` (axes from receiverAxes), its corner at
// (u, v) = corner, `texels` texels of edge `pitch`.
ReceiverMap makeMap(glm::dvec3 point, glm::dvec3 normal, glm::dvec2 corner, double pitch, glm::ivec2 texels) {
  ReceiverMap map;
  map.point = point;
  map.normal = glm::normalize(normal);
  receiverAxes(map.normal, map.u, map.v);
  map.origin = corner;
  map.pitch = pitch;
  map.texels = texels;
  return map;
}

// The world point of the plane at texel coordinates t (texel (i, j) covers [i, i+1] × [j, j+1]).
glm::dvec3 onPlane(const ReceiverMap& map, glm::dvec2 t) {
  return map.point + (map.origin.x + t.x * map.pitch) * map.u + (map.origin.y + t.y * map.pitch) * map.v;
}

// A patch whose corner c travels along dirs[c] (towards the plane, index n) from `height`
// (+ c·0.1·pitch, so the patch is not flat) above the plane and meets it at texel coordinates t[c].
Patch patchOnto(const ReceiverMap& map, const std::array<glm::dvec2, 4>& t, const std::array<glm::dvec3, 4>& dirs,
                double height, double n = 1.0) {
  Patch p;
  for (std::size_t c = 0; c < 4; ++c) {
    const glm::dvec3 d = glm::normalize(dirs[c]);
    const double h = height + 0.1 * static_cast<double>(c) * map.pitch;
    p.x[c] = onPlane(map, t[c]) - (h / glm::dot(-d, map.normal)) * d;
    p.w[c] = n * d;
  }
  // The pass reads the flux from the receive info, never the patch's own FLUX.
  p.flux = glm::dvec3(100.0);
  p.area0 = 1.0;
  return p;
}
Patch patchOnto(const ReceiverMap& map, const std::array<glm::dvec2, 4>& t, glm::dvec3 dir, double height) {
  return patchOnto(map, t, {dir, dir, dir, dir}, height);
}

// A patch for the pass: the patch (world coordinates), the flux it brings to the plane, and the
// receive flag (a > 0: received).
struct Arrival {
  Patch patch;
  glm::dvec3 flux{0.0};
  float received = 1.0f;
};

struct ReceiverPassFixture {
  gl::GlContext& gl = test_scenes::glContext();  // first: everything below needs it current
  gl::ShaderLibrary library;
  gpu::ReceiverPass pass{library};
  ReceiverMap map;
  glm::dvec3 origin{0.0};  // the grid's origin: the list holds world − origin

  ReceiverPassFixture(const ReceiverMap& m, glm::dvec3 o) : map(m), origin(o) {}

  // The patch as the GPU holds it: grid-local, packed to float.
  PatchTexels packed(const Patch& world) const {
    Patch local = world;
    for (auto& x : local.x) x -= origin;
    return packPatch(local);
  }
  // ... and back in world coordinates (double), for the CPU reference.
  Patch asSeenByGpu(const Patch& world) const {
    Patch p = unpackPatch(packed(world));
    for (auto& x : p.x) x += origin;
    return p;
  }

  // The GPU pass: flux per texel (u fastest). `map_out`, when given, gets the irradiance (fill).
  std::vector<glm::dvec3> gpu(const std::vector<Arrival>& arrivals, ReceiverMap* map_out = nullptr) const {
    std::vector<PatchTexels> texels;
    for (const Arrival& a : arrivals) texels.push_back(packed(a.patch));
    const int side = patchSideFor(texels.size(), 2);
    PatchTextures list(side);
    list.upload(texels);
    std::vector<float> info(static_cast<std::size_t>(side) * static_cast<std::size_t>(side) * 4, 0.0f);
    for (std::size_t k = 0; k < arrivals.size(); ++k) {
      const glm::ivec2 t = mortonTexel(static_cast<std::uint32_t>(k));
      const std::size_t at = (static_cast<std::size_t>(t.y) * static_cast<std::size_t>(side) + static_cast<std::size_t>(t.x)) * 4;
      for (int c = 0; c < 3; ++c) info[at + static_cast<std::size_t>(c)] = static_cast<float>(arrivals[k].flux[c]);
      info[at + 3] = arrivals[k].received;
    }
    const gl::Texture2D receiveInfo(glm::ivec2(side), gl::TextureFormat::RGBA32F, info, 4,
                                    {gl::Filter::Nearest, gl::Wrap::ClampToEdge});
    gpu::ReceiverTarget target(map.texels);
    pass.run(list, receiveInfo, arrivals.size(), target, map, origin);
    if (map_out) target.fill(*map_out);
    return target.readFlux();
  }

  // The CPU reference (receiver.h), on the float-rounded patches and fluxes.
  std::vector<glm::dvec3> cpu(const std::vector<Arrival>& arrivals) const {
    std::vector<glm::dvec3> flux(map.texelCount(), glm::dvec3(0.0));
    for (const Arrival& a : arrivals) {
      if (!(a.received > 0.0f)) continue;
      std::array<glm::dvec2, 4> footprint;
      if (!patchFootprint(asSeenByGpu(a.patch), map, footprint)) continue;
      depositFootprint(map, footprint, glm::dvec3(glm::vec3(a.flux)), flux);
    }
    return flux;
  }
};

glm::dvec3 total(const std::vector<glm::dvec3>& flux) {
  glm::dvec3 sum(0.0);
  for (const glm::dvec3& f : flux) sum += f;
  return sum;
}

double maxComponent(glm::dvec3 v) { return std::max(std::abs(v.x), std::max(std::abs(v.y), std::abs(v.z))); }

// Per-texel agreement: |gpu − cpu| ≤ tolerance in every channel; returns the largest difference.
double expectTexelsNear(const std::vector<glm::dvec3>& gpu, const std::vector<glm::dvec3>& cpu, glm::ivec2 texels,
                        double tolerance, const std::string& what) {
  double worst = 0.0;
  int reported = 0;
  for (std::size_t t = 0; t < cpu.size(); ++t) {
    const double diff = maxComponent(gpu[t] - cpu[t]);
    worst = std::max(worst, diff);
    if (!(diff <= tolerance) && reported++ < 5)
      ADD_FAILURE() << what << ": texel (" << t % static_cast<std::size_t>(texels.x) << ", "
                    << t / static_cast<std::size_t>(texels.x) << "): gpu (" << gpu[t].x << ", " << gpu[t].y << ", "
                    << gpu[t].z << "), cpu (" << cpu[t].x << ", " << cpu[t].y << ", " << cpu[t].z << ")";
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------

TEST(ReceiverPassTest, HandMadeFootprintsMatchTheCpu) {
  // A ground (normal +y: u = +x, v = −z) with a 32² map of 0.05 texels; the grid's origin is off
  // the plane's point so that the pass's grid-local → plane transform is exercised.
  const ReceiverMap map = makeMap({0.3, -0.35, 0.2}, {0, 1, 0}, {-0.7, -0.9}, 0.05, {32, 32});
  ReceiverPassFixture fx(map, {-1.1, -0.6, -0.4});
  const glm::dvec3 down = -map.normal;
  const double deg = std::acos(-1.0) / 180.0;
  // w tilted 35° from the normal, between u and v; the patch a square across it, so its footprint
  // is that square stretched by 1/cos 35° along the tilt.
  const glm::dvec3 tilt = glm::normalize(map.u + 0.4 * map.v);
  const glm::dvec3 oblique = std::cos(35 * deg) * down + std::sin(35 * deg) * tilt;
  Patch slanted;
  {
    const glm::dvec3 a1 = glm::normalize(glm::cross(oblique, map.v)), a2 = glm::cross(oblique, a1);
    const glm::dvec3 centre = onPlane(map, {17.3, 9.6}) - 0.4 * oblique;
    const double e = 0.23;  // 4.6 texels
    const double s[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
    for (std::size_t c = 0; c < 4; ++c) {
      slanted.x[c] = centre + e * (s[c][0] * a1 + s[c][1] * a2);
      slanted.w[c] = 1.33 * oblique;  // in water: |w| = n
    }
    std::array<glm::dvec2, 4> f;
    ASSERT_TRUE(patchFootprint(slanted, map, f));
    const double area = 0.5 * std::abs((f[2] - f[0]).x * (f[3] - f[1]).y - (f[2] - f[0]).y * (f[3] - f[1]).x);
    ASSERT_NEAR(area, e * e / std::cos(35 * deg), 1e-12) << "the footprint is stretched by 1/cos θ";
  }
  // A patch collapsed to a point (all corners and directions equal): a footprint of no area, in
  // float and in double, whose flux goes to the texel of its centroid (depositConvex).
  Patch collapsed;
  for (std::size_t c = 0; c < 4; ++c) {
    collapsed.x[c] = onPlane(map, {20.5, 3.25}) + glm::dvec3(0.1, 0.3, -0.05);
    collapsed.w[c] = glm::normalize(onPlane(map, {20.5, 3.25}) - collapsed.x[c]);
  }
  // A corner ray parallel to the plane (w·normal == 0 exactly, in double and in float).
  Patch grazing = patchOnto(map, {{{3, 24}, {6, 24}, {6, 27}, {3, 27}}}, down, 0.2);
  grazing.w[2] = glm::dvec3(1.0, 0.0, 0.0);

  struct Case {
    std::string name;
    Arrival arrival;
  };
  const std::vector<Case> cases = {
      {"texel-aligned square", {patchOnto(map, {{{4, 4}, {8, 4}, {8, 8}, {4, 8}}}, down, 0.3), {1.6, 3.2, 0.8}}},
      {"oblique (35°)", {slanted, {2.0, 1.0, 0.5}}},
      {"concave", {patchOnto(map, {{{10.3, 10.2}, {14.1, 12.6}, {20.4, 10.1}, {14.2, 20.7}}}, down, 0.25), {1, 2, 3}}},
      {"twisted (bow-tie)",
       {patchOnto(map, {{{5.2, 13.7}, {12.4, 13.1}, {5.9, 20.3}, {12.8, 20.6}}},
                  {down, down + 0.1 * map.u, down - 0.2 * map.v, down + 0.15 * (map.u + map.v)}, 0.35),
        {0.7, 0.7, 0.7}}},
      {"partly off the map", {patchOnto(map, {{{-3.3, 20.2}, {6.1, 19.4}, {7.5, 35.8}, {-2.2, 34.1}}}, down, 0.2), {3, 1, 2}}},
      {"not received (a = 0)", {patchOnto(map, {{{22, 22}, {27, 22}, {27, 27}, {22, 27}}}, down, 0.2), {5, 5, 5}, 0.0f}},
      {"not received (a < 0)", {patchOnto(map, {{{22, 22}, {27, 22}, {27, 27}, {22, 27}}}, down, 0.2), {5, 5, 5}, -1.0f}},
      {"degenerate (collapsed to a point)", {collapsed, {0.9, 0.3, 0.6}}},
      {"a corner ray parallel to the plane", {grazing, {4, 4, 4}}},
  };

  // Tolerance: 1e-5 of the patch's flux per texel. The shader computes the footprint corners in
  // float from coordinates of about 1 world unit (ulp 1.2e-7, i.e. 2.4e-6 texel), so they are off
  // by at most a few 1e-6 texel; moving an edge of length L (texels) by δ moves δ·L of the
  // footprint's area A from one texel to the next, a fraction δ·L/A ≲ 1e-5 of the flux for these
  // footprints (L/A ≲ 1 texel⁻¹). The clipping runs relative to each texel (errors ~1e-7 of a
  // texel's area). Measured: below 1e-7 of the flux. A wrong texel, share or clip is off by far
  // more (≥ 1e-3 of the flux).
  std::vector<Arrival> all;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::vector<Arrival> one = {c.arrival};
    const std::vector<glm::dvec3> gpu = fx.gpu(one), cpu = fx.cpu(one);
    const double worst = expectTexelsNear(gpu, cpu, map.texels, 1e-5 * maxComponent(c.arrival.flux), c.name);
    EXPECT_LE(maxComponent(total(gpu) - total(cpu)), 1e-5 * maxComponent(c.arrival.flux)) << "total flux";
    std::printf("[ receiver ] %-36s worst texel difference %.3g of the flux\n", c.name.c_str(),
                worst / maxComponent(c.arrival.flux));
    all.push_back(c.arrival);
  }

  // What each case must deposit, independently of the reference.
  const std::vector<glm::dvec3> aligned = fx.gpu({cases[0].arrival});
  for (int j = 0; j < 32; ++j)
    for (int i = 0; i < 32; ++i) {
      const bool inside = i >= 4 && i < 8 && j >= 4 && j < 8;
      const glm::dvec3 want = inside ? cases[0].arrival.flux / 16.0 : glm::dvec3(0.0);
      EXPECT_LE(maxComponent(aligned[static_cast<std::size_t>(j) * 32 + static_cast<std::size_t>(i)] - want), 1e-6)
          << "aligned square, texel (" << i << ", " << j << ")";
    }
  for (std::size_t k : {1u, 2u, 3u, 7u}) {  // wholly on the map: all of the flux
    const glm::dvec3 sum = total(fx.gpu({cases[k].arrival}));
    EXPECT_LE(maxComponent(sum - cases[k].arrival.flux), 1e-5 * maxComponent(cases[k].arrival.flux)) << cases[k].name;
  }
  const glm::dvec3 off = total(fx.gpu({cases[4].arrival}));
  EXPECT_GT(off.x, 0.2 * cases[4].arrival.flux.x) << "part of it on the map";
  EXPECT_LT(off.x, 0.8 * cases[4].arrival.flux.x) << "part of it off the map, dropped";
  for (std::size_t k : {5u, 6u, 8u}) EXPECT_EQ(maxComponent(total(fx.gpu({cases[k].arrival}))), 0.0) << cases[k].name;
  const std::vector<glm::dvec3> point = fx.gpu({cases[7].arrival});
  EXPECT_LE(maxComponent(point[3 * 32 + 20] - cases[7].arrival.flux), 1e-6) << "collapsed: all in texel (20, 3)";

  // Corner rays that all meet the plane at one point (a focus on the plane): a footprint of float
  // rounding's size. The GPU treats it as degenerate (thinner than float resolves) and puts all of
  // its flux into the texel of the focus. (Not compared with the CPU: depositFootprint clips such
  // a speck with a shoelace sum in plane coordinates of size ~1, which cancels catastrophically
  // and can return more flux than the patch has.)
  Arrival focus{{}, {0.9, 0.3, 0.6}};
  for (std::size_t c = 0; c < 4; ++c) {
    focus.patch.x[c] = onPlane(map, {12.5, 27.75}) +
                       glm::dvec3(0.05 * static_cast<double>(c % 2), 0.3, 0.05 * static_cast<double>(c / 2));
    focus.patch.w[c] = glm::normalize(onPlane(map, {12.5, 27.75}) - focus.patch.x[c]);
  }
  const std::vector<glm::dvec3> focused = fx.gpu({focus});

  // Light grazing the plane: one corner ray meets it 1e4 texels away, so the triangles reach far
  // off the map and cross its texels as long thin wedges. The crossing points come from the
  // endpoint nearer each texel edge, so the far vertex costs no precision: every texel within 1e-4
  // of its own flux.
  {
    Arrival grazing_far{patchOnto(map, {{{14.3, 14.6}, {18.2, 14.1}, {17.6, 18.9}, {13.8, 18.7}}}, down, 0.3), {1, 1, 1}};
    grazing_far.patch.w[2] = glm::normalize(onPlane(map, {1.0e4, 2.7e3}) - grazing_far.patch.x[2]);
    const std::vector<glm::dvec3> gpu = fx.gpu({grazing_far}), cpu = fx.cpu({grazing_far});
    double worst = 0.0, biggest = 0.0;
    for (const glm::dvec3& c : cpu) biggest = std::max(biggest, c.x);
    for (std::size_t t = 0; t < cpu.size(); ++t) {
      if (cpu[t].x > 1e-3 * biggest) worst = std::max(worst, std::abs(gpu[t].x / cpu[t].x - 1.0));
      EXPECT_NEAR(gpu[t].x, cpu[t].x, 1e-4 * cpu[t].x + 1e-9) << "grazing, texel " << t;
    }
    std::printf("[ receiver ] grazing: worst relative texel difference %.3g (map flux %.3g)\n", worst,
                total(cpu).x);
    EXPECT_GT(total(cpu).x, 1e-3) << "part of the flux on the map";
  }

  EXPECT_LE(maxComponent(focused[27 * 32 + 12] - focus.flux), 1e-6) << "focus: all in texel (12, 27)";
  EXPECT_LE(maxComponent(total(focused) - focus.flux), 1e-6) << "focus: nothing elsewhere";

  // All at once (additive, and patch k reads its own receive info): the sum of the cases.
  ReceiverMap filled = map;
  const std::vector<glm::dvec3> gpu = fx.gpu(all, &filled), cpu = fx.cpu(all);
  expectTexelsNear(gpu, cpu, map.texels, 1e-5 * 3.2, "all cases together");
  // fill(): irradiance = flux / pitch², RGB floats, u fastest.
  ASSERT_EQ(filled.irradiance.size(), map.texelCount() * 3);
  for (std::size_t t = 0; t < map.texelCount(); ++t)
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(filled.irradiance[3 * t + static_cast<std::size_t>(c)], gpu[t][c] / (0.05 * 0.05),
                  1e-6 * (1.0 + gpu[t][c] / (0.05 * 0.05)));
}

TEST(ReceiverPassTest, RandomPatchesMatchTheCpu) {
  // A tilted plane, a 48 × 40 map (not a power of two), a thousand random patches: sizes from a
  // fifth of a texel to 8 texels, corners jittered (some concave, some twisted, some shuffled into
  // bow-ties), corner rays tilted up to 60° and spread a little, some partly or wholly off the map,
  // a tenth not received.
  const ReceiverMap map = makeMap({0.2, 0.1, -0.3}, {0.25, 1.0, -0.15}, {-1.1, -0.8}, 0.045, {48, 40});
  ReceiverPassFixture fx(map, {-0.9, -0.2, -1.2});
  std::mt19937 rng(20240611u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  const double pi = std::acos(-1.0);
  std::vector<Arrival> arrivals;
  glm::dvec3 received(0.0);
  for (int k = 0; k < 1000; ++k) {
    const glm::dvec2 centre(uniform(-4.0, 52.0), uniform(-4.0, 44.0));
    const double size = std::exp(uniform(std::log(0.2), std::log(8.0)));
    const double angle = uniform(0.0, 2.0 * pi);
    const glm::dvec2 e1(std::cos(angle), std::sin(angle)), e2(-e1.y, e1.x);
    const double s[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
    std::array<glm::dvec2, 4> t;
    for (std::size_t c = 0; c < 4; ++c)
      t[c] = centre + size * ((s[c][0] + uniform(-0.3, 0.3)) * e1 + (s[c][1] + uniform(-0.3, 0.3)) * e2);
    if (unit(rng) < 0.1) std::swap(t[1], t[2]);  // a bow-tie
    const double theta = uniform(0.0, 60.0) * pi / 180.0, phi = uniform(0.0, 2.0 * pi);
    const glm::dvec3 dir = std::cos(theta) * -map.normal + std::sin(theta) * (std::cos(phi) * map.u + std::sin(phi) * map.v);
    std::array<glm::dvec3, 4> dirs;
    for (auto& d : dirs) d = dir + glm::dvec3(uniform(-0.05, 0.05), uniform(-0.05, 0.05), uniform(-0.05, 0.05));
    Arrival a{patchOnto(map, t, dirs, uniform(0.02, 1.0), unit(rng) < 0.5 ? 1.0 : 1.5),
              {uniform(0.1, 2.0), uniform(0.1, 2.0), uniform(0.1, 2.0)}};
    if (unit(rng) < 0.1) a.received = unit(rng) < 0.5 ? 0.0f : -1.0f;
    else received += a.flux;
    arrivals.push_back(a);
  }
  const std::vector<glm::dvec3> gpu = fx.gpu(arrivals), cpu = fx.cpu(arrivals);
  double diff2 = 0.0, norm2 = 0.0;
  for (std::size_t t = 0; t < cpu.size(); ++t) {
    const glm::dvec3 d = gpu[t] - cpu[t];
    diff2 += glm::dot(d, d);
    norm2 += glm::dot(cpu[t], cpu[t]);
  }
  const double relative = std::sqrt(diff2 / norm2);
  EXPECT_LE(relative, 1e-4) << "relative L2 difference of the maps";
  std::printf("[ receiver ] random patches: relative L2 %.3g\n", relative);
  // The flux on the map: most of what was received (the rest fell off the map), the same as the
  // CPU's to float summation (a few hundred float additions per texel and channel).
  const glm::dvec3 g = total(gpu), c = total(cpu);
  EXPECT_GT(c.x, 0.5 * received.x);
  EXPECT_LT(c.x, 0.99 * received.x);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(g[ch], c[ch], 1e-5 * c[ch]) << "total flux, channel " << ch;
}

TEST(ReceiverPassTest, TiledWavefrontGivesUniformIrradiance) {
  // A plane wavefront of irradiance E travelling along L, 50° from the (tilted) plane's normal,
  // cut into a 9 × 7 grid of square patches of edge e: their footprints tile a parallelogram of the
  // plane, where the planar irradiance is E·cos θ (θ between L and the normal) in every texel the
  // parallelogram covers whole. No footprint is aligned with the texels (about 2.5 × 3.9 texels).
  const ReceiverMap map = makeMap({-0.1, 0.05, 0.2}, {-0.2, 1.0, 0.3}, {-0.9, -0.7}, 0.04, {48, 48});
  ReceiverPassFixture fx(map, {-1.0, -0.5, -0.6});
  const double pi = std::acos(-1.0), theta = 50.0 * pi / 180.0;
  const glm::dvec3 L = std::cos(theta) * -map.normal + std::sin(theta) * glm::normalize(map.u - 0.3 * map.v);
  const glm::dvec3 a0 = glm::normalize(glm::cross(L, map.u + 0.2 * map.v)), b0 = glm::cross(L, a0);
  // Rotate the wavefront's lattice within its plane, off the texel axes.
  const double r = 0.3;
  const glm::dvec3 a1 = std::cos(r) * a0 + std::sin(r) * b0, a2 = glm::cross(L, a1);
  const glm::dvec3 E(1.0, 0.5, 2.0);
  const double e = 0.1;
  const int nu = 9, nv = 7;
  const glm::dvec3 start = onPlane(map, {24.0, 24.0}) - 1.5 * L - 0.5 * e * (double(nu) * a1 + double(nv) * a2);
  auto lattice = [&](int i, int j) { return start + e * (double(i) * a1 + double(j) * a2); };
  std::vector<Arrival> arrivals;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      Arrival a;
      a.patch.x = {lattice(i, j), lattice(i + 1, j), lattice(i + 1, j + 1), lattice(i, j + 1)};
      for (auto& w : a.patch.w) w = L;
      a.flux = E * (e * e);
      arrivals.push_back(a);
    }
  ReceiverMap filled = map;
  const std::vector<glm::dvec3> gpu = fx.gpu(arrivals, &filled);

  // The covered parallelogram, in texel coordinates (double), and the texels it holds whole.
  const double cos_theta = -glm::dot(L, map.normal);
  Patch whole;
  whole.x = {lattice(0, 0), lattice(nu, 0), lattice(nu, nv), lattice(0, nv)};
  for (auto& w : whole.w) w = L;
  std::array<glm::dvec2, 4> f;
  ASSERT_TRUE(patchFootprint(whole, map, f));
  for (auto& p : f) p = (p - map.origin) / map.pitch;
  const double orient = (f[1] - f[0]).x * (f[2] - f[0]).y - (f[1] - f[0]).y * (f[2] - f[0]).x > 0.0 ? 1.0 : -1.0;
  auto inside = [&](glm::dvec2 q) {
    for (int k = 0; k < 4; ++k) {
      const glm::dvec2 a = f[static_cast<std::size_t>(k)], b = f[static_cast<std::size_t>((k + 1) % 4)];
      if (orient * ((b - a).x * (q - a).y - (b - a).y * (q - a).x) < 1e-6) return false;
    }
    return true;
  };
  const glm::dvec3 want = E * cos_theta;
  int covered = 0;
  double worst = 0.0;
  for (int j = 0; j < map.texels.y; ++j)
    for (int i = 0; i < map.texels.x; ++i) {
      if (!(inside({i, j}) && inside({i + 1, j}) && inside({i, j + 1}) && inside({i + 1, j + 1}))) continue;
      ++covered;
      const std::size_t t = static_cast<std::size_t>(j) * static_cast<std::size_t>(map.texels.x) + static_cast<std::size_t>(i);
      for (int c = 0; c < 3; ++c) {
        const double got = filled.irradiance[3 * t + static_cast<std::size_t>(c)];
        worst = std::max(worst, std::abs(got / want[c] - 1.0));
        EXPECT_NEAR(got, want[c], 1e-5 * want[c]) << "texel (" << i << ", " << j << "), channel " << c;
      }
    }
  EXPECT_GT(covered, 300) << "texels wholly inside the tiled region";
  std::printf("[ receiver ] tiling: %d covered texels, worst relative deviation %.3g\n", covered, worst);
  // Flux conservation: the whole wavefront lands on the map.
  const glm::dvec3 sum = total(gpu), in = E * (e * e * nu * nv);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], in[c], 1e-5 * in[c]) << "total flux, channel " << c;
  // And the CPU agrees texel by texel (edges included).
  expectTexelsNear(gpu, fx.cpu(arrivals), map.texels, 1e-5 * maxComponent(E * (e * e)), "tiling vs cpu");
}

TEST(ReceiverPassTest, TargetChecksItsSize) {
  gl::GlContext& gl = test_scenes::glContext();
  const int limit = gl.info().maxTextureSize;
  try {
    gpu::ReceiverTarget target(glm::ivec2(limit + 1, 4));
    FAIL() << "a map wider than GL_MAX_TEXTURE_SIZE was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("GL_MAX_TEXTURE_SIZE"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("receiver"), std::string::npos) << e.what();
  }
  EXPECT_THROW(gpu::ReceiverTarget(glm::ivec2(0, 4)), InputError);
  gpu::ReceiverTarget target(glm::ivec2(5, 3));
  EXPECT_EQ(target.bytes(), 5u * 3u * 16u);
  const std::vector<glm::dvec3> flux = target.readFlux();
  ASSERT_EQ(flux.size(), 15u);
  for (const glm::dvec3& f : flux) EXPECT_EQ(maxComponent(f), 0.0) << "cleared";
  ReceiverMap wrong = makeMap({0, 0, 0}, {0, 1, 0}, {0, 0}, 0.1, {4, 3});
  EXPECT_THROW(target.fill(wrong), RuntimeError);
}

}  // namespace
}  // namespace eik
