// The CPU twin of the light simulator against analytic answers (docs/testing.md): energy, Fresnel,
// Beer–Lambert, the ball lens, the Luneburg lens, shadows, point lights and determinism.
//
// Scenes are built in memory with the voxelizer (test_scenes.h) and assume its default
// pre-smoothing of n, σ = 0.75 voxel (docs/physics.md: tests state the σ they assume). All run in a few
// seconds on two cores in a Release build.
#include "lightsim/cpu_simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "core/stopwatch.h"
#include "lightsim/bake.h"
#include "lightsim/test_scenes.h"

namespace eik {
namespace {

using namespace test_scenes;

constexpr double kPi = std::numbers::pi;

// Relative residual of the energy ledger, worst channel.
double ledgerResidual(const SimulationStats& s) { return s.ledgerResidual(); }

// The y index of the voxel layer that contains the world coordinate y.
int layerOf(const GridSpec& g, double y) { return int(std::floor((y - g.bounds_min.y) / g.voxelSize().y)); }

// ---------------------------------------------------------------------------------------------
// Plane waves in a homogeneous medium

TEST(CpuSimulator, PlaneWaveDepositsItsIrradiance) {
  const GridSpec g = cubicGrid(24, 0.5);
  CpuSimulator sim(uniformVolume(g, 1.0));
  LightSpec light;
  light.power = {2.0, 1.0, 0.5};
  const BakeResult r = sim.run(light, test_scenes::pointDepositOptions());
  // Step 0.5 voxel: two deposits of Φ·Δs/V per voxel, E = E_L exactly.
  for (int j = 0; j < 24; ++j) {
    EXPECT_NEAR(voxelValue(r.irradiance, g, 5, j, 17).x, 2.0, 1e-5) << j;
    EXPECT_NEAR(voxelValue(r.irradiance, g, 5, j, 17).z, 0.5, 1e-5) << j;
    EXPECT_EQ(voxelValue(r.light_dir, g, 5, j, 17), glm::dvec3(0, -1, 0));
  }
  EXPECT_EQ(r.stats.splits, 0u);
  EXPECT_EQ(r.stats.kills.exited, 24u * 24u);
  EXPECT_EQ(r.stats.flux_out, r.stats.flux_in);
  EXPECT_NEAR(r.stats.flux_in.x, 2.0, 1e-12);
  EXPECT_EQ(r.stats.backend, "cpu");
  // The max deposit (thesis §6.2.3) stores the same E and direction.
  SimulationOptions max;
  max.deposit = DepositMode::Max;
  const BakeResult m = sim.run(light, max);
  EXPECT_NEAR(voxelValue(m.irradiance, g, 9, 3, 2).y, 1.0, 1e-6);
  EXPECT_EQ(voxelValue(m.light_dir, g, 9, 3, 2), glm::dvec3(0, -1, 0));
}

TEST(CpuSimulator, ObliquePlaneWaveInGlassKeepsItsIrradianceOnAverage) {
  // In a uniform medium of index n the light travels straight and E is unchanged; deposits are
  // point samples, so single voxels alias (a patch deposits 1–3 times in a voxel), the mean does not.
  const GridSpec g = cubicGrid(24, 0.5);
  CpuSimulator sim(uniformVolume(g, 1.5));
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.4, -1.0, 0.25));
  for (Integrator integrator : {Integrator::Euler, Integrator::RK2, Integrator::RK4}) {
    SimulationOptions o;
    o.integrator = integrator;
    const BakeResult r = sim.run(light, o);
    double sum = 0.0;
    int n = 0;
    for (int k = 8; k < 16; ++k)
      for (int j = 8; j < 16; ++j)
        for (int i = 8; i < 16; ++i) {
          sum += voxelValue(r.irradiance, g, i, j, k).x;
          ++n;
          EXPECT_NEAR(glm::distance(voxelValue(r.light_dir, g, i, j, k), light.direction), 0.0, 1e-6);
        }
    EXPECT_NEAR(sum / n, 1.0, 0.01);
    EXPECT_LT(ledgerResidual(r.stats), 1e-12);
    EXPECT_EQ(r.stats.flux_reflected, glm::dvec3(0.0));
  }
}

// ---------------------------------------------------------------------------------------------
// Energy

// One ray by the ray equation in arc length (Eq. 4.8/4.9: dx/ds = w/n, dw/ds = ∇n), classical
// RK4 with a step of 1/20 voxel, through the same n field: an independent check of the wavefront
// simulation. It tracks boundary layers with the same rules as ALGORITHM.md step 3
// (boundaryReflectance), evaluated along the ray instead of at patch midpoints every ½ voxel.
struct TracedRay {
  int exit_face = -1;        // as exitFace: 0 −x, 1 +x, 2 −y, 3 +y, 4 −z, 5 +z
  double transmitted = 1.0;  // Π (1 − R) over the boundary layers crossed
  glm::dvec3 exit_point{0.0};
};

TracedRay traceRay(const VolumeSampler& s, glm::dvec3 x, const glm::dvec3& dir, const SimulationOptions& o,
                   double steps_per_voxel = 20.0) {
  const GridSpec& g = s.grid();
  const double h = s.h(), ds = h / steps_per_voxel;
  glm::dvec3 w = dir * s.ior(x);
  auto f = [&](const glm::dvec3& p, const glm::dvec3& q, glm::dvec3& dp, glm::dvec3& dq) {
    const glm::dvec4 ng = s.iorAndGradient(p);
    dp = q / ng.x;
    dq = glm::dvec3(ng.y, ng.z, ng.w);
  };
  TracedRay ray;
  double n_in = 0.0, cos_in = 0.0;
  bool entered = false;
  for (int step = 0; step < 1000000; ++step) {
    const bool inside = insideBox(x, g.bounds_min, g.bounds_max);
    if (inside) entered = true;
    if (entered && !inside) break;
    glm::dvec3 a1, b1, a2, b2, a3, b3, a4, b4;
    f(x, w, a1, b1);
    f(x + 0.5 * ds * a1, w + 0.5 * ds * b1, a2, b2);
    f(x + 0.5 * ds * a2, w + 0.5 * ds * b2, a3, b3);
    f(x + ds * a3, w + ds * b3, a4, b4);
    const glm::dvec3 d_old = glm::normalize(w);
    const double n_old = s.ior(x);
    x += ds / 6 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
    w += ds / 6 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
    const glm::dvec4 ng = s.iorAndGradient(x);
    const glm::dvec3 grad(ng.y, ng.z, ng.w);
    const double len = glm::length(grad);
    if (n_in == 0.0 && len * h > o.boundary_on) {
      n_in = n_old;
      cos_in = std::fabs(glm::dot(d_old, grad / len));
    } else if (n_in != 0.0 && len * h < o.boundary_off) {
      const double cos_out = len > 0.0 ? std::fabs(glm::dot(glm::normalize(w), grad / len)) : -1.0;
      ray.transmitted *= 1.0 - boundaryReflectance(n_in, cos_in, ng.x, cos_out, o.boundary_off);
      n_in = 0.0;
    }
  }
  ray.exit_point = x;
  ray.exit_face = exitFace(x, glm::normalize(w), g);
  return ray;
}

