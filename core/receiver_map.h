// Receiver maps (docs/volume-format.md "receivers"; docs/physics.md "Receivers"): the planar
// irradiance that `lightsim` bakes onto a diffuse plane (the scene's ground), finer than the
// volume's grid, and that the viewer shades that plane with.
//
// A map is a rectangle of texels on the plane through `point` with unit normal `normal`, spanned by
// the unit in-plane axes `u` and `v` (u × v = normal): texel (i, j) covers the (u, v) coordinates
// [origin + (i, j)·pitch, origin + (i + 1, j + 1)·pitch] relative to `point`. Its value is the RGB
// planar irradiance (W/m², flux through the plane per area, the cos θ included) averaged over the
// texel. On disk it is a one-texel-thick 3D NRRD oriented in the plane (space directions pitch·u,
// pitch·v, pitch·normal), so ParaView and 3D Slicer show it where it lies.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/nrrd.h"

namespace eik {

struct ReceiverMap {
  std::string name = "ground";
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0, 1.0, 0.0};
  glm::dvec3 u{1.0, 0.0, 0.0}, v{0.0, 0.0, 1.0};
  glm::dvec2 origin{0.0};           // (u, v) of the map's corner, relative to `point`
  double pitch = 0.0;               // texel edge, world units
  glm::ivec2 texels{0};
  std::vector<float> irradiance;    // RGB per texel, u fastest; W/m²

  std::size_t texelCount() const { return static_cast<std::size_t>(texels.x) * static_cast<std::size_t>(texels.y); }
  // World position of the centre of texel (i, j).
  glm::dvec3 texelCenter(int i, int j) const {
    return point + (origin.x + (i + 0.5) * pitch) * u + (origin.y + (j + 0.5) * pitch) * v;
  }
  // (u, v) plane coordinates of a world point (its projection onto the plane).
  glm::dvec2 planeCoordinates(const glm::dvec3& world) const {
    return {glm::dot(world - point, u), glm::dot(world - point, v)};
  }
  // The map without its irradiance (every other member copied).
  ReceiverMap geometry() const {
    ReceiverMap g;
    g.name = name;
    g.point = point;
    g.normal = normal;
    g.u = u;
    g.v = v;
    g.origin = origin;
    g.pitch = pitch;
    g.texels = texels;
    return g;
  }
  // The oriented NRRD header of the map (3 components).
  NrrdHeader nrrdHeader() const;
  // The manifest entry, with `file` the NRRD's name relative to the manifest.
  nlohmann::json toJson(const std::string& file) const;
};

// The in-plane axes for a plane normal: u the world axis least aligned with the normal, projected
// onto the plane (+x for a ground facing +y), and v = normal × u, so that u × v = normal (−z there).
void receiverAxes(const glm::dvec3& normal, glm::dvec3& u, glm::dvec3& v);

// Parses a manifest entry (not the data): InputError naming `source` and `key` for anything
// malformed. `file` receives the NRRD path as written.
ReceiverMap receiverFromJson(const nlohmann::json& j, const std::string& source, const std::string& key,
                             std::string& file);

// Checks that a NRRD header is the one `map` needs (components, texels, orientation, tolerance
// 1e-4 of the pitch); InputError naming `source` and `key` otherwise.
void checkReceiverHeader(const ReceiverMap& map, const NrrdHeader& header, const std::string& source,
                         const std::string& key, const std::string& nrrd);

}  // namespace eik
