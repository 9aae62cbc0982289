// Tests of makeSimulator (make_simulator.h): each back end gives the simulator it names, the GPU
// path's extra figures come through the Simulator interface, `--backend auto` probes the renderer
// (OSMesa is a software rasteriser: the CPU twin) and falls back to the twin without OpenGL, and a
// GpuSimulator runs in (and owns) the context it is given, as it does after a hardware probe.
#include "lightsim/make_simulator.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/testing.h"
#include "gl/context.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/gpu_simulator.h"
#include "lightsim/test_scenes.h"

namespace eik {
namespace {

Volume smallSphere() { return test_scenes::gpuGlassSphere(12, ",sigma_a=0.5:1:2"); }

LightSpec obliqueLight() {
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  return light;
}

TEST(MakeSimulatorTest, CpuBackendIsTheTwin) {
  const Volume volume = smallSphere();
  SimulatorBackendOptions options;
  options.backend = SimulatorBackend::Cpu;
  const std::unique_ptr<Simulator> simulator = makeSimulator(volume, options);
  ASSERT_NE(dynamic_cast<CpuSimulator*>(simulator.get()), nullptr);
  const BakeResult r = simulator->run(obliqueLight(), test_scenes::gpuTestOptions());
  EXPECT_EQ(r.stats.backend, "cpu");
  EXPECT_EQ(r.irradiance.data, CpuSimulator(volume).run(obliqueLight(), test_scenes::gpuTestOptions()).irradiance.data);
  EXPECT_EQ(simulator->lastRunStats(), nlohmann::json::object());
}

TEST(MakeSimulatorTest, GlBackendIsTheGpuPathWithItsTextureFigures) {
  test_scenes::glContext();
  const Volume volume = smallSphere();
  SimulatorBackendOptions options;  // Gl
  const std::unique_ptr<Simulator> simulator = makeSimulator(volume, options);
  const auto* gpu = dynamic_cast<GpuSimulator*>(simulator.get());
  ASSERT_NE(gpu, nullptr);
  const BakeResult r = simulator->run(obliqueLight(), test_scenes::gpuTestOptions());
  EXPECT_EQ(r.stats.backend, "gl");
  const nlohmann::json extra = simulator->lastRunStats();
  ASSERT_TRUE(extra.contains("texture_bytes")) << extra.dump();
  const GpuRunInfo& info = gpu->lastRunInfo();
  EXPECT_EQ(extra["texture_bytes"]["volume"].get<std::size_t>(), info.volume_bytes);
  EXPECT_EQ(extra["texture_bytes"]["atlas"].get<std::size_t>(), info.atlas_bytes);
  EXPECT_EQ(extra["texture_bytes"]["patch_lists_peak"].get<std::size_t>(), info.patch_bytes_peak);
  EXPECT_EQ(extra["texture_bytes"]["total_peak"].get<std::size_t>(), info.texture_bytes_peak);
  EXPECT_EQ(info.texture_bytes_peak, info.volume_bytes + info.atlas_bytes + info.patch_bytes_peak);
  EXPECT_GT(info.volume_bytes, 0u);
}

TEST(MakeSimulatorTest, GlBackendWithAnUnknownOpenGlBackEndIsAnInputError) {
  const Volume volume = smallSphere();
  SimulatorBackendOptions options;
  options.gl = "nonsense";
  EXPECT_THROW(makeSimulator(volume, options), InputError);
  options.backend = SimulatorBackend::Cpu;  // never parsed for the twin
  EXPECT_NE(makeSimulator(volume, options).get(), nullptr);
}

// `--backend auto` with `--gl gl`: the simulator it makes and what it reports (one line each call).
std::unique_ptr<Simulator> autoChoice(const Volume& volume, const std::string& gl, std::vector<std::string>& reports) {
  SimulatorBackendOptions options;
  options.backend = SimulatorBackend::Auto;
  options.gl = gl;
  options.report = [&](const std::string& why) { reports.push_back(why); };
  return makeSimulator(volume, options);
}

TEST(MakeSimulatorTest, AutoTakesTheTwinOnASoftwareRasterizer) {
  std::vector<std::string> reports;
  // llvmpipe (or softpipe): always software
  const std::unique_ptr<Simulator> simulator = autoChoice(smallSphere(), "osmesa", reports);
  EXPECT_NE(dynamic_cast<CpuSimulator*>(simulator.get()), nullptr);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0], "OSMesa renders in software, so the CPU twin (faster than a software rasterizer)");
}

