// A dispersive volume baked band by band (`lightsim --bands N`, docs/programs.md; docs/physics.md
// "Dispersion"): each band propagates with its own n(λ) = n + B·(1/λ² − 1/λ_d²), the Cauchy B of
// the volume's `dispersion` field and of its slot table, and carries its share of the light's RGB
// power (core/spectrum.h spectralBands); the bands' bakes add up to the RGB bake. A volume without
// dispersion is baked once: every band would bend alike.
#pragma once

#include "core/spectrum.h"
#include "core/volume.h"
#include "lightsim/simulator.h"

namespace eik {

// A `dispersion` field with a value other than 0, or a slot of the interface table with a Cauchy B.
bool isDispersive(const Volume& volume);

// The volume as light of wavelength λ (µm) sees it: the `ior` field + B·cauchyTerm(λ) with B from
// the `dispersion` field, `ior_grad` + cauchyTerm(λ)·∇B (central differences of the field, one-sided
// at the grid's faces), and each slot's `ior` + its dispersion_b·cauchyTerm(λ). λ_d or a volume
// without dispersion: unchanged.
Volume volumeAtWavelength(const Volume& volume, double lambda_um);

// The bands' bakes summed into one: irradiance, receiver maps (the same geometry in every band: the
// light's direction and the box set it), the statistics' fluxes and counts (steps and peaks: the
// largest band's). light_dir is the irradiance-weighted mean direction (lum(E_band)·d_band summed,
// then made unit).
class BandSum {
 public:
  void add(BakeResult band);
  // The sum (after at least one add).
  BakeResult finish();

 private:
  bool empty_ = true;
  BakeResult sum_;
  std::vector<double> direction_;  // Σ lum(E)·d per voxel, 3 per voxel
};

}  // namespace eik
