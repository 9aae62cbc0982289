// Sharp material interfaces (docs/volume-format.md "interfaces", docs/physics.md "Sharp
// interfaces"): what `voxelize --interfaces sharp` records and what lightsim and the viewer read.
//
// A volume with sharp interfaces carries the field `interfaces`: per voxel, for each of up to four
// *slots*, the signed distance (world units, negative inside) from the voxel centre to the surface
// of that slot's solid, clamped to ±band. A slot is one optical material: the union of the objects
// that share it (same n, same dispersion; every opaque object shares one slot; a graded-index
// object is a slot of its own). The manifest lists the slots, innermost first:
//
//   "interfaces": {"band": 0.05, "slots": [
//       {"name": "wine", "ior": 1.34, "dispersion_b": 0, "graded": false, "opaque": false,
//        "sigma_a": [0.5, 8, 6]}, ...]}
//
// The material at a point x is the first slot k whose trilinearly interpolated distance d_k(x) is
// negative (innermost wins, as in compositing), and air (n = 1) where none is. Inside a
// homogeneous slot n is its constant `ior` and ∇n = 0; inside a graded slot n and ∇n come from the
// `ior` and `ior_grad` fields. Where a ray or a wavefront corner passes from one material to
// another between two steps, the crossing is found on the zero set of the slot's distance, with
// the normal ∇d_k, and Snell's law and the exact Fresnel equations apply there
// (the discrete refraction of Ropinski et al. 2009, joined with the thesis' ray equation).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/grid.h"
#include "core/volume.h"

namespace eik {

constexpr int kMaxInterfaceSlots = 4;
// The distance field's band: distances beyond ±band (in voxels) are clamped.
constexpr double kInterfaceBandVoxels = 4.0;

struct InterfaceSlot {
  std::string name;
  double ior = 1.5;           // n of a homogeneous slot (at λ_d)
  double dispersion_b = 0.0;  // Cauchy B, µm²
  bool graded = false;        // n varies inside: taken from the ior / ior_grad fields
  bool opaque = false;        // stops light; shaded with the `opaque` field
  // σa of every object in the slot (per world unit, RGB) when they share one; absent when they
  // differ or the volume predates it (then the `sigma_a` field alone describes absorption).
  std::optional<glm::dvec3> sigma_a;
};

struct InterfaceTable {
  std::vector<InterfaceSlot> slots;  // innermost first; at most kMaxInterfaceSlots
  double band = 0.0;                 // world units

