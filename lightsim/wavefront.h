// Wavefront patches: the state of the light simulator and the pieces of one step that both back
// ends share (lightsim/ALGORITHM.md; thesis §4.2.3, §6.2). The CPU twin (cpu_simulator.h) is built
// from these functions, and the GPU path (gpu_simulator.h) uses them for its initial patch list and
// as the reference its shaders must agree with:
//  - Patch and its derived quantities (ALGORITHM.md "Patch state");
//  - VolumeSampler: n, ∇n and σa sampled exactly like GL texture() ("Units and inputs");
//  - initialPatches: directional and point lights ("Initialisation", thesis §6.2.1);
//  - splitPatch: the 2×2 bilinear split ("One step", 6; Fig. 4.3);
//  - fresnelReflectance (the corrected thesis Eq. 3.6), ray–box tests and the run's constants.
//
// Everything here is double precision. The GPU stores the same quantities in float, so the two
// agree to float rounding, not bit for bit.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "core/interfaces.h"
#include "lightsim/quiet_map.h"
#include "core/volume.h"
#include "lightsim/simulator.h"

namespace eik {

// ---------------------------------------------------------------------------------------------
// Patch state (ALGORITHM.md "Patch state").

// lum(c) = (r + g + b)/3, the grey value used for the direction sum and the `max` deposit.
inline double luminance(const glm::dvec3& c) { return (c.x + c.y + c.z) / 3.0; }

// Four corner particles, counter-clockwise seen from the side the light comes from, so that the
// area vector N = ½ (x₂ − x₀) × (x₃ − x₁) points along the propagation.
struct Patch {
  std::array<glm::dvec3, 4> x{};  // corner positions
  std::array<glm::dvec3, 4> w{};  // corner directions, |w_c| = n(x_c) (Eq. 4.12/4.13)
  glm::dvec3 flux{0.0};           // Φ in W per channel; Φ = E·A (intensity law, Eq. 4.15/4.16)
  double area0 = 0.0;             // A₀, the area at creation (initialisation or split)
  double depth = 0.0;             // splits since initialisation: +1 per 2×2 split, +½ per 1×2 split
  double n_in = 0.0;              // n before the boundary layer the patch is in; 0: not in a layer
  double cos_in = 0.0;            // |cos θ| of incidence on entering that layer
  double t_fresnel = 1.0;         // 1 − R applied in the last step (1 when none)
  // Sharp interfaces (core/interfaces.h; ALGORITHM.md "Sharp interfaces"):
  std::array<int, 4> medium{-1, -1, -1, -1};  // the material slot each corner is in (−1: air)
  double reflect_pending = 0.0;   // fraction of the flux reflected at the crossing in progress
  int crossed = 0;                // corners (bits 0–3) that crossed since that crossing began
  // Corners (bits 0–3) totally reflected at the reflection in progress: a wavefront meets a surface
  // corner by corner, over several steps, so those already reflected are through it, not torn off.
  int reflected = 0;
  int bounce = 0;                 // reflections this wavefront has come through
  int reflections = 0;            // total internal reflections of its corners so far

