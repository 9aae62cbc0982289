#include "voxelize/pipeline.h"

namespace eik {

Volume buildVolume(const std::vector<Region>& regions, const GridSpec& grid, const PipelineOptions& options) {
  // Progress: compositing is about half the work, smoothing and the gradient the rest.
  auto report = [&options](double from, double to) -> ProgressFn {
    if (!options.progress) return {};
    return [&options, from, to](double f) { options.progress(from + (to - from) * f); };
  };
  CompositeOptions composite;
  composite.all_fields = options.all_fields;
  composite.progress = report(0.0, 0.5);
  Volume volume = compositeRegions(regions, grid, composite);

  Field& ior = volume.fields.at("ior");
  gaussianSmooth(ior, grid, options.smooth_sigma_voxels);  // Eq. 3.2
  // n(λ) = n + B·(1/λ² − 1/λ_d²): the Cauchy B is part of n, so it is smoothed with it. Then
  // B/(n − 1) stays the material's own ratio through the boundary layer, which the viewer's
  // ∇n(λ) = ∇n·(1 + c·B/(n − 1)) relies on.
  if (auto dispersion = volume.fields.find("dispersion"); dispersion != volume.fields.end())
    gaussianSmooth(dispersion->second, grid, options.smooth_sigma_voxels);
  if (options.progress) options.progress(0.8);
  volume.fields["ior_grad"] = gradient(ior, grid, options.gradient);  // Eq. 3.1
  volume.metadata["ior_smoothing_sigma_voxels"] = options.smooth_sigma_voxels;
  volume.metadata["ior_gradient"] = gradientOperatorName(options.gradient);
  if (options.progress) options.progress(1.0);
  return volume;
}

}  // namespace eik
