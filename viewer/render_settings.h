// What the viewer's ray caster includes (thesis §5 image formation, §6.3 view renderer): each term
// of Eq. 5.10 can be switched off, for comparisons and for speed. A change that alters the shader
// variant (integrator, terms, debug output) recompiles it in SceneRenderer::setSettings.
#pragma once

#include <string>

namespace eik {

// How a viewing ray is advanced along the ray equation (Eq. 5.11/5.12, docs/physics.md).
enum class RayIntegrator {
  Euler,  // one ∇n fetch a step, |w| renormalised to n
  RK4,    // classical Runge–Kutta, four ∇n fetches a step
};

// "euler" | "rk4" (any case); InputError naming `source` otherwise.
RayIntegrator parseRayIntegrator(const std::string& text, const std::string& source = "--integrator");
const char* rayIntegratorName(RayIntegrator integrator);

// A debug picture instead of radiance (tests of the ray geometry).
enum class RenderOutput {
  Radiance,       // linear HDR radiance, RGB; alpha 1
  ExitPosition,   // world position where the (green) ray last left a volume; alpha 1 if it entered one
  ExitDirection,  // world direction of the (green) ray after the last volume (unit); alpha as above
};

struct RenderSettings {
  double step_voxels = 0.5;                      // arc length per ray step, in voxels of each object
  RayIntegrator integrator = RayIntegrator::Euler;
  bool refraction = true;    // curved rays (off: straight rays through the volumes)
  bool scattering = true;    // ω̂·L_s: HG in-scattering of the baked irradiance (Eq. 5.10)
  bool fresnel = true;       // δ·R·L_r at boundaries and the product of transmissions
  bool attenuation = true;   // Beer–Lambert, per channel
  bool emission = true;      // L_e
  bool dispersion = true;    // R, G, B follow their own rays where a `dispersion` field exists
  // Spectral bands of the dispersion (core/spectrum.h spectralBands, as `lightsim --bands`): 3 traces
  // R, G and B at 0.61, 0.55, 0.465 µm; 4 … 16 trace that many bands over 0.38 – 0.78 µm, each
  // weighted by its CIE share of R, G and B (where the draw target has a depth buffer; else 3).
  int bands = 3;
  // With 4 … 16 bands: trace the spectrum's two end bands and interpolate the others' rays between
  // them where the two took the same way (raymarch.frag spectralBand); off: trace every band.
  bool interpolate_bands = true;
  bool ground = true;        // the scene's ground plane, if it has one
  // One bounce through the scene: the first reflection off an object's outside is traced as a ray
  // of its own through the other objects and onto the ground (off: it sees the ground and the
  // environment only, as every other reflection does). Needs `fresnel`.
  bool reflect_objects = true;
  // March only the box of a volume's non-trivial region (straight elsewhere), and between sharp
  // surfaces of constant n step as far as the distance to the next surface allows (object.glsl
  // stepLength@).
  bool skip_empty_space = true;
  // Cross bricks of 4³ voxels where the medium is homogeneous (n, σa constant, nothing else) in one
  // step. Off by default: on llvmpipe the extra brick fetch a step cost more than it saved in the
  // scenes measured (64³ glass sphere 1.11× → 1.16× the bare march; 32³ absorbing one 2.2× → 2.8×).
  // The bricks are found when an object's textures are made (the SceneRenderer's constructor,
  // replaceVolume), only if this is on then; turned on later by setSettings, nothing is skipped.
  bool homogeneous_bricks = false;
  // A ray enters a boundary layer where |∇n|·h exceeds this (h: the voxel size) and leaves it where
  // |∇n|·h falls below a 16th of it; Fresnel is evaluated with n before and after the layer.
  double boundary_threshold = 0.02;
  // Rays stop once every channel's transmittance is below this (early termination).
  double min_transmittance = 1e-3;
  // Added to the environment map's mip level chosen from the ray footprint (refracted rays diverge).
  double environment_lod_bias = 0.0;
  RenderOutput output = RenderOutput::Radiance;
};

}  // namespace eik
