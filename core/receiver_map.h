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
  // Per texel, u fastest, W/m²: RGB (components 3), or one value where the three are equal in every
  // texel (components 1, grey: a white light through clear glass; makeGrey), a third of the memory
  // and of the file.
  std::vector<float> irradiance;
  int components = 3;

  std::size_t texelCount() const { return static_cast<std::size_t>(texels.x) * static_cast<std::size_t>(texels.y); }
  // Texel t's RGB irradiance, whichever the layout.
  glm::vec3 rgb(std::size_t t) const {
    if (components == 1) return glm::vec3(irradiance[t]);
    return {irradiance[3 * t], irradiance[3 * t + 1], irradiance[3 * t + 2]};
  }
  // An RGB map whose every texel holds three equal values becomes grey, in place (lossless);
  // any other map is left as it is. True when the map is grey afterwards.
  bool makeGrey();
  // A grey map becomes RGB again (three equal values a texel), in place; an RGB map stays as it is.
  void makeRgb();
  // Every texel's RGB, whichever the layout (a copy: for comparisons of maps).
  std::vector<float> rgbValues() const {
    ReceiverMap copy;
    copy.irradiance = irradiance;
    copy.components = components;
    copy.makeRgb();
    return copy.irradiance;
  }
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
    g.components = components;
    return g;
  }
  // The oriented NRRD header of the map (`components` components).
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

// Checks that a NRRD header is the one `map` needs (1 or 3 components, texels, orientation,
// tolerance 1e-4 of the pitch); InputError naming `source` and `key` otherwise. The caller takes
// the map's `components` from the header.
void checkReceiverHeader(const ReceiverMap& map, const NrrdHeader& header, const std::string& source,
                         const std::string& key, const std::string& nrrd);

}  // namespace eik