  // m = ¼ Σ x_c
  glm::dvec3 midpoint() const { return 0.25 * (x[0] + x[1] + x[2] + x[3]); }
  // d = normalize(Σ w_c)
  glm::dvec3 direction() const { return glm::normalize(w[0] + w[1] + w[2] + w[3]); }
  // N = ½ (x₂ − x₀) × (x₃ − x₁); |N| is the area of the (possibly non-planar) quadrilateral.
  glm::dvec3 areaVector() const { return 0.5 * glm::cross(x[2] - x[0], x[3] - x[1]); }
  double area() const { return glm::length(areaVector()); }
  // Longest of the four sides x₀x₁, x₁x₂, x₂x₃, x₃x₀ (the split criterion, step 5).
  double longestEdge() const {
    double e = 0.0;
    for (int c = 0; c < 4; ++c) e = std::max(e, glm::length(x[(c + 1) % 4] - x[c]));
    return e;
  }
  // E = Φ / A (Eq. 4.16); 0 for a degenerate patch.
  glm::dvec3 irradiance() const {
    const double a = area();
    return a > 0.0 ? flux / a : glm::dvec3(0.0);
  }
};

// ---------------------------------------------------------------------------------------------
// Sampling the volume (ALGORITHM.md "Units and inputs").

// h: the smallest voxel edge.
double voxelEdge(const GridSpec& grid);

// The eight texels and weights of one lookup with GL_LINEAR filtering and GL_CLAMP_TO_EDGE: the
// texture coordinate uvw = (x − bounds_min)/extent, the continuous voxel coordinate
// c = uvw·dims − 0.5, clamped to [0, dims − 1] per axis (which is what clamp-to-edge does to the
// filter footprint), i₀ = floor(c), i₁ = min(i₀ + 1, dims − 1), f = c − i₀.
struct TrilinearTaps {
  std::array<std::size_t, 8> index{};  // voxel indices, corner k = (kx + 2·ky + 4·kz)
  std::array<double, 8> weight{};      // Π (kα ? f_α : 1 − f_α)
};
TrilinearTaps trilinearTaps(const GridSpec& grid, const glm::dvec3& world);

// Samples up to four components of `field` at a world point (missing components are 0).
glm::dvec4 sampleTrilinear(const Field& field, const GridSpec& grid, const glm::dvec3& world);

// n, ∇n and σa of a volume, sampled like the GPU's textures. Holds its own interleaved float copy
// of the fields (n and ∇n together, so one lookup serves both); thread-safe for reading.
class VolumeSampler {
 public:
  // Needs `ior` (1 component) and `ior_grad` (3) — unless every material is sharp with a constant n
  // (no graded slot), where no sample reads them; `sigma_a` (3) is optional (absent: σa = 0).
  // Throws InputError naming the field otherwise.
  explicit VolumeSampler(const Volume& volume);
  // The same, taking the data of the volume's `interfaces` field instead of copying it where the
  // sampler keeps it as it is (one used slot per component): `interfaces_data` must be that field's
  // data, which is left empty (a full-grid array less: 9 MB at 132³). Otherwise it is copied.
  VolumeSampler(const Volume& volume, std::vector<float>* interfaces_data);

  const GridSpec& grid() const { return grid_; }
  double h() const { return h_; }
  bool hasAbsorption() const { return !sigma_a_.empty(); }

  double ior(const glm::dvec3& world) const;
  // n and ∇n from one lookup: (n, ∂n/∂x, ∂n/∂y, ∂n/∂z). With sharp interfaces: those of the
  // material the point is in (materialOptics(materialAt(world), world)).
  glm::dvec4 iorAndGradient(const glm::dvec3& world) const;
  glm::dvec3 sigmaA(const glm::dvec3& world) const;
  // σa per material (sharp interfaces with absorption; docs/physics.md "Absorption at sharp
  // interfaces"): true when each transparent material has one σa — the slot table's `sigma_a`, or
  // else the field's at its deep voxels (core/interfaces.h deepMaterialValues; the field's ramp
  // across a surface is the voxelizer's coverage blend) — which agrees with the field at every deep
  // voxel, and σa = 0 at those in air — or the air's σa is one box of smoke (core/interfaces.h
  // airMediumBox: airBox()). Then σa at a point is its material's, and a ray's absorbing length
  // ends on the interface itself (and on the smoke's faces), not on the field's ramp (exact
  // Beer–Lambert).
  bool absorptionPerMaterial() const { return absorption_per_material_; }
  // σa of material `slot` (−1: air: 0, or the smoke's inside its box); meaningful when
  // absorptionPerMaterial().
  glm::dvec3 materialSigmaA(int slot) const {
    return slot >= 0 ? slot_sigma_a_[static_cast<std::size_t>(slot)] : air_ ? air_->sigma_a : glm::dvec3(0.0);
  }
  // The smoke in the air where absorptionPerMaterial() found one.
  const std::optional<AirMedium>& airBox() const { return air_; }
  // ∫σa ds along the straight piece a → b of `length` in material `slot` (absorptionPerMaterial):
  // σa·length, in air only the share of it inside the smoke's box.
  glm::dvec3 pieceOpticalDepth(int slot, const glm::dvec3& a, const glm::dvec3& b, double length) const {
    const glm::dvec3 tau = materialSigmaA(slot) * length;
    return slot < 0 && air_ ? tau * boxShare(a, b, air_->lo, air_->hi) : tau;
  }

