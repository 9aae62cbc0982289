// The independent oracle for the light's physics: a Monte Carlo geometric-optics tracer of exact
// analytic shapes with the exact unpolarised Fresnel equations (docs/testing.md). It shares no code
// with lightsim or viewer (only GLM for vector arithmetic), works in double precision on the true
// surfaces, and follows every reflection and refraction (Russian roulette on the Fresnel R), so it
// carries none of the discretisation the voxel programs have.
//
// A scene is a set of non-overlapping convex dielectric solids in air (spheres and convex
// polyhedra given as intersections of half-spaces: boxes, slabs, prisms), lit by a directional
// light, above an opaque receiver plane that absorbs whatever reaches it and tallies its planar
// irradiance (flux through the plane per area).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace eik::reference {

// The exact unpolarised Fresnel reflectance R = (Rs + Rp)/2 for light going from index n1 into n2
// at incidence cos θ1 = cos_i (> 0); 1 beyond the critical angle.
double fresnelReflectance(double n1, double n2, double cos_i);

struct Hit {
  double t = 0.0;          // ray parameter of the surface point
  glm::dvec3 normal{0.0};  // outward unit normal of the solid there
};

// A convex solid with refractive index n: a sphere, or the intersection of half-spaces
// {x : dot(normal_i, x) <= offset_i}.
struct Solid {
  double ior = 1.5;
  double sigma_a = 0.0;  // absorption coefficient inside (1/m, grey): flux × e^(−σa s) along a path s
  bool is_sphere = true;
  glm::dvec3 center{0.0};
  double radius = 1.0;
  std::vector<glm::dvec4> planes;  // (outward unit normal, offset)

  static Solid sphere(glm::dvec3 center, double radius, double ior);
  static Solid box(glm::dvec3 lo, glm::dvec3 hi, double ior);
  // A prism along +z from z0 to z1 over the triangle (a, b, c) in the xy plane.
  static Solid prism(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, double z0, double z1, double ior);
  static Solid halfSpaces(std::vector<glm::dvec4> planes, double ior);

  // The first crossing of the surface with t > t_min (entering from outside or leaving from
  // inside); false when there is none.
  bool intersect(glm::dvec3 origin, glm::dvec3 dir, double t_min, Hit& hit) const;
  bool contains(glm::dvec3 p) const;
};

// A directional light of irradiance `irradiance` (W/m² on a plane facing it) travelling along
// `direction`, filling a disc of radius `beam_radius` around the line through `beam_center`.
struct DirectionalBeam {
  glm::dvec3 direction{0.0, -1.0, 0.0};
  glm::dvec3 beam_center{0.0};
  double beam_radius = 1.0;
  double irradiance = 1.0;
};

// The receiver: the plane through `point` with unit `normal` facing the light. Radial rings of
// width `ring_width` around `center` (a point on the plane) out to `max_radius`, and a square map of
// `map_texels`² texels of edge `map_pitch` centred on `center` (spanned by `map_u`, `map_v`), both
// of planar irradiance.
struct Receiver {
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0, 1.0, 0.0};
  glm::dvec3 center{0.0};
  double ring_width = 0.05;
  double max_radius = 4.0;
  int map_texels = 0;
  double map_pitch = 0.0;
  glm::dvec3 map_u{1.0, 0.0, 0.0}, map_v{0.0, 0.0, 1.0};
  // The map's corner in (u, v) relative to `center` (a ReceiverMap's origin); by default the map is
  // centred on `center`.
  bool map_origin_given = false;
  glm::dvec2 map_origin{0.0};
};

// A grid of cells over [lo, hi] (dims cells an axis) on which the tracer tallies the fluence rate
// (W/m²), ∫ Φ(s) K(x(s)) ds over the paths, over a cell's volume, with one of two windows K:
//  - box (hat = false): the cell itself, exactly (the paths are cut at the cells' faces, the decay
//    integrated in closed form);
//  - hat (hat = true): the trilinear hat around the cell's centre, reaching the neighbours' centres
//    (the window of a voxel of a baked volume), by the midpoint rule on 8 samples a cell's edge
//    along each path (its error, where a sample straddles a kink of the hat, averages out over rays).
struct FluenceGrid {
  glm::dvec3 lo{0.0}, hi{0.0};
  glm::ivec3 dims{0};
  bool hat = false;
  bool solids_only = false;  // tally the paths inside the solids only (not in the air)
};

struct TraceOptions {
  FluenceGrid fluence;  // dims 0: no fluence tally
  std::uint64_t rays = 1'000'000;
  std::uint64_t seed = 1;
  int max_interactions = 64;  // a path still bouncing after this many surface hits is dropped
  int threads = 0;            // 0: hardware concurrency
};

struct ReceiverTally {
  double ring_width = 0.0;
  std::vector<double> ring_flux;  // W through ring i = [i·w, (i+1)·w)
  std::vector<double> map_flux;   // W through each texel of the map (row-major, u fastest)
  double map_pitch = 0.0;
  int map_texels = 0;
  double flux_emitted = 0.0;      // W leaving the light
  double flux_received = 0.0;     // W absorbed by the receiver plane (anywhere)
  double flux_escaped = 0.0;      // W that left towards infinity
  double flux_dropped = 0.0;      // W of paths cut at max_interactions
  double flux_absorbed = 0.0;     // W absorbed inside the solids (σa)
  std::vector<double> fluence;    // TraceOptions::fluence's cells (x fastest), W/m²
  std::uint64_t rays = 0;

  // Planar irradiance (W/m²) averaged over the annulus r0 ≤ r < r1 (multiples of ring_width).
  double ringIrradiance(double r0, double r1) const;
  // Flux (W) through the disc r < radius (a multiple of ring_width).
  double encircledFlux(double radius) const;
};

// Traces `options.rays` rays of the beam through the solids onto the receiver.
ReceiverTally trace(const std::vector<Solid>& solids, const DirectionalBeam& beam, const Receiver& receiver,
                    const TraceOptions& options);

}  // namespace eik::reference
