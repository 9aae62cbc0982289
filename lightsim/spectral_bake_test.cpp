// The spectral bake (spectral_bake.h): the volume each band sees, the bands' sum, and a dense-flint
// prism whose bands leave it at the angles Snell's law gives with the Cauchy n(λ) — the exact
// refraction at the prism's two plane faces, computed here, not traced through the voxels.
#include "lightsim/spectral_bake.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/interfaces.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/test_scenes.h"
#include "lightsim/wavefront.h"

namespace eik {
namespace {

using namespace test_scenes;

// n shifts by B·(1/λ² − 1/λ_d²) in the slot table and the field, ∇n by that term times ∇B.
TEST(SpectralBake, TheVolumeAtAWavelength) {
  Volume volume = sharpVolume("procedural:sphere,r=0.4,ior=1.6,abbe=25", 16);
  volume.addField("ior_grad", 3);  // left out by voxelize (constant n); ∇B still shifts a ∇n given
  ASSERT_TRUE(isDispersive(volume));
  const double b = interfaceTable(volume).slots.at(0).dispersion_b;
  EXPECT_NEAR(b, 0.523655 * 0.6 / 25.0, 1e-6);  // docs/volume-format.md: B = 0.523655 (n − 1)/V_d
  // A B that grows linearly along x (0.01 µm² per world unit) so that its central difference is exact.
  Field& field = volume.fields.at("dispersion");
  const GridSpec& g = volume.grid;
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x) field.data[g.index(x, y, z)] = static_cast<float>(0.01 * g.center(x, y, z).x + 0.02);
  const Volume blue = volumeAtWavelength(volume, 0.45);
  const double term = cauchyTerm(0.45);
  EXPECT_NEAR(interfaceTable(blue).slots.at(0).ior, 1.6 + b * term, 1e-6);  // the table holds floats
  const std::size_t i = g.index(3, 8, 8);
  EXPECT_NEAR(blue.fields.at("ior").data[i], volume.fields.at("ior").data[i] + field.data[i] * term, 1e-5);
  EXPECT_NEAR(blue.fields.at("ior_grad").data[3 * i], volume.fields.at("ior_grad").data[3 * i] + 0.01 * term, 1e-5);
  EXPECT_NEAR(blue.fields.at("ior_grad").data[3 * i + 1], volume.fields.at("ior_grad").data[3 * i + 1], 1e-6);
  // At λ_d, and for a volume without dispersion, nothing changes.
  EXPECT_EQ(volumeAtWavelength(volume, kLambdaD).fields.at("ior").data, volume.fields.at("ior").data);
  const Volume plain = sharpVolume("procedural:sphere,r=0.4,ior=1.6", 16);
  EXPECT_FALSE(isDispersive(plain));
  EXPECT_EQ(volumeAtWavelength(plain, 0.45).metadata, plain.metadata);
}

// Two bands add up: irradiance and maps summed, light_dir the irradiance-weighted mean direction,
// fluxes summed, steps the longest band's.
TEST(SpectralBake, BandsAddUp) {
  auto band = [](float e, glm::vec3 d, double flux, int steps) {
    BakeResult r;
    r.irradiance.components = r.light_dir.components = 3;
    r.irradiance.data = {e, e, e};
    r.light_dir.data = {d.x, d.y, d.z};
    ReceiverMap map;
    map.texels = {1, 1};
    map.irradiance = {e, 2 * e, 3 * e};
    r.receivers.push_back(map);
    r.stats.flux_in = glm::dvec3(flux);
    r.stats.steps = steps;
    return r;
  };
  BandSum sum;
  sum.add(band(1.0f, {1, 0, 0}, 2.0, 10));
  sum.add(band(3.0f, {0, 1, 0}, 5.0, 7));
  const BakeResult r = sum.finish();
  EXPECT_EQ(r.irradiance.data, (std::vector<float>{4, 4, 4}));
  EXPECT_EQ(r.receivers.at(0).irradiance, (std::vector<float>{4, 8, 12}));
  EXPECT_NEAR(r.light_dir.data[0], 1.0 / std::sqrt(10.0), 1e-6);  // (1, 3, 0)/√10
  EXPECT_NEAR(r.light_dir.data[1], 3.0 / std::sqrt(10.0), 1e-6);
  EXPECT_EQ(r.stats.flux_in, glm::dvec3(7.0));
  EXPECT_EQ(r.stats.steps, 10);
}

// Snell's law in vector form: d refracted at a surface with unit normal `n` facing the incident
// side, from index n1 into n2 (false at total reflection).
bool refract(const glm::dvec3& d, const glm::dvec3& n, double n1, double n2, glm::dvec3& out) {
  const double eta = n1 / n2, cos_i = -glm::dot(d, n);
  const double k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
  if (k < 0.0) return false;
  out = glm::normalize(eta * d + (eta * cos_i - std::sqrt(k)) * n);
  return true;
}

// A dense-flint prism (n_d = 1.75, Abbe 20: B = 0.0196 µm²) of side 0.5 (voxelize's `prism`, its
// axis along y, a corner towards −z: faces AC and AB meet there with outward normals
// (∓cos 30°, 0, −sin 30°)) in a sun that meets face AC at the minimum-deviation angle for n_d
// (inside, the ray runs parallel to the base). Each band's light leaves through face AB; its mean
// direction (flux-weighted over the patches that leave within 3° of the exact direction) against
// the exact refraction at the two faces with that band's n(λ). The faces are planes, so the bake's
// error is the voxelised normals' (sharp interfaces: a fraction of a degree) and the patches' own
// spread. Returns the worst band's deviation from the exact angle (degrees); each band within `bound`.
double expectPrismBendsEachBandAsSnellsLaw(int res, double bound) {
  const Volume volume = sharpVolume("procedural:prism,side=0.5,height=0.4,ior=1.75,abbe=20", res);
  const double b = interfaceTable(volume).slots.at(0).dispersion_b;
  const glm::dvec3 n_ac(-std::cos(M_PI / 6), 0.0, -0.5), n_ab(std::cos(M_PI / 6), 0.0, -0.5);
  // Minimum deviation for n_d: the incident ray makes θ₁ = asin(n_d sin 30°) with the inward normal of AC.
  const double theta1 = std::asin(1.75 * 0.5);
  const double a = M_PI / 6 - theta1;  // the incident direction's angle in the x–z plane (from +x towards +z)
  const glm::dvec3 sun(std::cos(a), 0.0, std::sin(a));
  LightSpec light;
  light.direction = sun;
  SimulationOptions options;
  options.volume_deposits = false;
  options.free_flight = true;
  options.straight_step_voxels = 2.0;
  options.bounces = 0;
  const std::vector<SpectralBand> bands = spectralBands(7);
  double previous = 0.0, worst = 0.0;
  for (const SpectralBand& band : bands) {
    const double n = 1.75 + b * cauchyTerm(band.lambda_um);
    glm::dvec3 inside, out;
    if (!refract(sun, n_ac, 1.0, n, inside) || !refract(inside, -n_ab, n, 1.0, out)) {
      ADD_FAILURE() << "no exact path through the prism at " << band.lambda_um;
      return 180.0;
    }
    const double exact = glm::degrees(std::acos(glm::dot(sun, out)));
    glm::dvec3 sum(0.0);
    double flux = 0.0;
    options.on_leave = [&](const Patch& p) {
      const glm::dvec3 d = p.direction();
      if (glm::degrees(std::acos(std::min(1.0, glm::dot(d, out)))) > 3.0) return;
      sum += luminance(p.flux) * d;
      flux += luminance(p.flux);
    };
    CpuSimulator sim(volumeAtWavelength(volume, band.lambda_um));
    const BakeResult r = sim.run(light, options);
    if (!(flux > 0.0)) {
      ADD_FAILURE() << "no light left the prism near the exact direction at " << band.lambda_um;
      return 180.0;
    }
    const double baked = glm::degrees(std::acos(glm::dot(sun, glm::normalize(sum))));
    std::printf("%d³, %.4f um: n %.4f, deviation %.3f deg (exact %.3f), %.4f W\n", res, band.lambda_um, n, baked, exact,
                flux);
    EXPECT_NEAR(baked, exact, bound) << res << "³, " << band.lambda_um << " um";
    worst = std::max(worst, std::abs(baked - exact));
    // The bands run from violet to red, and red is bent least: the deviation falls band by band.
    if (&band != &bands.front()) {
      EXPECT_LT(baked, previous - 0.2);
    }
    previous = baked;
    // The band's ledger closes.
    EXPECT_LT(r.stats.ledgerResidual(), 1e-9);
  }
  return worst;
}

// At two resolutions: the 0.1° at 32³ (measured worst 0.025°), and converging from 24³
// (measured worst 0.13°, the blue band, where the prism's faces are 10 voxels wide and their
// voxelised normals tilt most; bound 0.2° there).
TEST(SpectralBake, APrismBendsEachBandAsSnellsLawWithCauchy) {
  const double coarse = expectPrismBendsEachBandAsSnellsLaw(24, 0.2);
  const double fine = expectPrismBendsEachBandAsSnellsLaw(32, 0.1);
  EXPECT_LT(fine, coarse);
}

}  // namespace
}  // namespace eik