  bool empty() const { return slots.empty(); }
  nlohmann::json toJson() const;
};

// The table of a volume with an `interfaces` field (nullopt-like empty table without one).
// InputError naming `source` and the key for a malformed table, a field with the wrong component
// count, or a field without a table (and the reverse).
InterfaceTable interfaceTable(const Volume& volume, const std::string& source = "volume");

// Each material's value of a per-voxel `field` (up to 3 components) where it is one constant
// throughout the material, read from the voxels at least `depth` (world units) from every slot
// surface, where the voxelizer blends nothing in (voxelize/composite.h mixes regions by coverage
// only within a voxel of their surfaces). Index 0 is air, 1 + k slot k; opaque slots are not
// looked at (no ray goes on in them). `one_value` is false when a material's deep voxels disagree
// (beyond a relative 1e-6: two objects of one n and different σa share a slot; smoke in the air);
// a material with no deep voxel (a wall thinner than two voxels) is not `seen`. Without `with_air`
// the air is not looked at either (its field may vary: smoke in a box, viewer/volume_analysis.h).
struct MaterialValues {
  bool one_value = true;
  std::vector<bool> seen;          // [0] air, [1 + k] slot k
  std::vector<glm::dvec3> value;   // where seen (unused components 0)
};
MaterialValues deepMaterialValues(const Volume& volume, const InterfaceTable& table, const Field& field, double depth,
                                  bool with_air = true);
// Air whose σa and scattering are one constant inside a box and 0 outside it: smoke around the
// objects (n = 1, so no slot of its own; the amber bunny's). The deep air voxels (as above) inside
// the box of those that are not 0 all hold one value; those in its faces' layer a share f of it
// (the part of the voxel the smoke covers: voxelize blends by coverage; an axis-aligned box's edges
// the product of two faces' shares) with the same g; each face lies where its voxels' share puts
// it, 1 − f of a voxel in from the layer's outer side. Then a straight path in air from a to b is
// in the smoke for boxShare(a, b, lo, hi) of its length: the viewer's march (viewer/volume_analysis.h
// slotMedia) and the bake (lightsim VolumeSampler::absorptionPerMaterial) take the smoke's
// constants over that share, and the smoke ends at its faces as a material ends at its surface.
struct AirMedium {
  glm::dvec3 lo{0.0}, hi{0.0};  // the smoke's faces, volume coordinates
  glm::dvec3 sigma_a{0.0};
  glm::dvec2 scatter{0.0};      // albedo ω̂, Henyey–Greenstein g
};
// nullopt where the air's σa and ω̂ are not one box of one value, or are 0 throughout. `depth` in
// world units, as for deepMaterialValues.
std::optional<AirMedium> airMediumBox(const Volume& volume, const InterfaceTable& table, double depth);
// The share of the segment a → b inside the box [lo, hi] (slabs), in [0, 1].
double boxShare(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& lo, const glm::dvec3& hi);

// The depth, in (smallest) voxel edges, beyond which a voxel is deep inside its material: a voxel
// cube's corners lie √3/2 edges from its centre, so nothing of another object is blended in.
constexpr double kDeepVoxels = 1.0;

// The `interfaces` field holds one distance per slot (components = slot count, as voxelize writes
// it) or four, the unused slots' +band (volumes written before; docs/volume-format.md). The one value
// every distance beyond the first `used` holds: `band` where the field stores no more than those
// (less than four), the stored one where the four's unused slots all hold one value, nullopt where
// they vary (a hand-made file) or all four slots are used. Then the used slots' distances alone
// describe the field: lightsim's sampler keeps them alone, the viewer uploads them alone.
std::optional<float> unusedSlotDistance(const Field& interfaces, int used, double band);

// The `interfaces` field as four distances a voxel, the slots beyond those stored holding `band`
// (what a field of one distance per slot stands for): for readers that sample all four at once
// (lightsim's GPU passes, RGBA).
Field fourSlotDistances(const Field& interfaces, double band);

// Every material sharp with a constant n (no graded slot): n is the slot's own and ∇n = 0 wherever a
// ray or a patch is, so nothing reads the ior or ior_grad fields for optics, and voxelize leaves
// ior_grad out of such a volume (it would be 0 throughout).
bool constantSlots(const InterfaceTable& table);

// ∇n of a volume: its ior_grad field (3 components), or nullptr where it is left out as 0
// throughout (constantSlots) or left unread (Volume::unread_fields). An InputError naming `source`
// where any other volume lacks it.
const Field* iorGradient(const Volume& volume, const InterfaceTable& table, const std::string& source = "volume");

// n of a volume: its ior field (1 component), or nullptr where it was left unread
// (Volume::unread_fields) in a volume of constantSlots, whose n at a voxel centre is then that of
// the first slot whose distance there is negative, 1 in none (what voxelize writes:
// slotIndexAt). An InputError naming `source` where any other volume lacks it.
const Field* refractiveIndex(const Volume& volume, const InterfaceTable& table, const std::string& source = "volume");

// n at voxel `voxel` of a volume of constantSlots from its interfaces field (`distances`, one
// distance a voxel per used slot, `components` of them): the first slot whose distance is negative
// gives its n (as a float, as the ior field holds it), none gives 1.
inline float slotIndexAt(const InterfaceTable& table, const float* distances, int components, std::size_t voxel) {
  const float* d = distances + voxel * static_cast<std::size_t>(components);
  const int slots = std::min(components, static_cast<int>(table.slots.size()));
  for (int k = 0; k < slots; ++k)
    if (d[k] < 0.0f) return static_cast<float>(table.slots[static_cast<std::size_t>(k)].ior);
  return 1.0f;
}

// Which material a point is in: the slot index, or −1 for air.
inline int materialSlot(const glm::dvec4& distances, int slot_count) {
  for (int k = 0; k < slot_count; ++k)
    if (distances[k] < 0.0) return k;
  return -1;
}

}  // namespace eik
