// The scene's ground map of viewer/ground_map.h.
#include "viewer/ground_map.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/parallel.h"

namespace eik {

glm::dvec3 directIrradiance(const ReceiverLayer::Light& light, const glm::dvec3& x, const glm::dvec3& normal) {
  const glm::dvec3 pos(light.pos);
  if (light.pos.w == 0.0) return light.power * std::max(0.0, -glm::dot(normal, pos));
  const glm::dvec3 L = pos - x;
  const double r2 = std::max(glm::dot(L, L), 1e-12);
  double spot = 1.0;
  if (light.spot_scale > 0.0) {
    const double t =
        std::clamp((glm::dot(glm::dvec3(light.spot), -L / std::sqrt(r2)) - light.spot.w) * light.spot_scale, 0.0, 1.0);
    spot = t * t;
  }
  return light.power * (spot * std::max(0.0, glm::dot(normal, L) / std::sqrt(r2)) / r2);
}

glm::dvec3 bakedDirectIrradiance(const ReceiverLayer& layer, const glm::dvec3& x, const glm::dvec3& normal) {
  return directIrradiance({layer.light_pos, layer.light_power, layer.light_spot, layer.light_spot_scale}, x, normal);
}

glm::dvec3 otherLightsIrradiance(const ReceiverLayer& layer, const glm::dvec3& x, const glm::dvec3& normal) {
  glm::dvec3 sum(0.0);
  for (const ReceiverLayer::Light& light : layer.other_lights) sum += directIrradiance(light, x, normal);
  return sum;
}

bool receiverChangeAt(const ReceiverLayer& layer, const glm::dvec3& xw, glm::dvec3& change) {
  const ReceiverMap& map = *layer.map;
  change = glm::dvec3(0.0);
  const glm::dvec3 x = glm::dvec3(layer.to_volume * glm::dvec4(xw, 1.0));
  const glm::dvec2 size = glm::dvec2(map.texels) * map.pitch;
  const glm::dvec2 st = (map.planeCoordinates(x) - map.origin) / size;
  if (st.x < 0.0 || st.y < 0.0 || st.x > 1.0 || st.y > 1.0) return false;
  // Bilinear between texel centres, clamped to the edge texels (GL_LINEAR, CLAMP_TO_EDGE).
  const glm::dvec2 at = st * glm::dvec2(map.texels) - 0.5;
  const int i0 = static_cast<int>(std::floor(at.x)), j0 = static_cast<int>(std::floor(at.y));
  const double fx = at.x - i0, fy = at.y - j0;
  auto texel = [&](int i, int j) {
    i = std::clamp(i, 0, map.texels.x - 1);
    j = std::clamp(j, 0, map.texels.y - 1);
    const std::size_t t = static_cast<std::size_t>(j) * static_cast<std::size_t>(map.texels.x) + static_cast<std::size_t>(i);
    if (!layer.texels) return glm::dvec4(glm::dvec3(map.rgb(t)), 1.0);
    const float* e = &(*layer.texels)[4 * t];
    return glm::dvec4(e[0], e[1], e[2], e[3]);
  };
  const glm::dvec4 E = (1 - fx) * (1 - fy) * texel(i0, j0) + fx * (1 - fy) * texel(i0 + 1, j0) +
                       (1 - fx) * fy * texel(i0, j0 + 1) + fx * fy * texel(i0 + 1, j0 + 1);
  const glm::dvec3 normal = glm::cross(map.u, map.v);
  change = glm::dvec3(E) - bakedDirectIrradiance(layer, x, normal) * (E.w >= 0.0 ? 1.0 : 2.0);
  if (!layer.texels) change -= otherLightsIrradiance(layer, x, normal);
  return true;
}

GroundMap combineReceiverMaps(const std::vector<ReceiverLayer>& layers, const glm::dvec3& point, const glm::dvec3& u,
                              const glm::dvec3& v, std::size_t max_texels) {
  GroundMap g;
  g.point = point;
  g.u = u;
  g.v = v;
  if (layers.empty()) return g;
  // The union of the footprints in (u, v), and the finest pitch in world units.
  glm::dvec2 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
  double finest = std::numeric_limits<double>::max();
  std::size_t finest_layer = 0;
  auto toWorld = [](const ReceiverLayer& layer, const glm::dvec3& x) { return glm::dvec3(layer.to_world * glm::dvec4(x, 1.0)); };
  for (std::size_t l = 0; l < layers.size(); ++l) {
    const ReceiverLayer& layer = layers[l];
    const ReceiverMap& map = *layer.map;
    const glm::dvec2 size = glm::dvec2(map.texels) * map.pitch;
    for (int corner = 0; corner < 4; ++corner) {
      const glm::dvec2 c = map.origin + glm::dvec2(corner & 1 ? size.x : 0.0, corner & 2 ? size.y : 0.0);
      const glm::dvec3 w = toWorld(layer, map.point + c.x * map.u + c.y * map.v) - point;
      const glm::dvec2 p(glm::dot(w, u), glm::dot(w, v));
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    const glm::dmat3 linear(layer.to_world);
    const double pitch = map.pitch * std::min(glm::length(linear * map.u), glm::length(linear * map.v));
    if (pitch < finest) {
      finest = pitch;
      finest_layer = l;
    }
  }
  g.pitch = finest;
  const glm::dvec2 extent = hi - lo;
  auto texelsAt = [&](double pitch) { return (std::ceil(extent.x / pitch) + 1) * (std::ceil(extent.y / pitch) + 1); };
  if (texelsAt(finest) > static_cast<double>(max_texels)) {
    g.pitch = finest * std::sqrt(texelsAt(finest) / static_cast<double>(max_texels));
    while (texelsAt(g.pitch) > static_cast<double>(max_texels)) g.pitch *= 1.01;
  }
  // The finest map's own lattice where its axes are the ground's (a translated object): its texel
  // centres are the ground map's, so bilinear filtering of the sum reproduces it exactly.
  const ReceiverLayer& anchor = layers[finest_layer];
  const glm::dmat3 anchor_linear(anchor.to_world);
  const glm::dvec3 au = glm::normalize(anchor_linear * anchor.map->u), av = glm::normalize(anchor_linear * anchor.map->v);
  glm::dvec2 start = lo;
  if (g.pitch == finest && glm::dot(au, u) > 0.999999 && glm::dot(av, v) > 0.999999) {
    const glm::dvec3 corner = toWorld(anchor, anchor.map->point + anchor.map->origin.x * anchor.map->u +
                                                  anchor.map->origin.y * anchor.map->v) - point;
    const glm::dvec2 c(glm::dot(corner, u), glm::dot(corner, v));
    start = c + glm::floor((lo - c) / g.pitch + 1e-9) * g.pitch;
  }
  g.origin = start;
  g.texels = glm::ivec2(glm::max(glm::dvec2(1.0), glm::ceil((hi - start) / g.pitch - 1e-9)));
  g.rgba.assign(static_cast<std::size_t>(g.texels.x) * static_cast<std::size_t>(g.texels.y) * 4, 0.0f);
  parallelFor(0, g.texels.y, [&](std::int64_t row) {
    const std::size_t j = static_cast<std::size_t>(row);
    for (int i = 0; i < g.texels.x; ++i) {
      const glm::dvec3 xw = point + (g.origin.x + (i + 0.5) * g.pitch) * u + (g.origin.y + (static_cast<double>(j) + 0.5) * g.pitch) * v;
      glm::dvec3 sum(0.0);
      bool covered = false;
      for (const ReceiverLayer& layer : layers) {
        glm::dvec3 change;
        if (receiverChangeAt(layer, xw, change)) {
          sum += change;
          covered = true;
        }
      }
      float* out = &g.rgba[4 * (j * static_cast<std::size_t>(g.texels.x) + static_cast<std::size_t>(i))];
      out[0] = static_cast<float>(sum.x);
      out[1] = static_cast<float>(sum.y);
      out[2] = static_cast<float>(sum.z);
      out[3] = covered ? 1.0f : 0.0f;
    }
  });
  return g;
}

}  // namespace eik