  // Sharp interfaces (core/interfaces.h); an empty table and slot −1 everywhere without them.
  bool sharp() const { return !table_.empty(); }
  const InterfaceTable& interfaces() const { return table_; }
  int slotCount() const { return static_cast<int>(table_.slots.size()); }
  // The slot distances d_k at a point (trilinear, clamp-to-edge); unused slots read +band.
  glm::dvec4 distances(const glm::dvec3& world) const;
  // The material slot a point is in (−1: air): materialSlot(distances(world)), read from the
  // lookup's cell where all eight taps agree on it (one byte instead of the distances' eight taps).
  int materialAt(const glm::dvec3& world) const;
  // n and ∇n inside material `slot` at `world`: (n_k, 0) for a homogeneous slot, the ior and ior_grad
  // fields for a graded one, (1, 0) for air (−1). Without sharp interfaces: iorAndGradient.
  glm::dvec4 materialOptics(int slot, const glm::dvec3& world) const;
  bool opaque(int slot) const { return slot >= 0 && table_.slots[static_cast<std::size_t>(slot)].opaque; }
  // The outward unit normal of slot k's surface near `world`: ∇d_k by central differences of half a
  // voxel; (0, 0, 0) where the distance is flat (far outside the band).
  glm::dvec3 interfaceNormal(int slot, const glm::dvec3& world) const;
  // The bricks where a straight step is exact (quiet_map.h), built with the sampler.
  const QuietMap& quietMap() const { return quiet_; }
  // The voxels with σa ≠ 0 (any channel) as a QuietMap: its quiet boxes have no absorption.
  QuietMap absorberMap() const;
  // The smallest n of any material (sharp interfaces: every slot and air; else the ior field).
  double minIor() const { return min_ior_; }

