#include "voxelize/mesh_voxelizer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "core/error.h"
#include "core/stopwatch.h"
#include "voxelize/mesh_distance.h"
#include "voxelize/solid_voxelizer.h"
#include "voxelize/surface_voxelizer.h"

namespace eik {
namespace {

// How sheet-like a mesh is. Openness is measured on the whole mesh, so that the rims of a seam
// (a lid resting in a body, two halves of a shell with a gap) cancel as they would if closed.
// Volume is measured per connected component, each about its own area centroid, so that an
// inverted twin cannot cancel a solid and two opposite sheets (a floor and a ceiling) add up to
// nothing. A "soup" whose triangles share no vertices (more than 16 components and more than one
// per four triangles) has its volume measured as a whole instead.
struct SheetMeasures {
  double area = 0.0;
  double openness = 0.0;  // |Σ area vectors| / area
  double volume = 0.0;    // Σ_c |signed volume_c|
  std::uint32_t components = 0;
};

SheetMeasures measureSheets(const TriangleMesh& mesh) {
  SheetMeasures m;
  std::vector<std::uint32_t> ids = mesh.triangleComponents(&m.components);
  if (m.components > 16 && m.components > mesh.triangles.size() / 4) std::fill(ids.begin(), ids.end(), 0u);
  if (ids.empty()) return m;
  const std::size_t n = *std::max_element(ids.begin(), ids.end()) + 1;
  std::vector<glm::dvec3> centroid(n, glm::dvec3(0.0));
  std::vector<double> area(n, 0.0), volume(n, 0.0);
  glm::dvec3 vector_area(0.0);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::dvec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1), c = mesh.corner(t, 2);
    const glm::dvec3 va = 0.5 * glm::cross(b - a, c - a);
    const double ta = glm::length(va);
    vector_area += va;
    area[ids[t]] += ta;
    centroid[ids[t]] += ta * (a + b + c) / 3.0;
  }
  for (std::size_t c = 0; c < n; ++c)
    if (area[c] > 0.0) centroid[c] /= area[c];
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::dvec3& o = centroid[ids[t]];
    volume[ids[t]] += glm::dot(mesh.corner(t, 0) - o, glm::cross(mesh.corner(t, 1) - o, mesh.corner(t, 2) - o)) / 6.0;
  }
  for (std::size_t c = 0; c < n; ++c) {
    m.area += area[c];
    m.volume += std::abs(volume[c]);
  }
  m.openness = m.area > 0.0 ? std::min(1.0, glm::length(vector_area) / m.area) : 0.0;
  return m;
}

bool classifyOpenSurface(const SheetMeasures& m, const GridSpec& grid, const MeshVoxelizeOptions& options,
                         std::string& reason) {
  const glm::dvec3 h3 = grid.voxelSize();
  const double h = (h3.x + h3.y + h3.z) / 3.0;
  char buffer[256];
  bool surface = false;
  if (m.area <= 0.0) {
    std::snprintf(buffer, sizeof buffer, "solid: no area (only degenerate triangles)");
  } else if (m.openness > options.open_surface_openness) {
    std::snprintf(buffer, sizeof buffer, "open surface: openness |sum of area vectors|/area = %.3f > %.3f",
                  m.openness, options.open_surface_openness);
    surface = true;
  } else if (m.volume < options.thin_volume_voxels * m.area * h) {
    std::snprintf(buffer, sizeof buffer,
                  "open surface: encloses %.3g, less than %.3g x area x voxel size (a sheet thinner than %.3g voxel)",
                  m.volume, options.thin_volume_voxels, 2.0 * options.thin_volume_voxels);
    surface = true;
  } else {
    std::snprintf(buffer, sizeof buffer, "solid: openness %.3f, enclosed volume %.6g", m.openness, m.volume);
  }
  reason = buffer;
  return surface;
}

