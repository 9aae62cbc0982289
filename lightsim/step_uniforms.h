// StepUniforms: the constants of a run as the step passes see them, in float: Δt and the boundary
// thresholds g_on, g_off of the update pass (shaders/lightsim/update.frag, ALGORITHM.md steps 1–3),
// and Δt, the kill threshold, the split length, the depth limit and the split rule of the analysis
// pass (shaders/lightsim/fate.glsl, ALGORITHM.md step 5).
#pragma once

#include <glm/vec3.hpp>

#include "core/grid.h"
#include "lightsim/simulator.h"

namespace eik::gpu {

struct StepUniforms {
  float dt = 0.0f;                              // Δt
  // An ordinary step's time with sharp interfaces: a straight step's (straight_step_voxels·h) where
  // they apply to the run (straightSteps, cpu_simulator.h), else Δt; and how far it reaches from
  // the corners (its time / min(1, min n)), the box the absorber map must find σa = 0 in.
  float stepDt = 0.0f, straightReach = 0.0f;
  // A reflected wavefront's ordinary step (StepContext::reflected_step_dt); Δt here too.
  float reflectedStepDt = 0.0f;
  // With volume deposits, a straight step in which a corner met an interface is retaken as a step
  // of Δt (StepContext::retake_at_interfaces, cpu_simulator.h).
  bool retakeAtInterfaces = false;
  float flightCap = 0.0f;                       // free flight: the propagation box's diagonal
  // Free flight with volume deposits: the track deposit pass's bound on a step's extent, in voxels
  // (TrackDepositUniforms::maxExtentVoxels); 0: none (no volume deposits).
  float flightExtentVoxels = 0.0f;
  bool mergeSteps = true;                       // SimulationOptions::merge_straight_steps
  float boundaryOn = 0.0f, boundaryOff = 0.0f;  // g_on, g_off
  float fluxKill = 0.0f;                        // flux_threshold · Φ_ref
  float splitLength = 0.0f;                     // split_voxels · h · (1 + margin)
  float maxDepth = 0.0f;                        // max_depth
  bool axisSplit = true;                        // SplitRule::Axis
  bool killAtMaxDepth = false;                  // DepthLimit::Kill
  glm::vec3 boxMin{0.0f}, boxMax{0.0f};         // the propagation box (wavefront.h propagationBox)
  int bounces = 0;                              // reflections followed (sharp interfaces)
  // The receiver plane (RECEIVER in the analysis pass), in the grid's frame.
  glm::vec3 receiverPoint{0.0f}, receiverNormal{0.0f, 1.0f, 0.0f};
  // A patch torn at the depth limit gives the receiver the light its corners carry past the object
  // (analysis.frag passingShare, the twin's); off in a scene's chain of boxes (on_leave).
  bool passToReceiver = false;

  // The uniforms of a run of `options` on `grid`, whose largest initial patch flux is Φ_ref =
  // fluxRef (initialPatches): Δt = timeStep, the split length splitThreshold, the box
  // propagationBox (wavefront.h), in the frame of `grid` (GpuSimulator passes the grid-local one).
  // stepDt is Δt here: the simulator sets a straight step's where its volume allows them.
  static StepUniforms from(const GridSpec& grid, const SimulationOptions& options, double fluxRef);
};

}  // namespace eik::gpu