 private:
  GridSpec grid_;
  double h_ = 0.0;
  glm::dvec3 tap_scale_{1.0};  // dims/extent: world to voxel coordinates (taps3)
  std::vector<glm::vec4> ior_grad_;  // (n, ∇n) per voxel; empty where no sample reads the fields
  std::vector<glm::vec3> sigma_a_;   // empty: no absorption
  bool absorption_per_material_ = false;
  std::array<glm::dvec3, kMaxInterfaceSlots> slot_sigma_a_{};
  std::optional<AirMedium> air_;
  void findMaterialAbsorption(const Volume& volume);
  InterfaceTable table_;
  std::vector<glm::vec4> distances_; // empty without sharp interfaces or with used_distances_
  // The used slots' distances alone, slotCount() floats a voxel (a quarter of distances_ for one
  // slot: the lookup every corner makes each step reads that much less memory), with the unused
  // slots' one value; empty where those vary (then distances_ is read).
  std::vector<float> used_distances_;
  float unused_distance_ = 0.0f;
  // Per lookup cell (indexed by its first tap, i₀ + dims.x·(j₀ + dims.y·k₀); its taps i₀ and
  // min(i₀ + 1, dims − 1) per axis): the material every point of it is in when each slot's
  // distance has one sign at all eight taps (then so has their trilinear blend), else kMixedCell.
  static constexpr std::int8_t kMixedCell = -2;
  std::vector<std::int8_t> cell_material_;
  QuietMap quiet_;
  double min_ior_ = 1.0;
};

// ---------------------------------------------------------------------------------------------
// Geometry.

// Inside the closed box [lo, hi].
bool insideBox(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi);
// Does the ray origin + t·dir, t ≥ 0, meet the closed box [lo, hi]? (Slab test; an origin inside
// counts as a hit; dir need not be unit.)
bool rayHitsBox(const glm::dvec3& origin, const glm::dvec3& dir, const glm::dvec3& lo, const glm::dvec3& hi);

// The bilinear patch through corners x₀ = (0,0), x₁ = (1,0), x₂ = (1,1), x₃ = (0,1) at (u, v).
inline glm::dvec3 bilinear(const std::array<glm::dvec3, 4>& c, double u, double v) {
  return ((1.0 - u) * (1.0 - v)) * c[0] + (u * (1.0 - v)) * c[1] + (u * v) * c[2] + ((1.0 - u) * v) * c[3];
}

// Parameter origin (u_j, v_j) of child j of a 2×2 split: (0,0), (½,0), (0,½), (½,½) (step 6; the
// histogram pyramid's child order 0: (0,0), 1: (1,0), 2: (0,1), 3: (1,1)).
constexpr std::array<std::array<double, 2>, 4> kSplitChildOrigin{{{0.0, 0.0}, {0.5, 0.0}, {0.0, 0.5}, {0.5, 0.5}}};

// Which parameter directions a split halves (ALGORITHM.md step 5). The u edges are x₀x₁ and x₃x₂,
// the v edges x₁x₂ and x₀x₃.
struct SplitAxes {
  bool u = false;
  bool v = false;
  bool any() const { return u || v; }
  int count() const { return (u ? 2 : 1) * (v ? 2 : 1); }  // children: 1 (no split), 2 or 4
};

// The split rule of step 5 for a patch and a threshold length:
//  - SplitRule::Quad (the thesis): both axes when the longest of the four sides exceeds it;
//  - SplitRule::Axis (default): each axis whose longer edge exceeds it, so a sliver stretched along
//    one direction is halved along that one only (1×2) instead of into four slivers.
SplitAxes splitAxes(const Patch& patch, double threshold, SplitRule rule);

// The split of ALGORITHM.md step 6 into axes.count() children: corners and w from the bilinear
// patch at (u, v) ∈ {0, 1/nu, 1} × {0, 1/nv, 1} (nu = 2 when axes.u, else 1; likewise nv), w
// renormalised to n at the new corner, Φ_child = Φ·A_child/Σ A_children (flux conserved), depth + 1
// for a 2×2 split and + ½ for a 1×2 one (so Φ ≈ Φ₀/4^depth either way), A₀ = A_child,
// n_in/cos_in/t_fresnel inherited. Child j covers parameter cell (j mod nu, j div nu).
// `corner_samples` (optional): receives iorAndGradient at each child's corners (child j, corner c),
// which the split samples anyway (the CPU twin reuses them in the next update).
// Returns the number of children written to `children`.
int splitPatch(const Patch& parent, const VolumeSampler& sampler, SplitAxes axes, std::array<Patch, 4>& children,
               std::array<std::array<glm::dvec4, 4>, 4>* corner_samples = nullptr);
// The 2×2 split.
std::array<Patch, 4> splitPatch(const Patch& parent, const VolumeSampler& sampler,
                                std::array<std::array<glm::dvec4, 4>, 4>* corner_samples = nullptr);

// w scaled to length n (the renormalisation after each update and split); w unchanged if 0.
inline glm::dvec3 renormalised(const glm::dvec3& w, double n) {
  const double len = glm::length(w);
  return len > 0.0 ? w * (n / len) : w;
}

// ---------------------------------------------------------------------------------------------
// Fresnel (the corrected thesis Eq. 3.6; docs/physics.md): unpolarised reflectance
// R = (Rs + Rp)/2 for light going from index n1 into n2 at incidence cos θᵢ (|cos_i| is used), 1
// beyond the critical angle.
double fresnelReflectance(double n1, double n2, double cos_i);

// The reflectance a patch gets on leaving a boundary layer (ALGORITHM.md step 3, with two
// decisions this file makes where ALGORITHM.md is silent or wrong; see the .cpp for the numbers):
//  1. |n_out − n_in| < index_tolerance (boundary_off): no interface was crossed — the patch skimmed
//     the layer or was turned back by the ray equation (total internal reflection) — so R = 0.
//     ALGORITHM.md says "R ≈ 0" here, but the exact formula gives R → 1 for grazing patches that
//     skim the tail of a layer (n 1.003 → 1.001 at cos θ = 0.05 is beyond the "critical angle").
//  2. Otherwise R is evaluated on the side of lower index: R(n_in → n_out, cos_in) when
//     n_in ≤ n_out, else R(n_out → n_in, cos_out) (reciprocity: the same R for Snell-paired
//     angles). A smoothed boundary is several voxels thick and curved, so the angle measured at the
//     layer's inner edge is not the sharp interface's: on a smoothed sphere n·r·sin θ is conserved
//     across the layer (Bouguer), and rays that leave the sphere perfectly well meet the inner edge
//     beyond the critical angle — evaluating R there returned R = 1 for them.
// cos_out = |d_new·∇n̂(m_new)| at the point where the patch left the layer; < 0 when ∇n = 0 there
// (then the n_in side is used).
double boundaryReflectance(double n_in, double cos_in, double n_out, double cos_out, double index_tolerance);

// ---------------------------------------------------------------------------------------------
// Initialisation (ALGORITHM.md "Initialisation", thesis §6.2.1).

// Right-handed orthonormal (u, v) ⟂ L with u × v = L (L unit): u = normalize(e × L) with e the
// axis of L's smallest |component| (first of x, y, z on ties), v = L × u.
void orthonormalBasis(const glm::dvec3& L, glm::dvec3& u, glm::dvec3& v);

// Exact solid angle of the cube-face cell [a0, a1] × [b0, b1] on the face at distance 1:
// Ω = F(a1,b1) − F(a0,b1) − F(a1,b0) + F(a0,b0), F(a, b) = atan2(ab, sqrt(a² + b² + 1)).
double cubeCellSolidAngle(double a0, double b0, double a1, double b1);

// Cube-map faces: face f has outward normal n_f and tangents (s_f, t_f) with s_f × t_f = n_f; the
// point (a, b) ∈ [−1, 1]² of the face is n_f + a·s_f + b·t_f. Order +X, −X, +Y, −Y, +Z, −Z.
struct CubeFace {
  glm::dvec3 normal, s, t;
};
const std::array<CubeFace, 6>& cubeFaces();

// Point light: initial wavefront radius r₀ = max(ε, dist(p, box) − h), ε = ½h (ε inside the box),
// and the cube-map resolution M = clamp(ceil(2·r₀/(patch_voxels·h)), 1, 2048): a cell's chord at
// r₀ is then at most patch_voxels·h (the largest cell, at a face centre, subtends atan(2/M) < 2/M).
double pointLightStartRadius(const glm::dvec3& position, const GridSpec& grid);
// The brightest irradiance the light itself (unfocused) puts anywhere in the grid, max channel:
// a directional light's own; a point light's intensity over its squared distance to the grid's
// box (0 when it is inside the box: no bound). The reference of track_deposit.h trackSpacing.
double brightestIrradiance(const LightSpec& light, const GridSpec& grid);
int pointLightCubeResolution(double start_radius, const GridSpec& grid, const SimulationOptions& options);
constexpr int kMaxCubeResolution = 2048;

// The initial patch list, in the order both back ends use:
//  - directional: the covering rectangle of the box's projection, on the plane through the box
//    corner first along L moved back by ½h, cut into Nu × Nv patches (edges ≤ patch_voxels·h),
//    row by row (iv outer, iu inner), keeping those whose midpoint ray hits the box. w = n·L,
//    Φ = E_L·A.
//  - point: the cube map face by face (+X … −Z), then rows (j outer, i inner), keeping the cells
//    whose centre ray from p hits the box; corners p + r₀·dir, w = n·dir, Φ = I·Ω_cell.
// A₀ = A, depth 0, n_in = 0. `flux_ref` (if not null) receives Φ_ref, the largest channel of the
// largest initial patch flux (0 when the list is empty). An empty list means the light misses the
// volume: a point light so far away that the box falls between the centre rays of the finest cube
// map (M = 2048). A directional light always meets the box. Zero power is allowed here (patches
// that carry nothing); parseLight rejects it. Throws InputError for an unusable light (zero or non-finite direction or position,
// negative or non-finite power) and for bad options (validateOptions).
// Throws InputError for an unusable light: zero or non-finite direction or position, negative or
// non-finite power.
void validateLight(const LightSpec& light);

// With a receiver map (receiver.h), the patches also cover the map wholly: those whose ray meets the
// map but not the box go straight to it. With `direct` as well, for a directional light with
// options.direct_receiver_light, those cells are left out of the list: their number and flux go to
// *direct, and directMapLight (receiver.h) puts their light on the map (for a point light, and
// otherwise, *direct stays empty and every cell is a patch). Φ_ref is over every cell either way.
struct DirectCells {
  std::uint64_t cells = 0;
  glm::dvec3 flux{0.0};  // W, RGB
};
std::vector<Patch> initialPatches(const LightSpec& light, const GridSpec& grid, const VolumeSampler& sampler,
                                  const SimulationOptions& options, double* flux_ref,
                                  const ReceiverMap* map = nullptr, DirectCells* direct = nullptr);

// Gives the initial patches to options.initial_patches, when set (a scene's light from object to
// object, simulator.h), and raises `flux_ref` to the largest flux of a patch it added.
void adjustInitialPatches(std::vector<Patch>& patches, const VolumeSampler& sampler, const SimulationOptions& options,
                          double& flux_ref);

// ---------------------------------------------------------------------------------------------
// Constants of a run.

// Throws InputError ("lightsim options: NAME: ...") for a value out of range: a non-positive or
// non-finite step, patch or split size; max_depth < 0 or > 16; a negative threshold or max_steps;
// negative boundary thresholds or boundary_off > boundary_on.
void validateOptions(const SimulationOptions& options);
// The box patches live in: the grid's, grown by one voxel with DepositKernel::Track, so that the
// hats of the outermost voxels (which reach half a voxel past the grid) get every path through them.
void propagationBox(const GridSpec& grid, const SimulationOptions& options, glm::dvec3& lo, glm::dvec3& hi);
// Δt = step_voxels·h.
double timeStep(const GridSpec& grid, const SimulationOptions& options);
// options.max_steps, or when 0: ceil(4 × grid diagonal / Δt).
int maxSteps(const GridSpec& grid, const SimulationOptions& options);
// The split threshold of step 5: a patch splits when its longest edge exceeds
// split_voxels·h·(1 + kSplitMargin). Initial patches are made with edges of exactly
// patch_voxels·h (= split_voxels·h by default), and without the margin rounding (double on the
// CPU, float on the GPU) splits an arbitrary subset of them at once; 10⁻⁴ is far above float
// rounding of an edge (≈ 10⁻⁷·extent/h relative) and far below anything physical.
constexpr double kSplitMargin = 1e-4;
inline double splitThreshold(const GridSpec& grid, const SimulationOptions& options) {
  return options.split_voxels * voxelEdge(grid) * (1.0 + kSplitMargin);
}
// Reflected wavefronts (bounce ≥ 1: the Fresnel-reflected share of a crossing, followed with
// SimulationOptions::bounces) split at this many split lengths. They carry the reflectance R of
// the light they left (4 % at normal incidence on glass), and a smooth wavefront's discretisation
// error grows as the patch edge squared, so at 4× the edge their share of the error, 16 R, stays
// under the transmitted light's for R < 6 %. Measured on the 128³ sphere over a floor: 18 % fewer
// patch-steps, 17 % faster, the receiver map within 2.3·10⁻⁴ relative L2 of the bake with one
// split length for all, every ring against exact optics the same to three digits; the wine glass
// 16 % faster, its map within 3.9·10⁻⁴. At the depth limit every patch is kept within
// kMaxUnsplitEdge of the run's split length (a reflected one is then killed as soon as it should
// split: kept larger, the reflected light trapped in thin glass lives on for dozens of steps).
constexpr double kReflectedSplitFactor = 4.0;
// ... and take straight steps (--straight-step, in materials of constant n) this many times as long,
// for the same reason: a straight step is exact for the rays, and what a longer one costs is the
// wavefront's resolution between splits, which matters in proportion to the flux. Measured with
// the default one bounce: the 128³ sphere over a floor 24 % fewer patch-steps and its rings against
// exact optics the same to three digits; the wine glass 33 % fewer patch-steps, 23 % faster, its
// map within 1.6·10⁻³ relative L2; the logo block, the layered cube and the museum's cube half the
// patch-steps, their fields within 2.4·10⁻³. With volume deposits a reflected wavefront's straight
// step is not retaken where it meets an interface (cpu_simulator.cpp stepPatch). BENCHMARKS.md,
// issue 13 nineteenth part.
constexpr double kReflectedStepFactor = 4.0;
// DepthLimit::Keep keeps a patch at max_depth unsplit only while its longest edge is at most this
// many split lengths; beyond it the patch is killed (its midpoint no longer says where its flux
// is, so its deposit would land far from the light it carries).
constexpr double kMaxUnsplitEdge = 4.0;
// The flux kill threshold of step 5: flux_threshold · Φ_ref / 4^depth.
inline double fluxKillThreshold(double flux_ref, const SimulationOptions& options, int depth) {
  return options.flux_threshold * flux_ref * std::ldexp(1.0, -2 * depth);
}

}  // namespace eik
