#include "lightsim/cpu_simulator.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <cmath>

#include "lightsim/test_scenes.h"

namespace eik {
namespace {

using namespace test_scenes;

TEST(Explore, SphereFlux) {
  const Volume vol = glassSphere(64, box({-0.8, -0.7, -0.8}, {0.8, 0.6, 0.8}));
  std::printf("dims %d %d %d\n", vol.grid.dims.x, vol.grid.dims.y, vol.grid.dims.z);
  CpuSimulator sim(vol);
  for (double step : {0.4}) {
    SimulationOptions o;
    o.step_voxels = step;
    LightSpec light;
    auto t = std::chrono::steady_clock::now();
    BakeResult r = sim.run(light, o);
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    std::printf("step %.2f: %.3f s  %s\n", step, secs, r.stats.toJson().dump().c_str());
    for (int j0 = 0; j0 < 52; j0+=2) {
      glm::dvec3 f = downwardFlux(r.irradiance, r.light_dir, vol.grid, j0, j0 + 2);
      std::printf(" layer %d: %.6f\n", j0, f.x);
    }
    glm::dvec3 f4 = downwardFlux(r.irradiance, r.light_dir, vol.grid, 0, 4);
    std::printf(" layers 0-4: %.6f ; in-refl %.6f\n", f4.x, r.stats.flux_in.x - r.stats.flux_reflected.x);
  }
}

TEST(Explore, KillMap) {
  const Volume vol = glassSphere(64, box({-0.8, -0.7, -0.8}, {0.8, 0.6, 0.8}));
  VolumeSampler sampler(vol);
  SimulationOptions o;
  LightSpec light;
  double flux_ref = 0;
  std::vector<Patch> patches = initialPatches(light, vol.grid, sampler, o, &flux_ref);
  StepContext ctx{&sampler, &o, timeStep(vol.grid, o), flux_ref, vol.grid.voxelVolume()};
  int printed = 0;
  std::map<std::string, double> killmap;
  for (int step = 0; step < 400 && !patches.empty(); ++step) {
    std::vector<Patch> next;
    for (Patch& p : patches) {
      Patch before = p;
      PatchStepResult r = stepPatch(p, ctx);
      glm::dvec3 m = p.midpoint();
      if (r.fate == PatchFate::Split && p.depth < o.max_depth) {
        auto ch = splitPatch(p, sampler);
        for (auto& c : ch) next.push_back(c);
      } else if (r.fate == PatchFate::Keep) next.push_back(p);
      if (r.reflected.x > 0) {
        char key[96];
        std::snprintf(key, sizeof key, "R nin=%.1f cos=%.2f", before.n_in, std::round(before.cos_in*20)/20);
        char key2[96];
        std::snprintf(key2, sizeof key2, "F nin=%.1f cos=%.2f", before.n_in, std::round(before.cos_in*20)/20);
        killmap[key2] += before.flux.x;
        killmap[key] += r.reflected.x;
        if (printed < 12 && before.n_in > 1.3 && r.reflected.x > 0.3 * before.flux.x) { ++printed; std::printf("R: m=(%.3f %.3f %.3f) n_in %.3f n_out %.3f cos_in %.3f d=(%.3f %.3f %.3f)\n", m.x,m.y,m.z, before.n_in, sampler.ior(m), before.cos_in, p.direction().x, p.direction().y, p.direction().z); }
      }
      if (false) {
        char key[64];
        std::snprintf(key, sizeof key, "%d y=%+.1f r=%.2f", int(r.fate), std::round(m.y*10)/10, std::round(glm::length(m)*20)/20);
        killmap[key] += p.flux.x;
        if (printed < 6 && r.fate == PatchFate::KilledDepth && step > 60) {
          ++printed;
          std::printf("step %d depth kill m=(%.3f %.3f %.3f) edge=%.4f area=%.3g n_in=%.3f\n", step, m.x, m.y, m.z, p.longestEdge(), p.area(), p.n_in);
          for (int c = 0; c < 4; ++c) std::printf("   x%d=(%.4f %.4f %.4f) w=(%.3f %.3f %.3f) | before x=(%.4f %.4f %.4f)\n", c, p.x[c].x, p.x[c].y, p.x[c].z, p.w[c].x, p.w[c].y, p.w[c].z, before.x[c].x, before.x[c].y, before.x[c].z);
        }
      }
    }
    patches.swap(next);
  }
  for (auto& [k, v] : killmap) if (v > 0.001) std::printf("%s: %.4f\n", k.c_str(), v);
}
TEST(Explore, DwellCheck) {
  const double ylo = -2.5;
  const Volume vol = glassSphere(75, box({-1.5, ylo, -1.5}, {1.5, 0.6, 1.5}));
  VolumeSampler sampler(vol);
  SimulationOptions o;
  o.step_voxels = 0.4;
  LightSpec light;
  double flux_ref = 0;
  std::vector<Patch> patches = initialPatches(light, vol.grid, sampler, o, &flux_ref);
  StepContext ctx{&sampler, &o, timeStep(vol.grid, o), flux_ref, vol.grid.voxelVolume()};
  const int L = vol.grid.dims.y;
  std::vector<double> dep(L), dep_cos(L), disp(L), disp_dir(L);
  const double h = sampler.h();
  for (int step = 0; step < 400 && !patches.empty(); ++step) {
    std::vector<Patch> next;
    for (Patch& p : patches) {
      Patch before = p;
      const double ds = ctx.dt / sampler.ior(before.midpoint());
      PatchStepResult r = stepPatch(p, ctx);
      glm::dvec3 m = p.midpoint();
      int j = int(std::floor((m.y - ylo) / h));
      if (j >= 0 && j < L) {
        dep[j] += p.flux.x * ds;
        dep_cos[j] += p.flux.x * ds * (-p.direction().y);
        disp[j] += p.flux.x * (before.midpoint().y - m.y);
        double cs = 0; for (int c = 0; c < 4; ++c) cs += (before.x[c].y - p.x[c].y) / 4; 
        disp_dir[j] += p.flux.x * cs;
      }
      if (r.fate == PatchFate::Split) { auto ch = splitPatch(p, sampler); for (auto& c : ch) next.push_back(c); }
      else if (r.fate == PatchFate::Keep) next.push_back(p);
    }
    patches.swap(next);
  }
  CpuSimulator sim(vol);
  BakeResult res = sim.run(light, o);
  std::printf("%s\n", res.stats.toJson().dump().c_str());
  for (int j = 0; j + 1 < L; j += 2)
    std::printf("layers %2d-%2d y=%+.3f: exact %.4f   field %.4f\n", j, j + 1, ylo + j * h,
                (dep_cos[j] + dep_cos[j + 1]) / (2 * h), downwardFlux(res.irradiance, res.light_dir, vol.grid, j, j+2).x);
}
TEST(Explore, Geom) {
  auto env = [](const char* k, double d) { const char* v = std::getenv(k); return v ? std::atof(v) : d; };
  const double W = env("W", 0.8), ylo = env("YLO", -0.7);
  const int res = int(env("RES", 40));
  const Volume vol = glassSphere(res, box({-W, ylo, -W}, {W, 0.6, W}));
  SimulationOptions o;
  o.step_voxels = env("STEP", 0.4);
  o.max_depth = int(env("DEPTH", 8));
  LightSpec light;
  CpuSimulator sim(vol);
  auto t = std::chrono::steady_clock::now();
  BakeResult r = sim.run(light, o);
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  const auto& s = r.stats;
  double expect = s.flux_in.x - s.flux_reflected.x - s.flux_killed.x;
  std::printf("dims %d %d %d  %.2f s  patches %llu peak %llu  in %.4f refl %.4f killed %.4f\n", vol.grid.dims.x, vol.grid.dims.y, vol.grid.dims.z, secs,
              (unsigned long long)s.total_patches, (unsigned long long)s.peak_patches, s.flux_in.x, s.flux_reflected.x, s.flux_killed.x);
  std::printf("outward (2 layers) %.4f  (4 layers) %.4f  flux_out %.4f\n", outwardFlux(r.irradiance, r.light_dir, vol.grid).x, outwardFlux(r.irradiance, r.light_dir, vol.grid, 4).x, s.flux_out.x);
  for (int j = 0; j < vol.grid.dims.y / 2; j += 2) {
    double f = downwardFlux(r.irradiance, r.light_dir, vol.grid, j, j + 2).x;
    std::printf(" y=%+.3f: %.4f  (%.2f %% vs in-refl-killed; sphere-relative %.2f %%)\n", vol.grid.center(0, j, 0).y, f, 100 * (f / expect - 1), 100 * (f - expect) / (M_PI * 0.25));
  }
}
TEST(Explore, Banding) {
  const GridSpec g = cubicGrid(32, 0.5);
  const Volume vol = uniformVolume(g, 1.0);
  CpuSimulator sim(vol);
  for (double step : {0.5, 0.4, 0.3}) {
    SimulationOptions o;
    o.step_voxels = step;
    LightSpec light;
    BakeResult r = sim.run(light, o);
    std::printf("step %.1f: ", step);
    for (int j = 31; j >= 20; --j) std::printf("%.3f ", voxelValue(r.irradiance, g, 16, j, 16).x);
    std::printf("\n");
  }
}
}  // namespace
}  // namespace eik
