// The run's constants as uniforms of the step passes (see step_uniforms.h).
#include "lightsim/step_uniforms.h"

#include "lightsim/wavefront.h"

namespace eik::gpu {

StepUniforms StepUniforms::from(const GridSpec& grid, const SimulationOptions& options, double fluxRef) {
  StepUniforms step;
  step.dt = static_cast<float>(timeStep(grid, options));
  step.stepDt = step.dt;
  step.reflectedStepDt = step.dt;
  step.boundaryOn = static_cast<float>(options.boundary_on);
  step.boundaryOff = static_cast<float>(options.boundary_off);
  step.fluxKill = static_cast<float>(options.flux_threshold * fluxRef);
  step.splitLength = static_cast<float>(splitThreshold(grid, options));  // split_voxels·h·(1 + margin)
  step.maxDepth = static_cast<float>(options.max_depth);
  step.axisSplit = options.split_rule == SplitRule::Axis;
  step.killAtMaxDepth = options.at_max_depth == DepthLimit::Kill;
  glm::dvec3 lo, hi;
  propagationBox(grid, options, lo, hi);
  step.boxMin = glm::vec3(lo);
  step.boxMax = glm::vec3(hi);
  step.flightCap = static_cast<float>(glm::length(hi - lo));
  step.bounces = options.bounces;
  step.mergeSteps = options.merge_straight_steps;
  return step;
}

}  // namespace eik::gpu