TEST(CpuSimulator, EnergyLedgerClosesAndThePlaneBelowTheSphereGetsWhatRayTracingPredicts) {
  // A glass sphere (n = 1.5, r = 0.5) at h = 0.04 (r = 12.5 voxels), lit straight down (E = 1).
  // The grid's bottom face, 0.2 below the sphere, is the plane below it.
  const double R = 0.5;
  const Volume v = glassSphere(40, box({-0.8, -0.7, -0.8}, {0.8, 0.6, 0.8}), R, 1.5);
  CpuSimulator sim(v);
  const LightSpec light;
  const SimulationOptions options = test_scenes::pointDepositOptions();
  CpuRunDiagnostics diag;
  const BakeResult r = sim.run(light, options, &diag);
  const SimulationStats& s = r.stats;
  const GridSpec& g = v.grid;
  std::printf("flux in %.6f out %.6f reflected %.6f killed %.6f absorbed %.6f unfinished %.6f\n", s.flux_in.x,
              s.flux_out.x, s.flux_reflected.x, s.flux_killed.x, s.flux_absorbed.x, s.flux_unfinished.x);

  // 1. The ledger: flux_in = out + absorbed + reflected + killed + unfinished.
  EXPECT_NEAR(s.flux_in.x, g.extent().x * g.extent().z, 1e-9);
  EXPECT_LT(ledgerResidual(s), 1e-6);
  std::printf("ledger relative residual %.3g\n", ledgerResidual(s));
  glm::dvec3 by_face(0.0);
  for (const glm::dvec3& f : diag.flux_out_by_face) by_face += f;
  EXPECT_NEAR(by_face.x, s.flux_out.x, 1e-9);
  EXPECT_LT(s.flux_killed.x, 0.005 * s.flux_in.x);

  // 2. The flux through the plane below is not simply in − reflected: the smoothed sphere turns
  // part of the light by more than 90° (the sharp sphere up to 96°; the smoothed boundary,
  // 4–5 voxels thick on a 12.5-voxel radius, bends marginal rays more, since n·r·sin θ is conserved
  // across it), and that light leaves through the sides and the top. So predict it by tracing
  // rays through the same n field, 4 per voxel edge over the sphere's disc and its smoothed rim.
  const double spacing = g.voxelSize().x / 4.0, rim = R + 3.0 * g.voxelSize().x;
  const int n_side = int(std::ceil(rim / spacing));
  std::vector<TracedRay> rays(std::size_t(4 * n_side * n_side));
  std::vector<char> traced(rays.size(), 0);
  parallelFor(0, 2 * n_side, [&](std::int64_t row) {
    const int b = int(row) - n_side;
    for (int a = -n_side; a < n_side; ++a) {
      const double x = (a + 0.5) * spacing, z = (b + 0.5) * spacing;
      if (x * x + z * z > rim * rim) continue;
      const std::size_t k = std::size_t(row) * std::size_t(2 * n_side) + std::size_t(a + n_side);
      rays[k] = traceRay(sim.sampler(), {x, g.bounds_max.y + 0.5 * g.voxelSize().y, z}, {0, -1, 0}, options);
      traced[k] = 1;
    }
  });
  double traced_bottom = 0.0, traced_other = 0.0, traced_area = 0.0, traced_reflected = 0.0;
  const double flux = spacing * spacing;  // per ray, E = 1
  for (std::size_t k = 0; k < rays.size(); ++k) {
    if (!traced[k]) continue;
    traced_area += flux;
    traced_reflected += flux * (1.0 - rays[k].transmitted);
    (rays[k].exit_face == 2 ? traced_bottom : traced_other) += flux * rays[k].transmitted;
  }
  const double straight = s.flux_in.x - traced_area;  // light that passes beside the rim
  const double predicted = straight + traced_bottom;
  const double bottom = diag.flux_out_by_face[2].x;
  const double sphere_flux = kPi * R * R;
  std::printf("through the plane below: %.5f; in - reflected %.5f; ray-traced prediction %.5f (%+.2f %% of the sphere's "
              "flux); traced: reflected %.5f, turned to the sides/top %.5f\n",
              bottom, s.flux_in.x - s.flux_reflected.x, predicted, 100.0 * (bottom - predicted) / sphere_flux,
              traced_reflected, traced_other);
  std::printf("light leaving through the sides and top: simulated %.5f, traced %.5f\n", s.flux_out.x - bottom,
              traced_other);
  // Within 1.5 % of the sphere's own flux πr² (0.46 % of the total flux in; the issue asks for 1 %
  // of it), plus the flux the simulator killed on the way (flux limit, ALGORITHM.md step 5), which
  // the tracer keeps. Measured: −1.04 % of πr² with the defaults (max_depth 6, patches kept at the
  // limit), −1.02 % with max_depth 8; with max_depth 8 and kills (the thesis) it was −1.11 %, of
  // which the killed flux explained 0.3 %.
  EXPECT_NEAR(bottom, predicted, 0.015 * sphere_flux + s.flux_killed.x);
  EXPECT_NEAR(s.flux_reflected.x, traced_reflected, 0.01 * sphere_flux);

  // 3. The reflected flux against the sharp sphere's single-bounce value,
  // πr²·∫ (R + (1 − R)·R) 2 sin θ cos θ dθ = 0.1292 W for n = 1.5 (entry plus exit): the smoothed
  // boundary refracts like a slightly different sphere, so allow 15 %.
  std::printf("reflected %.4f vs the sharp sphere's 0.1292\n", s.flux_reflected.x);
  EXPECT_NEAR(s.flux_reflected.x, 0.1292, 0.15 * 0.1292);

  // 4. The same plane read from the bake (what a user of the volume can do): Σ E·(light_dir·−ŷ)·h²
  // over the bottom voxel layers. Where patches of different directions share a voxel, light_dir is
  // their mean and E·cos(mean) over-reads Σ E_p·cos θ_p (|mean| ≤ 1); below a ball lens rays cross
  // everywhere (spherical aberration), so this reads high, by about 11 % here, never low.
  const double field = downwardFlux(r.irradiance, r.light_dir, g, 0, 2).x;
  std::printf("planar flux from the bake fields %.5f (%+.2f %% of the exact flux through the plane)\n", field,
              100.0 * (field / bottom - 1.0));
  EXPECT_GT(field, 0.99 * bottom);
  EXPECT_LT(field, 1.15 * bottom);
}

TEST(CpuSimulator, GlassSlabTransmitsTwoFresnelFactors) {
  // A slab of n = 1.5, 0.3 thick, filling the grid's cross-section, at normal incidence: below
  // it the flux is (1 − R)² of what came in, R = ((n − 1)/(n + 1))² = 0.04 (the reflections are
  // not followed, so no inter-reflection terms). Rays are parallel everywhere, so the bake-level
  // planar flux is exact here.
  const Bounds b = box({-0.25, -0.5, -0.25}, {0.25, 0.5, 0.25});
  const Volume v = slab(32, b, -0.15, 0.3, 1.5, glm::dvec3(0.0));
  CpuSimulator sim(v);
  const BakeResult r = sim.run(LightSpec{}, test_scenes::pointDepositOptions());
  const double in = r.stats.flux_in.x, R = 0.04;
  const int j = layerOf(v.grid, -0.35);
  const double below = downwardFlux(r.irradiance, r.light_dir, v.grid, j - 4, j).x;
  std::printf("slab: planar flux below %.6f, expected %.6f (%+.3f %%); reflected %.6f expected %.6f\n", below,
              in * (1 - R) * (1 - R), 100 * (below / (in * (1 - R) * (1 - R)) - 1), r.stats.flux_reflected.x,
              in * (R + (1 - R) * R));
  EXPECT_NEAR(below, in * (1 - R) * (1 - R), 0.01 * in);
  EXPECT_NEAR(r.stats.flux_reflected.x, in * (R + (1 - R) * R), 0.01 * in * (R + (1 - R) * R) + 1e-9);
  EXPECT_LT(ledgerResidual(r.stats), 1e-6);
}

TEST(CpuSimulator, AbsorbingSlabFollowsBeerLambert) {
  // n = 1 (no refraction, no Fresnel), σa = (0.5, 1, 2) per unit, d = 0.4: T = exp(−σa·d).
  // σa is box-filtered, not smoothed, and sampled trilinearly: Σ σa(m)·Δs over the slab is the
  // trapezoid rule on a piecewise-linear profile whose integral is σa·d.
  const Bounds b = box({-0.25, -0.5, -0.25}, {0.25, 0.5, 0.25});
  const glm::dvec3 sigma(0.5, 1.0, 2.0);
  const double d = 0.4;
  const Volume v = slab(32, b, -0.2, d, 1.0, sigma);
  CpuSimulator sim(v);
  const BakeResult r = sim.run(LightSpec{}, test_scenes::pointDepositOptions());
  const glm::dvec3 in = r.stats.flux_in;
  const int j = layerOf(v.grid, -0.3);
  const glm::dvec3 below = downwardFlux(r.irradiance, r.light_dir, v.grid, j - 4, j);
  for (int c = 0; c < 3; ++c) {
    const double t = std::exp(-sigma[c] * d);
    std::printf("slab channel %d: transmitted %.6f, exp(-σa d) %.6f (%+.3f %%)\n", c, below[c] / in[c], t,
                100 * (below[c] / in[c] / t - 1));
    EXPECT_NEAR(below[c] / in[c], t, 0.01 * t);
    EXPECT_NEAR(r.stats.flux_absorbed[c] / in[c], 1.0 - t, 0.01 * t);
  }
  EXPECT_EQ(r.stats.flux_reflected, glm::dvec3(0.0));
  EXPECT_LT(ledgerResidual(r.stats), 1e-6);
}

// ---------------------------------------------------------------------------------------------
// Lenses