TEST(MakeSimulatorTest, AutoWithoutAGpuDeviceTakesTheTwinWithoutProbing) {
  // EGL may be hardware, so it is probed where a GPU device exists; where none does (this
  // project's CI machines), the twin is chosen without a context: had the probe run, the report
  // would name the renderer it found ("llvmpipe ..., so the CPU twin ...").
  if (gl::gpuDevicePresent()) GTEST_SKIP() << "this machine has a GPU device: the probe runs";
  std::vector<std::string> reports;
  const std::unique_ptr<Simulator> simulator = autoChoice(smallSphere(), "egl", reports);
  EXPECT_NE(dynamic_cast<CpuSimulator*>(simulator.get()), nullptr);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0], "no GPU device (/dev/dri/renderD*, /dev/nvidia0), so the CPU twin");
}

TEST(MakeSimulatorTest, AutoWithoutOpenGlTakesTheTwinAndSaysWhy) {
  const Volume volume = smallSphere();
  std::vector<std::string> reports;
  const std::unique_ptr<Simulator> simulator = autoChoice(volume, "nonsense", reports);
  EXPECT_NE(dynamic_cast<CpuSimulator*>(simulator.get()), nullptr);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].rfind("no OpenGL context (--gl: unknown OpenGL back end 'nonsense'", 0), 0u) << reports[0];
  EXPECT_CONTAINS(reports[0], "), so the CPU twin");
  SimulatorBackendOptions quiet;  // no report
  quiet.backend = SimulatorBackend::Auto;
  quiet.gl = "nonsense";
  EXPECT_NE(makeSimulator(volume, quiet).get(), nullptr);
}

TEST(MakeSimulatorTest, GpuSimulatorRunsInTheContextItIsGiven) {
  // As after a hardware probe: the simulator takes the context, makes it current and bakes in it;
  // the bake equals one in a context of its own making.
  test_scenes::glContext();  // another context is current
  const Volume volume = smallSphere();
  BakeResult given, own;
  {
    auto context = std::make_unique<gl::GlContext>(
        gl::ContextOptions{.backend = gl::glBackendFromEnvironment(gl::GlBackend::OSMesa)});
    const gl::GlContext* raw = context.get();
    test_scenes::glContext();
    GpuSimulator gpu(volume, GpuSimulatorOptions{}, std::move(context));
    EXPECT_EQ(gl::GlContext::current(), raw);
    test_scenes::glContext();  // run() makes its context current again
    given = gpu.run(obliqueLight(), test_scenes::gpuTestOptions());
    EXPECT_EQ(gl::GlContext::current(), raw);
  }
  EXPECT_EQ(gl::GlContext::current(), nullptr);  // it went with the simulator
  {
    GpuSimulatorOptions options;
    options.backend = gl::glBackendFromEnvironment(gl::GlBackend::OSMesa);
    GpuSimulator gpu(volume, options);  // none current: one of its own
    own = gpu.run(obliqueLight(), test_scenes::gpuTestOptions());
  }
  EXPECT_EQ(given.irradiance.data, own.irradiance.data);
  EXPECT_EQ(given.light_dir.data, own.light_dir.data);
  EXPECT_GT(given.stats.steps, 0);
  test_scenes::glContext();
}

}  // namespace
}  // namespace eik
