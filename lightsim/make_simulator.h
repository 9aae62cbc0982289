// makeSimulator: the light simulator for a back end (`lightsim --backend gl|cpu|auto --gl ...`):
//   Gl    the GPU particle system (gpu_simulator.h) in a context of the `gl` back end (or the
//         current context, if one is);
//   Cpu   the CPU twin (cpu_simulator.h);
//   Auto  probes the OpenGL renderer: a hardware GPU gets the GPU path in the probed context; a
//         software rasteriser (gl::isSoftwareRenderer: llvmpipe & co., where the twin is faster)
//         or no OpenGL context at all gets the CPU twin. It takes the twin without loading a driver
//         when OSMesa is asked for (software only) or the machine has no GPU device
//         (gl::gpuDevicePresent). `report` is told the choice and why.
// The caller runs the result through the Simulator interface only (simulator.h).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/volume.h"
#include "lightsim/gpu_simulator.h"
#include "lightsim/simulator.h"

namespace eik {

enum class SimulatorBackend { Gl, Cpu, Auto };

struct SimulatorBackendOptions {
  SimulatorBackend backend = SimulatorBackend::Gl;
  // The OpenGL back end for Gl and the Auto probe, as `--gl` names it: "auto", "osmesa" or "egl"
  // (gl::parseGlBackend). Parsed only when OpenGL is used: a bad name is an InputError for Gl and,
  // for Auto, a reason to take the CPU twin.
  std::string gl = "auto";
  std::string source = "volume";  // the manifest, for error messages (GpuSimulatorOptions::source)
  // Gl: when the CPU reads each step's patch count (`--count-readback`; GpuSimulatorOptions).
  GpuSimulatorOptions::CountReadback count_readback = GpuSimulatorOptions::CountReadback::Auto;
  // Auto only: told which back end was chosen and why, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), so
  // the CPU twin (faster than a software rasterizer)" or "no OpenGL context (...), so the CPU twin".
  std::function<void(const std::string&)> report;
  // The CPU twin may take this data of the volume's `interfaces` field instead of copying it
  // (VolumeSampler): given by a caller that needs the field no more (`lightsim`, which writes it
  // back from its file); the GPU path leaves it.
  std::vector<float>* cpu_takes_interfaces = nullptr;
};

// Whether makeSimulator takes the CPU twin whatever the volume, known before any driver is loaded:
// `--backend cpu`, or auto with OSMesa asked for or no GPU device on the machine. (Auto may also
// take it after probing a software rasteriser; that is not known beforehand.)
bool takesCpuTwinUnprobed(const SimulatorBackendOptions& options);

// What the GPU path cannot do (ALGORITHM.md "Back ends"): a receiver map with point deposits.
// Returns "" when it can bake `volume` with `simulation`, else the reason.
std::string gpuPathLacks(const Volume& volume, const SimulationOptions& simulation);

// The simulator for `volume` (see GpuSimulator's and CpuSimulator's constructors for what they
// read and throw). With `simulation` given, Auto takes the CPU twin for a bake the GPU path cannot
// do yet (gpuPathLacks), and Gl refuses it with an InputError naming --backend.
std::unique_ptr<Simulator> makeSimulator(const Volume& volume, const SimulatorBackendOptions& options,
                                         const SimulationOptions* simulation = nullptr);

}  // namespace eik