// A ray through the volume by the ray equation in arc length (Eq. 4.8/4.9: dx/ds = w/n,
// dw/ds = ∇n), classical RK4 with a step of 1/50 voxel: an independent check of where the smoothed
// lens actually focuses. Returns the y where the ray, started at (ρ, y0, 0) going −y, crosses the
// axis x = 0, or NaN if it leaves the grid first.
double axisCrossing(const VolumeSampler& s, double rho, double y0) {
  glm::dvec3 x(rho, y0, 0.0);
  glm::dvec3 w = glm::dvec3(0, -1, 0) * s.ior(x);
  const double ds = s.h() / 50.0;
  auto f = [&](const glm::dvec3& p, const glm::dvec3& q, glm::dvec3& dp, glm::dvec3& dq) {
    const glm::dvec4 ng = s.iorAndGradient(p);
    dp = q / ng.x;
    dq = glm::dvec3(ng.y, ng.z, ng.w);
  };
  const GridSpec& g = s.grid();
  while (insideBox(x, g.bounds_min, g.bounds_max)) {
    glm::dvec3 a1, b1, a2, b2, a3, b3, a4, b4;
    f(x, w, a1, b1);
    f(x + 0.5 * ds * a1, w + 0.5 * ds * b1, a2, b2);
    f(x + 0.5 * ds * a2, w + 0.5 * ds * b2, a3, b3);
    f(x + ds * a3, w + ds * b3, a4, b4);
    const glm::dvec3 xn = x + ds / 6 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
    w += ds / 6 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
    if (xn.x <= 0.0) return x.y + (xn.y - x.y) * (x.x / (x.x - xn.x));
    x = xn;
  }
  return std::nan("");
}

// The voxel of largest irradiance (red) on the grid column through the axis x = z = 0, below y0.
int onAxisMaximum(const BakeResult& r, const GridSpec& g, double y0) {
  const int ic = g.dims.x / 2, kc = g.dims.z / 2;
  EXPECT_NEAR(g.center(ic, 0, kc).x, 0.0, 1e-9);  // odd dims: a column centred on the axis
  int best = -1;
  double best_e = -1.0;
  for (int j = 0; j < g.dims.y && g.center(0, j, 0).y < y0; ++j) {
    const double e = voxelValue(r.irradiance, g, ic, j, kc).x;
    if (e > best_e) {
      best_e = e;
      best = j;
    }
  }
  return best;
}

TEST(CpuSimulator, BallLensFocusesBetweenTheMarginalAndTheParaxialFocus) {
  // n = 1.5, R = 0.5, h = 1/30 (R = 15 voxels), odd x/z dims so that a voxel column lies on the
  // axis. The sharp sphere's paraxial focus is nR/(2(n − 1)) = 1.5R from the centre; spherical
  // aberration brings the outer zones to the axis sooner, the outermost (ρ → R) inside the glass.
  const double h = 1.0 / 30.0, R = 0.5;
  const Bounds b = box({-18.5 * h, -0.6 - 18 * h, -18.5 * h}, {18.5 * h, 0.6, 18.5 * h});
  const Volume v = glassSphere(54, b, R, 1.5);
  ASSERT_EQ(v.grid.dims, glm::ivec3(37, 54, 37));
  CpuSimulator sim(v);
  const BakeResult r = sim.run(LightSpec{}, {});

  // The foci of the smoothed sphere actually baked (smoothing shifts them, thesis Fig. 7.1):
  // trace rays through the same n field. Paraxial: ρ = 0.02R. Marginal: the outermost zone
  // (in steps of 0.05R) whose rays still meet the axis outside the glass.
  const VolumeSampler& s = sim.sampler();
  const double paraxial = axisCrossing(s, 0.02 * R, 0.6);
  double marginal = paraxial;
  for (double rho = 0.05; rho < 1.0; rho += 0.05) {
    const double y = axisCrossing(s, rho * R, 0.6);
    if (std::isnan(y) || s.ior({0, y, 0}) > 1.001) break;
    marginal = y;
  }
  const int j = onAxisMaximum(r, v.grid, 0.0);
  const double y_max = v.grid.center(0, j, 0).y;
  std::printf("ball lens: on-axis maximum at %.4f (%.3f R below the centre); traced paraxial focus %.4f (%.3f R, "
              "sharp sphere 1.5 R), marginal focus %.4f (%.3f R)\n",
              y_max, -y_max / R, paraxial, -paraxial / R, marginal, -marginal / R);
  EXPECT_NEAR(paraxial, -1.5 * R, 0.1 * R);  // the smoothed lens is still close to the sharp one
  EXPECT_LT(marginal, -R);                   // outside the sphere
  // Tolerance: one voxel either side (the maximum is a voxel, whose centre is within ½h of the
  // point, plus the point deposit's aliasing along the axis).
  EXPECT_GE(y_max, paraxial - h);
  EXPECT_LE(y_max, marginal + h);
}

TEST(CpuSimulator, LuneburgLensFocusesOnTheFarSurface) {
  // n(r) = sqrt(2 − (r/R)²): a plane wave focuses on the opposite surface, at distance R from the
  // centre. n is continuous at the surface (n = 1), so the pre-smoothing barely moves the focus.
  // The grid puts a voxel centre at y = −R.
  const double h = 1.0 / 30.0, R = 0.5;
  const Bounds b = box({-18.5 * h, -0.6 - 18.5 * h, -18.5 * h}, {18.5 * h, 0.6 - 0.5 * h, 18.5 * h});
  const Volume v = luneburgLens(54, b, R);
  ASSERT_EQ(v.grid.dims, glm::ivec3(37, 54, 37));
  CpuSimulator sim(v);
  for (Integrator integrator : {Integrator::Euler, Integrator::RK4}) {
    SimulationOptions o;
    o.integrator = integrator;
    const BakeResult r = sim.run(LightSpec{}, o);
    const int j = onAxisMaximum(r, v.grid, 0.0);
    const double y_max = v.grid.center(0, j, 0).y;
    std::printf("Luneburg (%s): on-axis maximum at %.4f, focus at %.4f: %.2f voxels off\n",
                integrator == Integrator::Euler ? "Euler" : "RK4", y_max, -R, (y_max + R) / h);
    EXPECT_NEAR(y_max, -R, 1.01 * h);
    EXPECT_LT(ledgerResidual(r.stats), 1e-6);
  }
}

// ---------------------------------------------------------------------------------------------
// Shadows and point lights

TEST(CpuSimulator, AbsorbingSphereCastsAnUmbra) {
  // n = 1 everywhere (no refraction), σa = 40 per unit inside r = 0.25: the centre ray keeps
  // e^−20 and the umbra (ρ < 0.6 r, path ≥ 1.6 r) at most e^−16.
  const Volume v = absorbingSphere(32, cube(0.5), 0.25, 40.0);
  CpuSimulator sim(v);
  const BakeResult r = sim.run(LightSpec{}, {});
  const GridSpec& g = v.grid;
  double umbra = 0.0, lit = 0.0;
  int n_umbra = 0, n_lit = 0;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::dvec3 c = g.center(i, j, k);
        if (c.y > -0.3) continue;  // below the sphere and its box-filtered edge
        const double rho = std::hypot(c.x, c.z);
        const double e = voxelValue(r.irradiance, g, i, j, k).x;
        if (rho < 0.6 * 0.25) {
          umbra += e;
          ++n_umbra;
        }
        if (rho > 1.5 * 0.25) {
          lit += e;
          ++n_lit;
        }
      }
  ASSERT_GT(n_umbra, 0);
  ASSERT_GT(n_lit, 0);
  const double fraction = (umbra / n_umbra) / (lit / n_lit);
  std::printf("umbra keeps %.3g of the unshadowed irradiance (mean lit E = %.4f)\n", fraction, lit / n_lit);
  EXPECT_LE(fraction, 0.01);
  EXPECT_NEAR(lit / n_lit, 1.0, 0.01);
  EXPECT_LT(ledgerResidual(r.stats), 1e-6);
}

TEST(CpuSimulator, PointLightFollowsTheInverseSquareLaw) {
  // In a homogeneous medium the accumulated (scalar) irradiance of a point light of intensity I is
  // I/r². The wavefront starts at ε = ½h from the light and is split as it grows.
  const GridSpec g = cubicGrid(32, 0.5);
  CpuSimulator sim(uniformVolume(g, 1.0, glm::dvec3(0.0, 0.0, 1.0)));
  LightSpec light;
  light.type = LightSpec::Type::Point;
  light.position = {0.01, -0.02, 0.015};
  light.power = {2.0, 2.0, 2.0};
  const BakeResult r = sim.run(light, {});
  double sum = 0.0, sum_absorbing = 0.0;
  int n = 0;
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 32; ++i) {
        const double d = glm::distance(g.center(i, j, k), light.position);
        if (d < 0.2 || d > 0.4) continue;
        const glm::dvec3 e = voxelValue(r.irradiance, g, i, j, k);
        sum += e.x * d * d / 2.0;
        sum_absorbing += e.z * d * d / (2.0 * std::exp(-1.0 * d));  // σa = 1 in blue
        ++n;
      }
  std::printf("point light: mean E·r²/I = %.4f (red), %.4f (blue, absorption divided out) over %d voxels\n", sum / n,
              sum_absorbing / n, n);
  EXPECT_NEAR(sum / n, 1.0, 0.02);
  EXPECT_NEAR(sum_absorbing / n, 1.0, 0.02);
  EXPECT_NEAR(r.stats.flux_in.x, 4.0 * kPi * 2.0, 1e-9);
  EXPECT_LT(ledgerResidual(r.stats), 1e-6);
}