// The mean voxel edge, the surface voxeliser's unit of thickness.
double meanVoxelEdge(const GridSpec& grid) {
  const glm::dvec3 h3 = grid.voxelSize();
  return (h3.x + h3.y + h3.z) / 3.0;
}

}  // namespace

bool isOpenSurface(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                   std::string* reason) {
  std::string why;
  const bool surface = classifyOpenSurface(measureSheets(mesh), grid, options, why);
  if (reason) *reason = why;
  return surface;
}

// voxelizeMesh after the input's validation and cleaning.
static Region voxelizeCleanMesh(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                                ProgressFn progress, MeshVoxelizeStats& stats, const Stopwatch& clock,
                                MeshVoxelizeStats* stats_out);

Region voxelizeMesh(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                    ProgressFn progress, MeshVoxelizeStats* stats_out) {
  const Stopwatch clock;
  MeshVoxelizeStats stats;
  for (const glm::uvec3& t : mesh.triangles)
    for (int c = 0; c < 3; ++c)
      if (t[c] >= mesh.positions.size())
        throw InputError(mesh.name, "triangles", "index " + std::to_string(t[c]) + " out of range (" +
                                                     std::to_string(mesh.positions.size()) + " positions)");
  for (const glm::dvec3& p : mesh.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError(mesh.name, "positions", "non-finite coordinate");
  if (grid.dims.x <= 0 || grid.dims.y <= 0 || grid.dims.z <= 0)
    throw InputError(mesh.name, "grid", "empty grid");
  const glm::dvec3 h = grid.voxelSize();
  if (!(h.x > 0.0 && h.y > 0.0 && h.z > 0.0)) throw InputError(mesh.name, "grid", "bounds have no extent");

  stats.topology = mesh.topology();  // reports the input's degenerate triangles too
  std::size_t dropped = 0;
  const TriangleMesh cleaned = withoutEmptyOrRepeatedTriangles(mesh, &dropped);
  stats.dropped_triangles = dropped;
  return voxelizeCleanMesh(cleaned, grid, options, progress, stats, clock, stats_out);
}

static Region voxelizeCleanMesh(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                                ProgressFn progress, MeshVoxelizeStats& stats, const Stopwatch& clock,
                                MeshVoxelizeStats* stats_out) {
  const SheetMeasures sheets = measureSheets(mesh);
  stats.area = sheets.area;
  stats.signed_volume = mesh.signedVolume();
  stats.openness = sheets.openness;
  bool surface = false;
  switch (options.surface_mode) {
    case SurfaceMode::Auto: surface = classifyOpenSurface(sheets, grid, options, stats.decision); break;
    case SurfaceMode::Solid: surface = false; stats.decision = "solid (forced)"; break;
    case SurfaceMode::Surface: surface = true; stats.decision = "open surface (forced)"; break;
  }
  stats.open_surface = surface;

  Region region;
  region.material = mesh.material;
  if (surface) {
    region.name = "mesh:" + mesh.name + " (open surface)";
    region.coverage.assign(grid.count(), 0.0f);
    voxelizeSurfaceLayer(mesh, grid, options, progress, region.coverage);
    region.material.opaque = true;
    region.enclosed_volume = 0.0;
  } else {
    region = voxelizeSolid(mesh, grid, options, progress, stats);
    region.name = "mesh:" + mesh.name;
    region.material = mesh.material;
    double sum = 0.0;
    for (float c : region.coverage) sum += c;
    region.enclosed_volume = sum * grid.voxelVolume();
  }
  if (options.distance_band > 0.0) {
    region.distance =
        surface ? sheetSignedDistance(mesh, grid, options.distance_band,
                                      std::max(options.surface_thickness_voxels, 0.0) * meanVoxelEdge(grid))
                : meshSignedDistance(mesh, grid, options.distance_band, region.coverage);
  }
  stats.seconds = clock.seconds();
  if (stats_out) *stats_out = stats;
  return region;
}

}  // namespace eik
