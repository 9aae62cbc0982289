// Choosing and making the light simulator (see make_simulator.h).
#include "lightsim/make_simulator.h"

#include <exception>

#include "core/error.h"

#include "gl/context.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/gpu_simulator.h"

namespace eik {

std::string gpuPathLacks(const Volume& volume, const SimulationOptions& simulation) {
  (void)volume;
  const bool track = simulation.deposit == DepositMode::Accumulate && simulation.deposit_kernel == DepositKernel::Track;
  if (simulation.receiver && !track) return "receiver maps with point deposits (use --deposit-kernel track)";
  return "";
}

bool takesCpuTwinUnprobed(const SimulatorBackendOptions& options) {
  if (options.backend == SimulatorBackend::Cpu) return true;
  if (options.backend != SimulatorBackend::Auto) return false;
  try {
    if (gl::resolveGlBackend(gl::parseGlBackend(options.gl)) == gl::GlBackend::OSMesa) return true;
  } catch (const std::exception&) {
    return true;  // a bad --gl name: Auto takes the twin
  }
  return !gl::gpuDevicePresent();
}

std::unique_ptr<Simulator> makeSimulator(const Volume& volume, const SimulatorBackendOptions& options,
                                         const SimulationOptions* simulation) {
  SimulatorBackend backend = options.backend;
  const std::string lacks = simulation ? gpuPathLacks(volume, *simulation) : std::string();
  if (!lacks.empty()) {
    if (backend == SimulatorBackend::Gl)
      throw InputError("--backend", "gl", "the GPU path does not do " + lacks + " yet: use --backend cpu or auto");
    if (backend == SimulatorBackend::Auto) {
      if (options.report) options.report("the GPU path does not do " + lacks + " yet, so the CPU twin");
      return std::make_unique<CpuSimulator>(volume, options.cpu_takes_interfaces);
    }
  }
  // Auto: probe the OpenGL renderer; a hardware context stays alive for the GPU path.
  std::unique_ptr<gl::GlContext> probe;
  if (backend == SimulatorBackend::Auto) {
    backend = SimulatorBackend::Cpu;
    try {
      gl::ContextOptions context;
      context.backend = gl::parseGlBackend(options.gl);
      // Two cases need no probe (a driver loaded for nothing costs 0.05-0.1 s a command): OSMesa
      // renders in software only (llvmpipe, softpipe), and a machine without a GPU device has
      // no hardware OpenGL whatever the back end.
      if (gl::resolveGlBackend(context.backend) == gl::GlBackend::OSMesa) {
        if (options.report) options.report("OSMesa renders in software, so the CPU twin (faster than a software rasterizer)");
        return std::make_unique<CpuSimulator>(volume, options.cpu_takes_interfaces);
      }
      if (!gl::gpuDevicePresent()) {
        if (options.report)
          options.report("no GPU device (/dev/dri/renderD*, /dev/nvidia0), so the CPU twin");
        return std::make_unique<CpuSimulator>(volume, options.cpu_takes_interfaces);
      }
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
  if (backend == SimulatorBackend::Cpu) return std::make_unique<CpuSimulator>(volume, options.cpu_takes_interfaces);
  GpuSimulatorOptions gpu;
  gpu.source = options.source;
  gpu.backend = gl::parseGlBackend(options.gl);
  gpu.count_readback = options.count_readback;
  return std::make_unique<GpuSimulator>(volume, gpu, std::move(probe));
}

}  // namespace eik