TEST(CpuSimulator, ALightThatMissesGivesAnEmptyBakeWithAWarning) {
  // A point light so far away that this tiny volume falls between the centre rays of the finest
  // cube map (2048² cells a face).
  const GridSpec g = cubicGrid(6, 3e-4);
  CpuSimulator sim(uniformVolume(g, 1.5));
  LightSpec light;
  light.type = LightSpec::Type::Point;
  light.position = {100.0, 37.0, -55.0};
  const BakeResult r = sim.run(light, {});
  EXPECT_EQ(r.stats.initial_patches, 0u);
  EXPECT_EQ(r.stats.steps, 0);
  EXPECT_TRUE(lightMissedVolume(r.stats));
  EXPECT_EQ(r.irradiance.data, std::vector<float>(g.count() * 3, 0.0f));
  EXPECT_EQ(r.light_dir.data, std::vector<float>(g.count() * 3, 0.0f));
  const auto json = r.stats.toJson();
  ASSERT_EQ(json.at("warnings").size(), 1u);
  EXPECT_NE(json.at("warnings")[0].get<std::string>().find("misses"), std::string::npos);
  // And it still bakes into a volume.
  Volume v = uniformVolume(g, 1.5);
  applyBake(v, r, light);
  EXPECT_TRUE(v.has("irradiance"));
}

// ---------------------------------------------------------------------------------------------
// Determinism

// Relative L2 difference of the red irradiance of `a` against `reference`, summed over 2×2×2-voxel
// blocks: single voxels carry the point-deposit noise of any discretisation.
double blockRelativeL2(const BakeResult& a, const BakeResult& reference, const GridSpec& grid) {
  const glm::ivec3 d = grid.dims;
  double diff2 = 0.0, norm2 = 0.0;
  for (int z = 0; z + 1 < d.z; z += 2)
    for (int y = 0; y + 1 < d.y; y += 2)
      for (int x = 0; x + 1 < d.x; x += 2) {
        double ea = 0.0, er = 0.0;
        for (int k = 0; k < 8; ++k) {
          const std::size_t i = grid.index(x + (k & 1), y + ((k >> 1) & 1), z + (k >> 2));
          ea += a.irradiance.data[3 * i];
          er += reference.irradiance.data[3 * i];
        }
        diff2 += (ea - er) * (ea - er);
        norm2 += er * er;
      }
  return std::sqrt(diff2 / norm2);
}

TEST(CpuSimulator, AxisAndQuadSplitsBakeTheSameLight) {
  // The split rule changes how the wavefront is discretised, not the physics: the two rules bake
  // the same irradiance, to the discretisation noise, and Axis needs fewer patch-steps.
  const Volume v = glassSphere(24, cube(0.6), 0.5, 1.5);
  CpuSimulator sim(v);
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.2, -1.0, 0.1));
  SimulationOptions axis, quad;
  axis.split_rule = SplitRule::Axis;
  quad.split_rule = SplitRule::Quad;
  const BakeResult a = sim.run(light, axis), q = sim.run(light, quad);
  const double rel = blockRelativeL2(a, q, v.grid);
  std::printf("axis vs quad: block relative L2 %.3e; patch-steps %llu vs %llu, flux out %.5f vs %.5f, killed %.5f vs %.5f\n",
              rel, (unsigned long long)a.stats.total_patches, (unsigned long long)q.stats.total_patches,
              a.stats.flux_out.x, q.stats.flux_out.x, a.stats.flux_killed.x, q.stats.flux_killed.x);
  EXPECT_LT(rel, 0.03);
  EXPECT_NEAR(a.stats.flux_out.x, q.stats.flux_out.x, 0.005 * a.stats.flux_in.x);
  EXPECT_NEAR(a.stats.flux_reflected.x, q.stats.flux_reflected.x, 0.005 * a.stats.flux_in.x);
  EXPECT_LT(a.stats.total_patches, q.stats.total_patches);
  EXPECT_LT(ledgerResidual(a.stats), 1e-9);
}

TEST(CpuSimulator, KeepingPatchesAtTheDepthLimitConservesFluxAndStaysCloserToAFineBake) {
  // At max_depth a patch that should split is kept unsplit (default, while its edges stay within
  // kMaxUnsplitEdge split lengths) or killed (the thesis). On a glass sphere a shallow limit with
  // Keep loses far less flux and bakes closer to a deep reference than the same limit with Kill.
  const Volume v = glassSphere(24, cube(0.6), 0.5, 1.5);
  CpuSimulator sim(v);
  const LightSpec light;
  SimulationOptions keep, kill, fine;
  keep.max_depth = kill.max_depth = 3;
  kill.at_max_depth = DepthLimit::Kill;
  fine.max_depth = 8;
  const BakeResult k = sim.run(light, keep), x = sim.run(light, kill), f = sim.run(light, fine);
  const double keep_error = blockRelativeL2(k, f, v.grid), kill_error = blockRelativeL2(x, f, v.grid);
  std::printf("depth limit 3: keep %llu patch-steps, killed %.5f W, block L2 %.4f against depth 8 (%llu); "
              "kill %llu patch-steps, killed %.5f W, block L2 %.4f\n",
              (unsigned long long)k.stats.total_patches, k.stats.flux_killed.x, keep_error,
              (unsigned long long)f.stats.total_patches, (unsigned long long)x.stats.total_patches,
              x.stats.flux_killed.x, kill_error);
  EXPECT_LT(k.stats.flux_killed.x, x.stats.flux_killed.x / 3);
  EXPECT_GT(x.stats.flux_killed.x, 0.05 * x.stats.flux_in.x);
  EXPECT_LT(keep_error, kill_error);
  EXPECT_LT(k.stats.total_patches, f.stats.total_patches / 2);
  EXPECT_LT(ledgerResidual(k.stats), 1e-9);
}

TEST(CpuSimulator, SameBitsWhateverTheThreadCount) {
  const Volume v = glassSphere(20, cube(0.6), 0.5, 1.5);
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  light.power = {1.0, 0.7, 0.4};
  // Free flight on a sharp sphere (the smoothed one has ∇n ≠ 0 in every voxel: nowhere quiet),
  // then also with straight steps, merged near the surface (mergedStepsTime).
  const Volume sharp = sharpVolume("procedural:sphere,r=0.5,ior=1.5", 20, cube(0.6));
  for (const int mode : {0, 1, 2}) {
  const bool flight = mode > 0;
  auto bake = [&](int threads) {
    ScopedThreads scope(threads);
    CpuSimulator sim(flight ? sharp : v);
    SimulationOptions o;
    o.max_depth = 5;  // fewer patches, same machinery
    o.free_flight = flight;
    if (mode == 2) o.straight_step_voxels = 2.0;
    if (flight) {
      // A floor with its map beyond the sphere's shadow: footprints by bands of rows, and the
      // direct light in closed form (directMapLight), also by bands.
      ReceiverSpec floor;
      floor.point = {0.0, -0.7, 0.0};
      floor.half_extent = 1.5;
      o.receiver = floor;
    }
    return sim.run(light, o);
  };
  const BakeResult one = bake(1), two = bake(2), three = bake(3);
  EXPECT_EQ(one.stats.flights > 0, flight);
  EXPECT_EQ(one.stats.renderer, "cpu, 1 thread");
  EXPECT_EQ(two.stats.renderer, "cpu, 2 threads");
  for (const BakeResult* other : {&two, &three}) {
    ASSERT_EQ(one.irradiance.data.size(), other->irradiance.data.size());
    EXPECT_EQ(std::memcmp(one.irradiance.data.data(), other->irradiance.data.data(), one.irradiance.data.size() * 4), 0);
    EXPECT_EQ(std::memcmp(one.light_dir.data.data(), other->light_dir.data.data(), one.light_dir.data.size() * 4), 0);
    EXPECT_EQ(one.stats.flux_out, other->stats.flux_out);
    EXPECT_EQ(one.stats.flux_reflected, other->stats.flux_reflected);
    EXPECT_EQ(one.stats.total_patches, other->stats.total_patches);
    EXPECT_EQ(one.stats.splits, other->stats.splits);
    EXPECT_EQ(one.stats.flights, other->stats.flights);
    ASSERT_EQ(one.receivers.size(), other->receivers.size());
    if (!one.receivers.empty()) {
      EXPECT_EQ(one.receivers[0].irradiance, other->receivers[0].irradiance);
    }
    EXPECT_EQ(one.stats.flux_received, other->stats.flux_received);
  }
  EXPECT_EQ(one.receivers.size(), flight ? 1u : 0u);
  EXPECT_GT(one.stats.splits, 0u);
  }
}

