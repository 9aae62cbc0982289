#include "voxelize/field_filters.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/parallel.h"

namespace eik {
namespace {

void checkScalar(const Field& field, const GridSpec& grid, const char* what) {
  if (field.components != 1)
    throw std::invalid_argument(std::string(what) + ": expected a 1-component field, got " +
                                std::to_string(field.components));
  if (field.data.size() != grid.count())
    throw std::invalid_argument(std::string(what) + ": field has " + std::to_string(field.data.size()) +
                                " values but the grid " + std::to_string(grid.count()) + " voxels");
}

// --- Slice-wise helpers for the gradients. A slice is nx·ny floats, x fastest. ---

// Eq. 3.1 along x of a slice, scaled: out = (f(x+1) − f(x−1))/2h, one-sided at the ends, 0 if nx = 1.
void differenceX(const float* in, float* out, int nx, int ny, double h) {
  const float inv_h = static_cast<float>(1.0 / h), inv_2h = static_cast<float>(0.5 / h);
  for (int y = 0; y < ny; ++y) {
    const float* f = in + static_cast<std::size_t>(y) * nx;
    float* d = out + static_cast<std::size_t>(y) * nx;
    if (nx < 2) {
      d[0] = 0.0f;
      continue;
    }
    d[0] = (f[1] - f[0]) * inv_h;
    for (int x = 1; x < nx - 1; ++x) d[x] = (f[x + 1] - f[x - 1]) * inv_2h;  // Eq. 3.1
    d[nx - 1] = (f[nx - 1] - f[nx - 2]) * inv_h;
  }
}

// The same along y.
void differenceY(const float* in, float* out, int nx, int ny, double h) {
  const float inv_h = static_cast<float>(1.0 / h), inv_2h = static_cast<float>(0.5 / h);
  for (int y = 0; y < ny; ++y) {
    float* d = out + static_cast<std::size_t>(y) * nx;
    if (ny < 2) {
      std::fill(d, d + nx, 0.0f);
      continue;
    }
    const int yp = std::min(y + 1, ny - 1), ym = std::max(y - 1, 0);
    const float scale = (yp - ym == 2) ? inv_2h : inv_h;
    const float* a = in + static_cast<std::size_t>(yp) * nx;
    const float* b = in + static_cast<std::size_t>(ym) * nx;
    for (int x = 0; x < nx; ++x) d[x] = (a[x] - b[x]) * scale;
  }
}

// [1, 4, 1]/6 along x, clamping at the ends.
void crossAverageX(const float* in, float* out, int nx, int ny) {
  constexpr float side = 1.0f / 6.0f, mid = 4.0f / 6.0f;
  for (int y = 0; y < ny; ++y) {
    const float* f = in + static_cast<std::size_t>(y) * nx;
    float* o = out + static_cast<std::size_t>(y) * nx;
    for (int x = 0; x < nx; ++x) o[x] = side * f[clampIndex(x - 1, nx)] + mid * f[x] + side * f[clampIndex(x + 1, nx)];
  }
}

// [1, 4, 1]/6 along y, clamping at the ends.
void crossAverageY(const float* in, float* out, int nx, int ny) {
  constexpr float side = 1.0f / 6.0f, mid = 4.0f / 6.0f;
  for (int y = 0; y < ny; ++y) {
    const float* a = in + static_cast<std::size_t>(clampIndex(y - 1, ny)) * nx;
    const float* b = in + static_cast<std::size_t>(y) * nx;
    const float* c = in + static_cast<std::size_t>(clampIndex(y + 1, ny)) * nx;
    float* o = out + static_cast<std::size_t>(y) * nx;
    for (int x = 0; x < nx; ++x) o[x] = side * a[x] + mid * b[x] + side * c[x];
  }
}

// Writes component `c` of an interleaved 3-component slice.
void scatterComponent(const float* in, float* grad_slice, std::size_t n, int c) {
  for (std::size_t i = 0; i < n; ++i) grad_slice[3 * i + static_cast<std::size_t>(c)] = in[i];
}

}  // namespace

Field centralDifferenceGradient(const Field& scalar, const GridSpec& grid) {
  checkScalar(scalar, grid, "centralDifferenceGradient");
  Field grad;
  grad.components = 3;
  grad.data.resize(grid.count() * 3);
  const int nx = grid.dims.x, ny = grid.dims.y, nz = grid.dims.z;
  const std::size_t slice = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  const glm::dvec3 h = grid.voxelSize();
  const float* f = scalar.data.data();
  parallelFor(0, nz, [&](std::int64_t zz) {
    const int z = static_cast<int>(zz);
    std::vector<float> d(slice);
    const float* s0 = f + static_cast<std::size_t>(z) * slice;
    float* out = grad.data.data() + static_cast<std::size_t>(z) * slice * 3;
    differenceX(s0, d.data(), nx, ny, h.x);
    scatterComponent(d.data(), out, slice, 0);
    differenceY(s0, d.data(), nx, ny, h.y);
    scatterComponent(d.data(), out, slice, 1);
    if (nz < 2) {
      std::fill(d.begin(), d.end(), 0.0f);
    } else {
      const int zp = std::min(z + 1, nz - 1), zm = std::max(z - 1, 0);
      const float scale = static_cast<float>((zp - zm == 2 ? 0.5 : 1.0) / h.z);  // Eq. 3.1, one-sided at borders
      const float* a = f + static_cast<std::size_t>(zp) * slice;
      const float* b = f + static_cast<std::size_t>(zm) * slice;
      for (std::size_t i = 0; i < slice; ++i) d[i] = (a[i] - b[i]) * scale;
    }
    scatterComponent(d.data(), out, slice, 2);
  });
  return grad;
}

Field isotropicGradient(const Field& scalar, const GridSpec& grid) {
  checkScalar(scalar, grid, "isotropicGradient");
  Field grad;
  grad.components = 3;
  grad.data.resize(grid.count() * 3);
  const int nx = grid.dims.x, ny = grid.dims.y, nz = grid.dims.z;
  const std::size_t slice = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  const glm::dvec3 h = grid.voxelSize();
  const float* f = scalar.data.data();
  // Every operator below acts along one axis, so they commute; per output slice z only the input
  // slices z − 1, z, z + 1 are read.
  parallelFor(0, nz, [&](std::int64_t zz) {
    const int z = static_cast<int>(zz);
    std::vector<float> a(slice), b(slice), c(slice);
    const float* sm = f + static_cast<std::size_t>(clampIndex(z - 1, nz)) * slice;
    const float* s0 = f + static_cast<std::size_t>(z) * slice;
    const float* sp = f + static_cast<std::size_t>(clampIndex(z + 1, nz)) * slice;
    float* out = grad.data.data() + static_cast<std::size_t>(z) * slice * 3;
    // a = [1, 4, 1]/6 along z.
    for (std::size_t i = 0; i < slice; ++i) a[i] = (sm[i] + 4.0f * s0[i] + sp[i]) * (1.0f / 6.0f);
    // ∂/∂x: averaged along y and z.
    crossAverageY(a.data(), b.data(), nx, ny);
    differenceX(b.data(), c.data(), nx, ny, h.x);
    scatterComponent(c.data(), out, slice, 0);
    // ∂/∂y: averaged along x and z.
    crossAverageX(a.data(), b.data(), nx, ny);
    differenceY(b.data(), c.data(), nx, ny, h.y);
    scatterComponent(c.data(), out, slice, 1);
    // ∂/∂z: the z-difference of the slices, averaged along x and y.
    if (nz < 2) {
      std::fill(c.begin(), c.end(), 0.0f);
    } else {
      const float scale = static_cast<float>((sp - sm == static_cast<std::ptrdiff_t>(2 * slice) ? 0.5 : 1.0) / h.z);
      for (std::size_t i = 0; i < slice; ++i) a[i] = (sp[i] - sm[i]) * scale;
      crossAverageX(a.data(), b.data(), nx, ny);
      crossAverageY(b.data(), c.data(), nx, ny);
    }
    scatterComponent(c.data(), out, slice, 2);
  });
  return grad;
}

Field gradient(const Field& scalar, const GridSpec& grid, GradientOperator op) {
  return op == GradientOperator::CentralDifference ? centralDifferenceGradient(scalar, grid)
                                                   : isotropicGradient(scalar, grid);
}

const char* gradientOperatorName(GradientOperator op) {
  return op == GradientOperator::CentralDifference ? "central_difference" : "isotropic";
}

}  // namespace eik
