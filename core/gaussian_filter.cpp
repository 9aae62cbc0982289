#include "core/gaussian_filter.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/parallel.h"

namespace eik {
namespace {

// Thesis Eq. 3.2 writes the kernel as exp(−((x − x0)/σ)²) but calls σ the standard deviation; we
// use the standard-deviation form exp(−x²/(2σ²)), sampled at integer offsets and normalised.
std::vector<float> gaussianKernel(double sigma) {
  const int radius = gaussianRadius(sigma);
  std::vector<double> w(static_cast<std::size_t>(2 * radius + 1));
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    const double v = std::exp(-0.5 * (k * k) / (sigma * sigma));
    w[static_cast<std::size_t>(k + radius)] = v;
    sum += v;
  }
  std::vector<float> out(w.size());
  for (std::size_t i = 0; i < w.size(); ++i) out[i] = static_cast<float>(w[i] / sum);
  return out;
}

// Convolves a scalar array (x fastest) along one axis with an odd, centred kernel, in place,
// clamping to the edge voxel at the borders. Every pass runs its inner loop along contiguous x, so
// it vectorises; parallel over z-slices (deterministic: each output value is written once).
void convolveAxis(std::vector<float>& values, const glm::ivec3& dims, int axis, const std::vector<float>& kernel) {
  const int nx = dims.x, ny = dims.y, nz = dims.z;
  if (dims[axis] < 2 || kernel.size() < 2) return;
  const int radius = static_cast<int>(kernel.size() / 2);
  const int taps = static_cast<int>(kernel.size());
  const std::size_t slice = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  float* data = values.data();

  if (axis == 0) {
    // Each row is copied into a buffer padded by clamping, then convolved.
    parallelFor(0, nz, [&](std::int64_t z) {
      std::vector<float> padded(static_cast<std::size_t>(nx + 2 * radius));
      std::vector<float> out(static_cast<std::size_t>(nx));
      for (int y = 0; y < ny; ++y) {
        float* row = data + static_cast<std::size_t>(z) * slice + static_cast<std::size_t>(y) * nx;
        for (int x = -radius; x < nx + radius; ++x) padded[static_cast<std::size_t>(x + radius)] = row[clampIndex(x, nx)];
        std::fill(out.begin(), out.end(), 0.0f);
        for (int k = 0; k < taps; ++k) {
          const float wk = kernel[static_cast<std::size_t>(k)];
          const float* src = padded.data() + k;
          for (int x = 0; x < nx; ++x) out[static_cast<std::size_t>(x)] += wk * src[x];
        }
        std::copy(out.begin(), out.end(), row);
      }
    });
  } else if (axis == 1) {
    // Per z-slice, whole rows are combined.
    parallelFor(0, nz, [&](std::int64_t z) {
      float* base = data + static_cast<std::size_t>(z) * slice;
      const std::vector<float> src(base, base + slice);
      for (int y = 0; y < ny; ++y) {
        float* dst = base + static_cast<std::size_t>(y) * nx;
        std::fill(dst, dst + nx, 0.0f);
        for (int k = 0; k < taps; ++k) {
          const float wk = kernel[static_cast<std::size_t>(k)];
          const float* row = src.data() + static_cast<std::size_t>(clampIndex(y + k - radius, ny)) * nx;
          for (int x = 0; x < nx; ++x) dst[x] += wk * row[x];
        }
      }
    });
  } else {
    // Per y, the x-z plane is copied out (rows of x stay contiguous) and convolved along z.
    parallelFor(0, ny, [&](std::int64_t y) {
      std::vector<float> plane(static_cast<std::size_t>(nx) * static_cast<std::size_t>(nz));
      for (int z = 0; z < nz; ++z) {
        const float* row = data + static_cast<std::size_t>(z) * slice + static_cast<std::size_t>(y) * nx;
        std::copy(row, row + nx, plane.data() + static_cast<std::size_t>(z) * nx);
      }
      for (int z = 0; z < nz; ++z) {
        float* dst = data + static_cast<std::size_t>(z) * slice + static_cast<std::size_t>(y) * nx;
        std::fill(dst, dst + nx, 0.0f);
        for (int k = 0; k < taps; ++k) {
          const float wk = kernel[static_cast<std::size_t>(k)];
          const float* src = plane.data() + static_cast<std::size_t>(clampIndex(z + k - radius, nz)) * nx;
          for (int x = 0; x < nx; ++x) dst[x] += wk * src[x];
        }
      }
    });
  }
}

}  // namespace

int gaussianRadius(double sigma_voxels) {
  return sigma_voxels > 0.0 ? static_cast<int>(std::ceil(3.0 * sigma_voxels - 1e-9)) : 0;
}

void gaussianSmooth(Field& scalar, const GridSpec& grid, double sigma_voxels) {
  if (!(sigma_voxels >= 0.0) || !std::isfinite(sigma_voxels))
    throw std::invalid_argument("gaussianSmooth: sigma must be a finite number >= 0, got " +
                                std::to_string(sigma_voxels));
  if (scalar.components != 1)
    throw std::invalid_argument("gaussianSmooth: expected a 1-component field, got " +
                                std::to_string(scalar.components));
  if (scalar.data.size() != grid.count())
    throw std::invalid_argument("gaussianSmooth: field has " + std::to_string(scalar.data.size()) +
                                " values but the grid " + std::to_string(grid.count()) + " voxels");
  if (sigma_voxels == 0.0 || grid.count() == 0) return;
  // Eq. 3.2 is separable: g(x, y, z) = g(x)·g(y)·g(z).
  const std::vector<float> kernel = gaussianKernel(sigma_voxels);
  for (int axis = 0; axis < 3; ++axis) convolveAxis(scalar.data, grid.dims, axis, kernel);
}

void gaussianSmoothComponents(Field& field, const GridSpec& grid, double sigma_voxels) {
  if (field.components < 1 || field.data.size() != grid.count() * static_cast<std::size_t>(field.components))
    throw std::invalid_argument("gaussianSmoothComponents: field size does not match the grid");
  if (field.components == 1) return gaussianSmooth(field, grid, sigma_voxels);
  const std::size_t count = grid.count(), comps = static_cast<std::size_t>(field.components);
  Field channel;
  channel.data.resize(count);
  for (std::size_t c = 0; c < comps; ++c) {
    for (std::size_t i = 0; i < count; ++i) channel.data[i] = field.data[i * comps + c];
    gaussianSmooth(channel, grid, sigma_voxels);
    for (std::size_t i = 0; i < count; ++i) field.data[i * comps + c] = channel.data[i];
  }
}

}  // namespace eik