// The merged straight steps change nothing but where a patch is looked at: with volume deposits
// too (retaken straight steps, track deposits along the merged chords), a merged bake's volume
// light is the single steps' to rounding and the light's ledger closes.
TEST(CpuSimulator, MergedStraightStepsKeepTheVolumeLight) {
  const Volume sharp = sharpVolume("procedural:sphere,r=0.5,ior=1.5", 24, cube(0.6));
  CpuSimulator sim(sharp);
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  SimulationOptions merged;
  merged.max_depth = 5;
  merged.free_flight = true;
  merged.straight_step_voxels = 2.0;
  SimulationOptions single = merged;
  single.merge_straight_steps = false;
  const BakeResult a = sim.run(light, merged), b = sim.run(light, single);
  EXPECT_LT(a.stats.total_patches, b.stats.total_patches);
  EXPECT_LT(ledgerResidual(a.stats), 1e-9);
  double diff = 0.0, norm = 0.0;
  for (std::size_t i = 0; i < a.irradiance.data.size(); ++i) {
    const double d = static_cast<double>(a.irradiance.data[i]) - b.irradiance.data[i];
    diff += d * d;
    norm += static_cast<double>(b.irradiance.data[i]) * b.irradiance.data[i];
  }
  // Relative L2 within 1 % (measured 2.9·10⁻³ at 24³, in 71.6 k against 125 k patch-steps: where
  // a patch tears at the surface moves as with a slightly other straight step, see
  // CpuSimulator.MergedStraightStepsBakeTheSameLightInFewerPatchSteps).
  std::printf("merged against single straight steps: volume light %.3g relative L2, %llu against %llu patch-steps\n",
              std::sqrt(diff / norm), static_cast<unsigned long long>(a.stats.total_patches),
              static_cast<unsigned long long>(b.stats.total_patches));
  EXPECT_LT(std::sqrt(diff / norm), 1e-2);
  EXPECT_NEAR(luminance(a.stats.flux_absorbed + a.stats.flux_out + a.stats.flux_reflected),
              luminance(b.stats.flux_absorbed + b.stats.flux_out + b.stats.flux_reflected), 2e-3 * luminance(b.stats.flux_in));
}

// The CPU twin given the `interfaces` field's data to take (what lightsim does with the volume it
// then drops) takes it, leaving the field empty, and bakes what the one that copied it bakes, to the
// bit: the map, the volume light, the patch-steps; in absorbing glass too, whose σa per material is
// found from the field's distances (before they are taken). A field the sampler does not keep as it
// is (four slots' distances, two of them used) is copied, and left as it was.
TEST(CpuSimulator, TakingTheDistancesBakesWhatCopyingThemBakes) {
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  SimulationOptions o;
  o.receiver = test_scenes::floorAt(-0.7, 1.5);
  o.volume_deposits = true;
  for (const char* spec : {"procedural:sphere,r=0.5,ior=1.5", "procedural:sphere,r=0.5,ior=1.5,sigma_a=1:2:0.5"}) {
    SCOPED_TRACE(spec);
    const Volume whole = sharpVolume(spec, 20, cube(0.6));
    Volume donor = whole;
    std::vector<float>& data = donor.fields.at("interfaces").data;
    ASSERT_EQ(donor.fields.at("interfaces").components, 1);
    const BakeResult a = CpuSimulator(whole).run(light, o);
    CpuSimulator taker(donor, &data);
    EXPECT_TRUE(data.empty()) << "taken, not copied";
    const BakeResult b = taker.run(light, o);
    ASSERT_EQ(a.receivers.size(), 1u);
    ASSERT_EQ(b.receivers.size(), 1u);
    EXPECT_EQ(a.receivers[0].irradiance, b.receivers[0].irradiance);
    EXPECT_EQ(a.irradiance.data, b.irradiance.data);
    EXPECT_EQ(a.stats.total_patches, b.stats.total_patches);
    EXPECT_EQ(luminance(a.stats.flux_absorbed), luminance(b.stats.flux_absorbed));
  }
  // Four distances a voxel (the older layout), one slot used: the sampler keeps one of them, so it
  // copies, and the field is left whole.
  Volume four = sharpVolume("procedural:sphere,r=0.5,ior=1.5", 16, cube(0.6));
  Field& distances = four.fields.at("interfaces");
  std::vector<float> wide(4 * distances.data.size(), static_cast<float>(interfaceTable(four).band));
  for (std::size_t i = 0; i < distances.data.size(); ++i) wide[4 * i] = distances.data[i];
  distances.data = wide;
  distances.components = 4;
  const CpuSimulator copier(four, &distances.data);
  EXPECT_EQ(distances.data, wide);
}

// In a volume whose sharp materials all have a constant n no sample reads the n and ∇n fields
// (lightsim leaves them unread: VolumeReadOptions): without them the bake is the same to the bit;
// with a graded material they are needed, and their absence is named.
TEST(CpuSimulator, SharpConstantNMaterialsBakeWithoutTheNFields) {
  const Volume whole = sharpVolume("procedural:sphere,r=0.5,ior=1.5", 20, cube(0.6));
  Volume lean = whole;
  lean.fields.erase("ior");
  lean.fields.erase("ior_grad");
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  SimulationOptions o;
  o.receiver = test_scenes::floorAt(-0.7, 1.5);
  o.volume_deposits = true;
  const BakeResult a = CpuSimulator(whole).run(light, o), b = CpuSimulator(lean).run(light, o);
  ASSERT_EQ(a.receivers.size(), 1u);
  ASSERT_EQ(b.receivers.size(), 1u);
  EXPECT_EQ(a.receivers[0].irradiance, b.receivers[0].irradiance);
  EXPECT_EQ(a.irradiance.data, b.irradiance.data);
  EXPECT_EQ(a.stats.total_patches, b.stats.total_patches);
  EXPECT_GT(a.stats.total_patches, 0u);
  Volume graded = lean;
  nlohmann::json table = graded.metadata.at("interfaces");
  table["slots"][0]["graded"] = true;
  graded.metadata["interfaces"] = table;
  try {
    CpuSimulator sim(graded);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ior"), std::string::npos) << e.what();
  }
}

// Light trapped by total internal reflection (more than 16 reflections of its corners in all) stops
// and is unfinished light, not killed light: a small patch in the middle of a glass block going
// down, given the reflections of a trapped one, and the same patch one reflection short of it.
// A square patch of half edge e at the centre of `sampler`'s volume, in the plane y = 0, going down.
Patch squarePatchGoingDown(const VolumeSampler& sampler, double e) {
  Patch patch;
  const glm::dvec3 corners[4] = {{-e, 0.0, -e}, {e, 0.0, -e}, {e, 0.0, e}, {-e, 0.0, e}};
  for (int c = 0; c < 4; ++c) {
    patch.x[c] = corners[c];
    patch.medium[c] = sampler.materialAt(patch.x[c]);
    patch.w[c] = sampler.materialOptics(patch.medium[c], patch.x[c]).x * glm::dvec3(0.0, -1.0, 0.0);
  }
  patch.flux = glm::dvec3(1e-3);
  patch.area0 = patch.area();
  return patch;
}

TEST(CpuSimulator, APatchPastSixteenTotalInternalReflectionsIsTrappedNotKilled) {
  const Volume v = sharpVolume("procedural:box,size=0.8:0.8:0.8,center=0:0:0,ior=1.5", 24, cube(0.5));
  const VolumeSampler sampler(v);
  SimulationOptions options;
  const StepContext ctx = makeStepContext(sampler, options, 1.0);
  for (const int reflections : {16, 17}) {
    Patch patch = squarePatchGoingDown(sampler, 0.01);
    ASSERT_GE(patch.medium[0], 0);  // inside the glass
    patch.reflections = reflections;
    PatchSamples samples = samplePatch(patch, sampler);
    const PatchStepResult r = stepPatch(patch, samples, ctx);
    if (reflections > 16) {
      EXPECT_EQ(r.fate, PatchFate::Trapped);
    } else {
      EXPECT_EQ(r.fate, PatchFate::Keep);
    }
  }
}

