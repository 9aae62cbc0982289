// Choosing and making the light simulator (see make_simulator.h).
#include "lightsim/make_simulator.h"

#include <exception>

#include "gl/context.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/gpu_simulator.h"

namespace eik {

std::unique_ptr<Simulator> makeSimulator(const Volume& volume, const SimulatorBackendOptions& options) {
  SimulatorBackend backend = options.backend;
  // Auto: probe the OpenGL renderer; a hardware context stays alive for the GPU path.
  std::unique_ptr<gl::GlContext> probe;
  if (backend == SimulatorBackend::Auto) {
    backend = SimulatorBackend::Cpu;
    try {
      gl::ContextOptions context;
      context.backend = gl::parseGlBackend(options.gl);
      probe = std::make_unique<gl::GlContext>(context);
      if (!gl::isSoftwareRenderer(probe->info())) backend = SimulatorBackend::Gl;
      if (options.report)
        options.report(probe->info().renderer + ", so the " +
                       (backend == SimulatorBackend::Gl ? "GPU path" : "CPU twin (faster than a software rasterizer)"));
    } catch (const std::exception& e) {
      if (options.report) options.report(std::string("no OpenGL context (") + e.what() + "), so the CPU twin");
    }
    if (backend == SimulatorBackend::Cpu) probe.reset();
  }
  if (backend == SimulatorBackend::Cpu) return std::make_unique<CpuSimulator>(volume);
  GpuSimulatorOptions gpu;
  gpu.source = options.source;
  gpu.backend = gl::parseGlBackend(options.gl);
  return std::make_unique<GpuSimulator>(volume, gpu, std::move(probe));
}

}  // namespace eik
