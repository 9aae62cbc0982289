#include "lightsim/spectral_bake.h"

#include <algorithm>
#include <stdexcept>

#include "core/interfaces.h"

namespace eik {

bool isDispersive(const Volume& volume) {
  if (const Field* b = volume.find("dispersion"))
    if (std::any_of(b->data.begin(), b->data.end(), [](float v) { return v != 0.0f; })) return true;
  if (!volume.has("interfaces")) return false;
  const InterfaceTable table = interfaceTable(volume);
  return std::any_of(table.slots.begin(), table.slots.end(), [](const InterfaceSlot& s) { return s.dispersion_b != 0.0; });
}

Volume volumeAtWavelength(const Volume& volume, double lambda_um) {
  Volume at = volume;
  const double term = cauchyTerm(lambda_um);
  if (term == 0.0 || !isDispersive(volume)) return at;
  const GridSpec& g = volume.grid;
  if (const Field* b = volume.find("dispersion"); b && b->components == 1) {
    Field* n = at.fields.count("ior") ? &at.fields["ior"] : nullptr;
    Field* grad = at.fields.count("ior_grad") ? &at.fields["ior_grad"] : nullptr;
    const glm::dvec3 spacing = (g.bounds_max - g.bounds_min) / glm::dvec3(g.dims);
    for (int z = 0; z < g.dims.z; ++z)
      for (int y = 0; y < g.dims.y; ++y)
        for (int x = 0; x < g.dims.x; ++x) {
          const std::size_t i = g.index(x, y, z);
          if (n) n->data[i] = static_cast<float>(n->data[i] + term * b->data[i]);
          if (!grad) continue;
          const int p[3] = {x, y, z};
          for (int a = 0; a < 3; ++a) {
            int lo[3] = {x, y, z}, hi[3] = {x, y, z};
            lo[a] = std::max(0, p[a] - 1);
            hi[a] = std::min(g.dims[a] - 1, p[a] + 1);
            if (hi[a] == lo[a]) continue;
            const double db = b->data[g.index(hi[0], hi[1], hi[2])] - b->data[g.index(lo[0], lo[1], lo[2])];
            float& v = grad->data[3 * i + static_cast<std::size_t>(a)];
            v = static_cast<float>(v + term * db / ((hi[a] - lo[a]) * spacing[a]));
          }
        }
  }
  if (volume.has("interfaces")) {
    InterfaceTable table = interfaceTable(volume);
    for (InterfaceSlot& s : table.slots) s.ior += s.dispersion_b * term;
    at.metadata["interfaces"] = table.toJson();
  }
  return at;
}

void BandSum::add(BakeResult band) {
  const std::size_t voxels = band.light_dir.data.size() / 3;
  if (empty_) {
    empty_ = false;
    direction_.assign(voxels * 3, 0.0);
    sum_ = std::move(band);
    for (std::size_t v = 0; v < voxels; ++v) {
      const float* e = sum_.irradiance.voxel(v);
      const double w = (e[0] + e[1] + e[2]) / 3.0;
      for (int c = 0; c < 3; ++c) direction_[3 * v + c] = w * sum_.light_dir.data[3 * v + c];
    }
    return;
  }
  if (band.irradiance.data.size() != sum_.irradiance.data.size() || band.receivers.size() != sum_.receivers.size())
    throw std::logic_error("BandSum: bands of different shapes");
  for (std::size_t v = 0; v < voxels; ++v) {
    const float* e = band.irradiance.voxel(v);
    const double w = (e[0] + e[1] + e[2]) / 3.0;
    for (int c = 0; c < 3; ++c) direction_[3 * v + c] += w * band.light_dir.data[3 * v + c];
  }
  for (std::size_t i = 0; i < band.irradiance.data.size(); ++i) sum_.irradiance.data[i] += band.irradiance.data[i];
  for (std::size_t r = 0; r < band.receivers.size(); ++r) {
    // A grey map and an RGB one (a white light and a coloured one) sum as RGB.
    if (band.receivers[r].components != sum_.receivers[r].components) {
      band.receivers[r].makeRgb();
      sum_.receivers[r].makeRgb();
    }
    std::vector<float>& to = sum_.receivers[r].irradiance;
    const std::vector<float>& from = band.receivers[r].irradiance;
    if (from.size() != to.size()) throw std::logic_error("BandSum: receiver maps of different sizes");
    for (std::size_t i = 0; i < to.size(); ++i) to[i] += from[i];
  }
  SimulationStats& s = sum_.stats;
  const SimulationStats& b = band.stats;
  s.steps = std::max(s.steps, b.steps);
  s.initial_patches += b.initial_patches;
  s.peak_patches = std::max(s.peak_patches, b.peak_patches);
  s.total_patches += b.total_patches;
  if (s.patch_steps_by_bounce.size() < b.patch_steps_by_bounce.size())
    s.patch_steps_by_bounce.resize(b.patch_steps_by_bounce.size(), 0);
  for (std::size_t i = 0; i < b.patch_steps_by_bounce.size(); ++i) s.patch_steps_by_bounce[i] += b.patch_steps_by_bounce[i];
  if (s.flux_received_by_bounce.size() < b.flux_received_by_bounce.size())
    s.flux_received_by_bounce.resize(b.flux_received_by_bounce.size(), glm::dvec3(0.0));
  for (std::size_t i = 0; i < b.flux_received_by_bounce.size(); ++i) s.flux_received_by_bounce[i] += b.flux_received_by_bounce[i];
  s.splits += b.splits;
  s.kills.flux += b.kills.flux;
  s.kills.exited += b.kills.exited;
  s.kills.folded += b.kills.folded;
  s.kills.depth += b.kills.depth;
  s.kills.received += b.kills.received;
  s.kills.blocked += b.kills.blocked;
  s.kills.trapped += b.kills.trapped;
  s.flux_in += b.flux_in;
  s.flux_out += b.flux_out;
  s.flux_absorbed += b.flux_absorbed;
  s.flux_reflected += b.flux_reflected;
  s.flux_killed += b.flux_killed;
  s.flux_unfinished += b.flux_unfinished;
  s.flux_received += b.flux_received;
  s.flux_blocked += b.flux_blocked;
  s.reflections += b.reflections;
  s.rollbacks += b.rollbacks;
  s.flights += b.flights;
  for (const auto& [phase, seconds] : b.phase_seconds) s.phase_seconds[phase] += seconds;
}

BakeResult BandSum::finish() {
  if (empty_) throw std::logic_error("BandSum: no band");
  const std::size_t voxels = direction_.size() / 3;
  for (std::size_t v = 0; v < voxels; ++v) {
    const glm::dvec3 d(direction_[3 * v], direction_[3 * v + 1], direction_[3 * v + 2]);
    const double len = glm::length(d);
    for (int c = 0; c < 3; ++c) sum_.light_dir.data[3 * v + c] = len > 0.0 ? static_cast<float>(d[c] / len) : 0.0f;
  }
  empty_ = true;
  direction_.clear();
  return std::move(sum_);
}

}  // namespace eik