// A reflected wavefront (bounce ≥ 1) splits at kReflectedSplitFactor split lengths, the light that
// entered at one (wavefront.h): a patch in the middle of a glass block, going down, with edges of
// 2 and of 5 split lengths. (The GPU path's rule, fate.glsl, is checked by its patch-steps against
// the twin's in ExactOpticsSphere.TheGpuPathFliesAndTakesStraightStepsAsTheTwinDoes.)
TEST(CpuSimulator, AReflectedWavefrontSplitsAtFourSplitLengths) {
  const Volume v = sharpVolume("procedural:box,size=0.8:0.8:0.8,center=0:0:0,ior=1.5", 24, cube(0.5));
  const VolumeSampler sampler(v);
  SimulationOptions options;
  const StepContext ctx = makeStepContext(sampler, options, 1.0);
  const double split = splitThreshold(sampler.grid(), options);
  for (const double edges : {2.0, 5.0}) {
    for (const int bounce : {0, 1}) {
      Patch patch = squarePatchGoingDown(sampler, 0.5 * edges * split);
      ASSERT_EQ(patch.medium[0], 0);  // inside the glass
      patch.bounce = bounce;
      PatchSamples samples = samplePatch(patch, sampler);
      const PatchStepResult r = stepPatch(patch, samples, ctx);
      const bool splits = bounce == 0 || edges > kReflectedSplitFactor;
      EXPECT_EQ(r.fate, splits ? PatchFate::Split : PatchFate::Keep) << "edges " << edges << ", bounce " << bounce;
    }
  }
}

