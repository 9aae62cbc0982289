#include "voxelize/composite.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <string>

#include "core/parallel.h"

namespace eik {
namespace {

Field& addZeroField(Volume& volume, const std::string& name, int components, std::size_t count) {
  Field& f = volume.fields[name];
  f.components = components;
  f.data.assign(count * static_cast<std::size_t>(components), 0.0f);
  return f;
}

bool nonZero(const glm::vec3& v) { return v.x != 0.0f || v.y != 0.0f || v.z != 0.0f; }

// A float rounded to the 7 significant digits it carries, for the manifest (1.34f → 1.34, not
// 1.340000033378601).
double tidy(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.7g", static_cast<double>(v));
  return std::strtod(text, nullptr);
}

nlohmann::json rgb(const glm::vec3& v) { return nlohmann::json::array({tidy(v.x), tidy(v.y), tidy(v.z)}); }

}  // namespace

bool blendsFields(const Material& m) {
  return nonZero(m.sigma_a) || nonZero(m.emission) || m.scatter != 0.0f || m.opaque || m.dispersion_b != 0.0f;
}

std::vector<std::size_t> compositeOrder(const std::vector<Region>& regions) {
  std::vector<std::size_t> order(regions.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (regions[a].enclosed_volume != regions[b].enclosed_volume)
      return regions[a].enclosed_volume < regions[b].enclosed_volume;
    return a > b;  // ties: the later input wins
  });
  return order;
}

Volume compositeRegions(const std::vector<Region>& regions, const GridSpec& grid, const CompositeOptions& options) {
  const std::size_t count = grid.count();
  for (const auto& r : regions) {
    if (r.coverage.size() != count)
      throw std::invalid_argument("compositeRegions: region '" + r.name + "' has " + std::to_string(r.coverage.size()) +
                                  " coverage values for a grid of " + std::to_string(count) + " voxels");
    if (!r.ior.empty() && r.ior.size() != count)
      throw std::invalid_argument("compositeRegions: region '" + r.name + "' has " + std::to_string(r.ior.size()) +
                                  " ior values for a grid of " + std::to_string(count) + " voxels");
  }

  bool need_sigma_a = options.all_fields, need_emission = options.all_fields, need_scatter = options.all_fields,
       need_opaque = options.all_fields, need_dispersion = options.all_fields;
  for (const auto& r : regions) {
    const Material& m = r.material;
    need_sigma_a |= nonZero(m.sigma_a);  // (blendsFields: any of these)
    need_emission |= nonZero(m.emission);
    need_scatter |= m.scatter != 0.0f;
    need_opaque |= m.opaque;
    need_dispersion |= m.dispersion_b != 0.0f;
  }

  Volume volume;
  volume.grid = grid;
  Field* ior = options.ior ? &addZeroField(volume, "ior", 1, count) : nullptr;
  Field* sigma_a = need_sigma_a ? &addZeroField(volume, "sigma_a", 3, count) : nullptr;
  Field* emission = need_emission ? &addZeroField(volume, "emission", 3, count) : nullptr;
  Field* scatter = need_scatter ? &addZeroField(volume, "scatter", 2, count) : nullptr;
  Field* opaque = need_opaque ? &addZeroField(volume, "opaque", 4, count) : nullptr;
  Field* dispersion = need_dispersion ? &addZeroField(volume, "dispersion", 1, count) : nullptr;

  const std::vector<std::size_t> order = compositeOrder(regions);
  const int nz = grid.dims.z;
  const std::size_t slice = static_cast<std::size_t>(grid.dims.x) * static_cast<std::size_t>(grid.dims.y);
  // Σ f_i per slice and region, summed serially afterwards (deterministic).
  std::vector<double> slice_fraction(static_cast<std::size_t>(nz) * regions.size(), 0.0);
  std::atomic<std::int64_t> slices_done{0};

  parallelFor(0, nz, [&](std::int64_t z) {
    double* fractions = slice_fraction.data() + static_cast<std::size_t>(z) * regions.size();
    const std::size_t begin = static_cast<std::size_t>(z) * slice, end = begin + slice;
    for (std::size_t v = begin; v < end; ++v) {
      float remaining = 1.0f;
      float n = 1.0f, b = 0.0f, w = 0.0f, wg = 0.0f, opaque_f = 0.0f;
      glm::vec3 sa(0.0f), le(0.0f), albedo(0.0f);
      for (std::size_t r : order) {
        if (remaining <= 0.0f) break;
        const Region& region = regions[r];
        const float f = std::min(std::clamp(region.coverage[v], 0.0f, 1.0f), remaining);
        if (f <= 0.0f) continue;
        remaining -= f;
        fractions[r] += f;
        const Material& m = region.material;
        const float n_i = region.ior.empty() ? m.ior : region.ior[v];
        n += f * (n_i - 1.0f);
        sa += f * m.sigma_a;
        le += f * m.emission;
        b += f * m.dispersion_b;
        w += f * m.scatter;
        wg += f * m.scatter * m.g;
        if (m.opaque) {
          opaque_f += f;
          albedo += f * m.albedo;
        }
      }
      if (ior) ior->data[v] = n;
      if (sigma_a) std::copy(&sa.x, &sa.x + 3, sigma_a->voxel(v));
      if (emission) std::copy(&le.x, &le.x + 3, emission->voxel(v));
      if (scatter) {
        scatter->voxel(v)[0] = w;
        scatter->voxel(v)[1] = w > 0.0f ? wg / w : 0.0f;
      }
      if (opaque && opaque_f > 0.0f) {
        float* o = opaque->voxel(v);
        o[0] = albedo.x / opaque_f;
        o[1] = albedo.y / opaque_f;
        o[2] = albedo.z / opaque_f;
        o[3] = opaque_f;
      }
      if (dispersion) dispersion->data[v] = b;
    }
    if (options.progress) options.progress(static_cast<double>(++slices_done) / std::max(1, nz));
  });

  nlohmann::json materials = nlohmann::json::array();
  const double voxel_volume = grid.voxelVolume();
  for (std::size_t r = 0; r < regions.size(); ++r) {
    double sum = 0.0;
    for (int z = 0; z < nz; ++z) sum += slice_fraction[static_cast<std::size_t>(z) * regions.size() + r];
    const Material& m = regions[r].material;
    nlohmann::json entry = {{"name", regions[r].name},
                            {"material", m.name},
                            {"ior", tidy(m.ior)},
                            {"ior_varies", !regions[r].ior.empty()},
                            {"sigma_a", rgb(m.sigma_a)},
                            {"emission", rgb(m.emission)},
                            {"scatter", tidy(m.scatter)},
                            {"g", tidy(m.g)},
                            {"dispersion_b", tidy(m.dispersion_b)},
                            {"opaque", m.opaque},
                            {"enclosed_volume", regions[r].enclosed_volume},
                            {"volume", sum * voxel_volume}};
    if (m.opaque) entry["albedo"] = rgb(m.albedo);
    materials.push_back(std::move(entry));
  }
  volume.metadata["materials"] = std::move(materials);
  return volume;
}

}  // namespace eik