// ... and takes straight steps kReflectedStepFactor times as long (wavefront.h), which with volume
// deposits are not retaken at Δt where they meet an interface: a patch going down, free flight off
// so that its ordinary step is a straight one; a straight step of time t moves every corner t/n
// along its ray (|dx/dt| = 1/n). In the middle of the block the step is whole at any bounce; a
// voxel above its bottom face a straight step (4/3 voxel in the glass) meets the face, and with volume deposits the
// transmitted light's is retaken as a step of Δt, the reflected light's is not. The GPU path's
// steps (flight.glsl sharpStepTime, update.frag) are checked by its patch-steps against the twin's
// in ExactOpticsSphere.TheGpuPathFliesAndTakesStraightStepsAsTheTwinDoes.
TEST(CpuSimulator, AReflectedWavefrontTakesFourTimesLongerStraightSteps) {
  const Volume v = sharpVolume("procedural:box,size=0.8:0.8:0.8,center=0:0:0,ior=1.5", 24, cube(0.5));
  const VolumeSampler sampler(v);
  const double h = sampler.h();
  for (const bool volume_deposits : {false, true}) {
    SimulationOptions options;
    options.free_flight = false;
    options.straight_step_voxels = 2.0;  // the command's default
    options.volume_deposits = volume_deposits;
    const StepContext ctx = makeStepContext(sampler, options, 1.0);
    ASSERT_DOUBLE_EQ(ctx.step_dt, options.straight_step_voxels * h);
    ASSERT_DOUBLE_EQ(ctx.reflected_step_dt, kReflectedStepFactor * ctx.step_dt);
    for (const int bounce : {0, 1, 2}) {
      Patch patch = squarePatchGoingDown(sampler, 0.01);
      ASSERT_EQ(patch.medium[0], 0);  // inside the glass, 9.6 voxels from its faces
      patch.bounce = bounce;
      const glm::dvec3 before = patch.midpoint();
      PatchSamples samples = samplePatch(patch, sampler);
      const PatchStepResult r = stepPatch(patch, samples, ctx);
      EXPECT_FALSE(r.flight);
      const double factor = bounce > 0 ? kReflectedStepFactor : 1.0;
      // The step is straight and exact: only rounding separates the two.
      EXPECT_NEAR(before.y - patch.midpoint().y, factor * ctx.step_dt / 1.5, 1e-12)
          << "bounce " << bounce << ", volume deposits " << volume_deposits;
      EXPECT_NEAR(glm::length(glm::dvec2(patch.midpoint().x - before.x, patch.midpoint().z - before.z)), 0.0, 1e-12);
    }
    for (const int bounce : {0, 1}) {  // (without volume deposits the transmitted light's step tears here)
      Patch patch = squarePatchGoingDown(sampler, 0.01);
      for (glm::dvec3& x : patch.x) x.y += -0.4 + h - patch.midpoint().y;  // a voxel above the face
      for (int c = 0; c < 4; ++c) ASSERT_EQ(sampler.materialAt(patch.x[c]), 0);
      patch.bounce = bounce;
      const glm::dvec3 before = patch.midpoint();
      PatchSamples samples = samplePatch(patch, sampler);
      const PatchStepResult r = stepPatch(patch, samples, ctx);
      const double moved = before.y - patch.midpoint().y;
      if (bounce > 0) {
        EXPECT_GT(moved, h) << "volume deposits " << volume_deposits << ": through the face";
      } else if (volume_deposits) {
        EXPECT_FALSE(r.rolled_back);
        EXPECT_NEAR(moved, ctx.dt / 1.5, 1e-12) << "retaken as a step of Δt";
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Timings for the report (not a test): --gtest_also_run_disabled_tests
// --gtest_filter='*CpuBench*'. BENCH_RES (default 64) sets the sphere's resolution (voxels across
// the sphere, plus 3 of air a side, as `voxelize --res`), BENCH_REPEAT (default 3) the runs.

TEST(CpuBench, DISABLED_GlassSphere) {
  const int res = std::getenv("BENCH_RES") ? std::atoi(std::getenv("BENCH_RES")) : 64;
  const int repeat = std::getenv("BENCH_REPEAT") ? std::atoi(std::getenv("BENCH_REPEAT")) : 3;
  const Volume v = proceduralVolume("procedural:sphere,r=0.5,ior=1.5", res);
  CpuSimulator sim(v);
  for (const glm::dvec3 dir : {glm::dvec3(0, -1, 0), glm::dvec3(0.3, -1.0, 0.2)}) {
    LightSpec light;
    light.direction = glm::normalize(dir);
    std::vector<double> seconds;
    BakeResult r;
    for (int i = 0; i < repeat; ++i) {
      const Stopwatch watch;
      r = sim.run(light, {});
      seconds.push_back(watch.seconds());
    }
    std::sort(seconds.begin(), seconds.end());
    const double median = seconds[seconds.size() / 2];
    std::printf("sphere %dx%dx%d, light (%.2f, %.2f, %.2f), %s: median %.3f s of %d; %d steps, %llu patch-steps "
                "(%.2f M/s), peak %llu patches, %llu splits\n",
                v.grid.dims.x, v.grid.dims.y, v.grid.dims.z, light.direction.x, light.direction.y, light.direction.z,
                r.stats.renderer.c_str(), median, repeat, r.stats.steps, (unsigned long long)r.stats.total_patches,
                1e-6 * double(r.stats.total_patches) / median, (unsigned long long)r.stats.peak_patches,
                (unsigned long long)r.stats.splits);
    std::printf("  phases: %s\n", r.stats.toJson().at("phase_seconds").dump().c_str());
  }
}

// Merged straight steps (ALGORITHM.md "Free flight"): where the quiet map lets no flight start (here
// a map with no quiet brick at all), a patch takes at once the straight steps whose ends keep every
// corner in its own material, and stops at the end of the last of them, exactly where those steps
// one at a time would have put it; the next step is the one that meets the interface.
// The step contexts of the merged-steps tests: the command's straight steps of 2 voxels, merged
// or one at a time, and no quiet brick anywhere (no flight: merged straight steps only).
struct MergeContexts {
  QuietMap nowhere_quiet;
  SimulationOptions merged, single;
  StepContext merged_ctx, single_ctx;
  explicit MergeContexts(const VolumeSampler& sampler) {
    merged.free_flight = true;
    merged.volume_deposits = false;
    merged.straight_step_voxels = 2.0;
    single = merged;
    single.merge_straight_steps = false;
    merged_ctx = context(sampler, merged);
    single_ctx = context(sampler, single);
  }
  MergeContexts(const MergeContexts&) = delete;  // the contexts point at the members
  MergeContexts& operator=(const MergeContexts&) = delete;

 private:
  StepContext context(const VolumeSampler& sampler, const SimulationOptions& options) const {
    StepContext ctx = makeStepContext(sampler, options, 1.0);
    ctx.quiet = &nowhere_quiet;
    ctx.flight_cap = 10.0;
    return ctx;
  }
};

// One straight step at a time from `start` until a step `meets` (at most 20): the steps before it,
// the patch after them and after the step that met.
struct SteppedUntil {
  int clear_steps = 0;
  Patch before, after;
};
template <typename Meets>
SteppedUntil stepUntil(const Patch& start, const VolumeSampler& sampler, const StepContext& ctx, Meets&& meets) {
  SteppedUntil s;
  s.before = start;
  PatchSamples samples = samplePatch(start, sampler);
  for (;; ++s.clear_steps) {
    Patch next = s.before;
    PatchSamples next_samples = samples;
    const PatchStepResult r = stepPatch(next, next_samples, ctx);
    EXPECT_FALSE(r.flight);
    if (meets(r, next) || s.clear_steps >= 20) {
      s.after = next;
      return s;
    }
    s.before = next;
    samples = next_samples;
  }
}

TEST(CpuSimulator, StraightStepsMergeUpToTheOneThatMeetsAnInterface) {
  // A glass slab, top face at y = −0.15; the patch starts 0.6 above it (14 voxels: 7 straight steps).
  const Volume v = sharpVolume("procedural:box,size=0.8:0.3:0.8,center=0:-0.3:0,ior=1.5", 24, cube(0.5));
  const VolumeSampler sampler(v);
  const MergeContexts contexts(sampler);
  const StepContext &merged_ctx = contexts.merged_ctx, &single_ctx = contexts.single_ctx;
  auto above = [&] {
    Patch patch = squarePatchGoingDown(sampler, 0.01);
    for (glm::dvec3& x : patch.x) x.y += 0.45;
    for (int c = 0; c < 4; ++c) patch.medium[c] = sampler.materialAt(patch.x[c]);
    return patch;
  };
  // One straight step at a time, until one meets the slab.
  ASSERT_EQ(above().medium[0], -1);
  const SteppedUntil single_steps = stepUntil(above(), sampler, single_ctx, [](const PatchStepResult& r, const Patch& p) {
    return p.medium[0] != -1 || r.fate != PatchFate::Keep;
  });
  const Patch& stepped = single_steps.before;
  const int clear_steps = single_steps.clear_steps;
  ASSERT_LT(clear_steps, 20);
  ASSERT_GE(clear_steps, 5);  // 0.6 / (2 voxels) = 7.2 steps of air above the face
  // Merged: one patch-step to the same place (the sum of k steps against one of k times the time:
  // rounding alone), then the crossing.
  Patch patch = above();
  PatchSamples samples = samplePatch(patch, sampler);
  const PatchStepResult r = stepPatch(patch, samples, merged_ctx);
  EXPECT_TRUE(r.flight);
  EXPECT_EQ(r.fate, PatchFate::Keep);
  for (int c = 0; c < 4; ++c) {
    EXPECT_NEAR(glm::length(patch.x[c] - stepped.x[c]), 0.0, 1e-12) << c;
    EXPECT_EQ(patch.medium[c], -1);
  }
  const PatchStepResult crossing = stepPatch(patch, samples, merged_ctx);
  EXPECT_FALSE(crossing.flight);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(patch.medium[c], 0) << c;  // into the glass
  // Off, the same patch takes its one straight step.
  Patch one = above();
  PatchSamples one_samples = samplePatch(one, sampler);
  EXPECT_FALSE(stepPatch(one, one_samples, single_ctx).flight);
  EXPECT_NEAR(above().midpoint().y - one.midpoint().y, single_ctx.step_dt, 1e-12);
}

// A reflected wavefront's straight steps (8 voxels) are longer than this slab is thick (2.4 voxels):
// the step that passes through it ends in air as it began. Looked at in pieces, that step still
// meets both faces (a Fresnel loss at each), and merged steps stop before it as they stop before
// any step that meets an interface; asked at its end only, the merged flight went through the
// slab as if it were not there.
TEST(CpuSimulator, AReflectedWavefrontsMergedStepsStopAtAWallThinnerThanAStep) {
  const double top = -0.2, thickness = 0.05;
  const Volume v = sharpVolume("procedural:box,size=0.8:" + std::to_string(thickness) + ":0.8,center=0:" +
                                   std::to_string(top - 0.5 * thickness) + ":0,ior=1.5",
                               48, cube(0.5));
  const VolumeSampler sampler(v);
  const MergeContexts contexts(sampler);
  const StepContext &merged_ctx = contexts.merged_ctx, &single_ctx = contexts.single_ctx;
  const double step = merged_ctx.reflected_step_dt;  // its length in air
  ASSERT_GT(step, 3.0 * thickness);
  // Three steps of air above the slab, the fourth from 0.06 above its top to below its bottom.
  auto above = [&] {
    Patch patch = squarePatchGoingDown(sampler, 0.01);
    for (glm::dvec3& x : patch.x) x.y += top + 0.06 + 3.0 * step;
    for (int c = 0; c < 4; ++c) patch.medium[c] = sampler.materialAt(patch.x[c]);
    patch.bounce = 1;
    return patch;
  };
  ASSERT_LT(top + 0.06 - step, top - thickness);
  auto meets = [](const PatchStepResult& r, const Patch& p) { return r.reflected.x > 0.0 || p.medium[0] != -1; };
  // One straight step at a time: the fourth meets the slab, and leaves it on the far side.
  ASSERT_EQ(above().medium[0], -1);
  const SteppedUntil single_steps = stepUntil(above(), sampler, single_ctx, meets);
  const Patch& stepped = single_steps.before;
  const int clear_steps = single_steps.clear_steps;
  ASSERT_LT(clear_steps, 20);
  // Both faces at normal incidence: (1 − R)² with R = (0.5 / 2.5)².
  EXPECT_NEAR(single_steps.after.flux.x / stepped.flux.x, (1.0 - 0.04) * (1.0 - 0.04), 1e-9);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(single_steps.after.medium[c], -1) << c;
  EXPECT_EQ(clear_steps, 3);
  // Merged: one patch-step to where the three clear steps end, then the step that meets the slab.
  Patch patch = above();
  PatchSamples samples = samplePatch(patch, sampler);
  const PatchStepResult r = stepPatch(patch, samples, merged_ctx);
  EXPECT_TRUE(r.flight);
  EXPECT_FALSE(meets(r, patch));
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(glm::length(patch.x[c] - stepped.x[c]), 0.0, 1e-12) << c;
  const PatchStepResult crossing = stepPatch(patch, samples, merged_ctx);
  EXPECT_FALSE(crossing.flight);
  EXPECT_TRUE(meets(crossing, patch));
}

// A sharp volume's bake as lightsim takes it (its defaults, free flight, straight steps of two
// voxels, no volume deposits) onto a floor of half extent 2 at y = 0.
SimulationOptions floorBakeOptions(const Volume& volume) {
  SimulationOptions options;
  const VolumeDefaults defaults = volumeDefaults(true, volume.grid);
  options.max_depth = defaults.max_depth;
  options.patch_voxels = defaults.patch_voxels;
  options.split_voxels = defaults.split_voxels;
  options.free_flight = true;
  options.volume_deposits = false;
  options.straight_step_voxels = 2.0;
  ReceiverSpec floor;
  floor.half_extent = 2.0;
  options.receiver = floor;
  return options;
}

// The same over a whole bake: the sphere over a floor and the wine glass (thin walls, a stem) under
// an oblique sun, baked as lightsim bakes them, with straight steps merged and one at a time. A
// merged patch-step ends where the steps one at a time would have, unless those steps would have
// been broken by a free flight (which lasts any time, not a number of straight steps), after which
// they end elsewhere along the ray: where a later step crosses a surface, and so whether a patch
// tears there, moves as it does when the straight step itself is changed a little. So the merged
// bake is held to the single steps' bake as closely as that: the maps within 1.5 times the change
// a 1.5 % longer straight step makes (and within 0.5 % anyway), the patches' splits, tears and
// receptions within 3 %, the received and the reflected flux within 0.1 % of the light in, and far
// fewer patch-steps. The wine glass is baked without reflected wavefronts: their straight steps of
// eight voxels pass its walls or not by where they end (its reflections differ by 8 % between the
// bakes, and as much between the single steps of 2 and 2.03 voxels).
TEST(CpuSimulator, MergedStraightStepsBakeTheSameLightInFewerPatchSteps) {
  struct Case {
    const char* spec;
    glm::dvec3 sun;
    int bounces;
    double min_saving;  // patch-steps one at a time over merged, at least
  };
  const Case cases[] = {{"procedural:sphere,r=1,center=0:1.5:0,ior=1.5", {0.0, -1.0, 0.0}, 1, 1.6},
                        {"procedural:wine_glass,center=0:1.1:0", {0.35, -1.0, 0.2}, 0, 1.2}};
  auto relativeL2 = [](const BakeResult& a, const BakeResult& b) {
    const std::vector<float>& ea = a.receivers.at(0).irradiance;
    const std::vector<float>& eb = b.receivers.at(0).irradiance;
    EXPECT_EQ(ea.size(), eb.size());
    double diff = 0.0, norm = 0.0;
    for (std::size_t i = 0; i < ea.size() && i < eb.size(); ++i) {
      diff += (static_cast<double>(ea[i]) - eb[i]) * (static_cast<double>(ea[i]) - eb[i]);
      norm += static_cast<double>(eb[i]) * eb[i];
    }
    return std::sqrt(diff / norm);
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.spec);
    const Volume volume = sharpVolume(c.spec, 32, std::nullopt, 2.0);
    CpuSimulator sim(volume);
    LightSpec light;
    light.direction = glm::normalize(c.sun);
    SimulationOptions options = floorBakeOptions(volume);
    options.bounces = c.bounces;
    SimulationOptions single = options;
    single.merge_straight_steps = false;
    SimulationOptions longer = single;
    longer.straight_step_voxels = 2.03;
    const BakeResult merged = sim.run(light, options), one = sim.run(light, single), other = sim.run(light, longer);
    EXPECT_GT(static_cast<double>(one.stats.total_patches), c.min_saving * static_cast<double>(merged.stats.total_patches));
    EXPECT_LT(relativeL2(merged, one), std::max(5e-3, 1.5 * relativeL2(other, one)));
    auto near = [](std::uint64_t x, std::uint64_t y) {
      return std::abs(static_cast<double>(x) - static_cast<double>(y)) <= 0.03 * static_cast<double>(std::max(x, y)) + 4.0;
    };
    EXPECT_PRED2(near, merged.stats.splits, one.stats.splits);
    EXPECT_PRED2(near, merged.stats.rollbacks, one.stats.rollbacks);
    EXPECT_PRED2(near, merged.stats.kills.depth, one.stats.kills.depth);
    EXPECT_PRED2(near, merged.stats.kills.received, one.stats.kills.received);
    EXPECT_PRED2(near, merged.stats.reflections, one.stats.reflections);
    const double in = luminance(merged.stats.flux_in);
    EXPECT_NEAR(luminance(merged.stats.flux_received), luminance(one.stats.flux_received), 1e-3 * in);
    EXPECT_NEAR(luminance(merged.stats.flux_reflected), luminance(one.stats.flux_reflected), 1e-3 * in);
    EXPECT_LT(ledgerResidual(merged.stats), 1e-9);
  }
}

// The patch-steps by the reflections their light came through (SimulationStats::
// patch_steps_by_bounce, `lightsim --stats`): they add up to the patch-steps; with --bounces B
// there are B + 1 orders; and each order's count does not depend on how many orders after it are
// followed (a reflected wavefront is a patch of its own: the light it left goes on as it did), so
// a wrong index — a reflection counted with its parent, or at its parent's order — fails here.
TEST(CpuSimulator, PatchStepsAreCountedByTheReflectionsTheirLightCameThrough) {
  const Volume volume = sharpVolume("procedural:sphere,r=1,center=0:1.5:0,ior=1.5", 32, std::nullopt, 2.0);
  CpuSimulator sim(volume);
  LightSpec light;
  light.direction = glm::dvec3(0.0, -1.0, 0.0);
  SimulationOptions options = floorBakeOptions(volume);
  std::vector<std::vector<std::uint64_t>> counts;
  for (int bounces = 0; bounces <= 2; ++bounces) {
    SCOPED_TRACE(bounces);
    options.bounces = bounces;
    const BakeResult bake = sim.run(light, options);
    const std::vector<std::uint64_t>& by_bounce = bake.stats.patch_steps_by_bounce;
    ASSERT_EQ(by_bounce.size(), static_cast<std::size_t>(bounces + 1));
    std::uint64_t sum = 0;
    for (const std::uint64_t n : by_bounce) {
      EXPECT_GT(n, 0u);
      sum += n;
    }
    EXPECT_EQ(sum, bake.stats.total_patches);
    EXPECT_EQ(bake.stats.toJson().at("patch_steps_by_bounce").get<std::vector<std::uint64_t>>(), by_bounce);
    for (std::size_t b = 0; b < counts.size(); ++b) EXPECT_EQ(by_bounce[b], counts.back()[b]) << "order " << b;
    counts.push_back(by_bounce);
    // The received flux by order: it adds up to the received flux (to rounding: summed in another
    // order), and the light reflected once brings some to the floor (off the sphere below 45°).
    const std::vector<glm::dvec3>& received = bake.stats.flux_received_by_bounce;
    ASSERT_EQ(received.size(), by_bounce.size());
    glm::dvec3 total(0.0);
    for (const glm::dvec3& f : received) total += f;
    EXPECT_NEAR(total.x, bake.stats.flux_received.x, 1e-12 * bake.stats.flux_received.x);
    if (bounces >= 1) {
      EXPECT_GT(received[1].x, 1e-4 * received[0].x);
    }
    EXPECT_EQ(bake.stats.toJson().at("flux_received_by_bounce").size(), received.size());
  }
}

// A patch torn at the silhouette at the depth limit dies, but the light of its corners that pass
// the sphere by goes straight on to the floor (stepPatch's passingShare): the direct light at the
// very edge of the shadow. Baked with and without it (a scene's chain of boxes, `on_leave`, turns
// it off: there that light may meet another object), the difference is light moved from the
// killed flux to the received flux, to rounding; it is all on the map (no texel loses light), and
// all of it lies on the shadow's edge: within two texels and a patch of r = 1 around the sphere's
// axis. It is half of what the depth kills took (measured 50 % at 32³; the rest entered the glass
// at grazing incidence).
TEST(CpuSimulator, ATornPatchHandsTheLightThatPassesTheObjectToTheReceiver) {
  const Volume volume = sharpVolume("procedural:sphere,r=1,center=0:1.5:0,ior=1.5", 32, std::nullopt, 2.0);
  CpuSimulator sim(volume);
  LightSpec light;
  light.direction = glm::dvec3(0.0, -1.0, 0.0);
  const SimulationOptions options = floorBakeOptions(volume);
  SimulationOptions chained = options;
  chained.on_leave = [](const Patch&) {};
  EXPECT_TRUE(tornLightPassesToReceiver(sim.sampler(), options));
  EXPECT_FALSE(tornLightPassesToReceiver(sim.sampler(), chained));
  const BakeResult passed = sim.run(light, options), lost = sim.run(light, chained);
  const double in = luminance(passed.stats.flux_in);
  ASSERT_GT(passed.stats.kills.depth, 0u);
  EXPECT_EQ(passed.stats.kills.depth, lost.stats.kills.depth);  // the same patches die
  EXPECT_EQ(passed.stats.total_patches, lost.stats.total_patches);
  const double moved = luminance(passed.stats.flux_received) - luminance(lost.stats.flux_received);
  std::printf("torn at the depth limit: killed %.5f W, of which %.5f W now received\n",
              luminance(lost.stats.flux_killed), moved);
  EXPECT_GT(moved, 0.3 * luminance(lost.stats.flux_killed));
  EXPECT_NEAR(luminance(lost.stats.flux_killed) - luminance(passed.stats.flux_killed), moved, 1e-12 * in);
  EXPECT_LT(ledgerResidual(passed.stats), 1e-9);
  const ReceiverMap& a = passed.receivers.at(0);
  const ReceiverMap& b = lost.receivers.at(0);
  ASSERT_EQ(a.texels, b.texels);
  const double edge = 2.0 * a.pitch + options.split_voxels * voxelEdge(volume.grid);
  double on_map = 0.0, off_edge = 0.0;
  for (int j = 0; j < a.texels.y; ++j)
    for (int i = 0; i < a.texels.x; ++i) {
      const std::size_t t = static_cast<std::size_t>(j) * static_cast<std::size_t>(a.texels.x) + static_cast<std::size_t>(i);
      const double gained = (a.rgb(t).x - b.rgb(t).x) * a.pitch * a.pitch;  // W
      EXPECT_GE(gained, -1e-6 * a.rgb(t).x * a.pitch * a.pitch) << "texel " << i << ", " << j;
      const glm::dvec3 c = a.texelCenter(i, j);
      on_map += gained;
      if (std::abs(std::hypot(c.x, c.z) - 1.0) > edge) off_edge += std::abs(gained);
    }
  EXPECT_NEAR(on_map, moved, 1e-4 * moved);  // float texels
  EXPECT_LT(off_edge, 1e-4 * moved);
}
}  // namespace
}  // namespace eik
