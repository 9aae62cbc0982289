#include "lightsim/scene_bake.h"

#include <cmath>

#include "core/interfaces.h"

namespace eik {

BakeFrame BakeFrame::of(const SceneObjectSpec& object) { return of(objectToWorld(object)); }

BakeFrame BakeFrame::of(const glm::dmat4& object_to_world) {
  const glm::dmat3 linear(object_to_world);
  BakeFrame frame;
  frame.scale = std::cbrt(std::abs(glm::determinant(linear)));
  frame.rotation = linear / frame.scale;
  frame.origin = glm::dvec3(object_to_world[3]);
  return frame;
}

LightSpec BakeFrame::light(const LightSpec& world) const {
  const glm::dmat3 to_bake = glm::transpose(rotation);  // R⁻¹ (R is a rotation)
  LightSpec light = world;
  light.direction = glm::normalize(to_bake * world.direction);
  light.position = to_bake * (world.position - origin);
  return light;
}

ReceiverSpec BakeFrame::receiver(const ReceiverSpec& world) const {
  const glm::dmat3 to_bake = glm::transpose(rotation);
  ReceiverSpec receiver = world;
  receiver.point = to_bake * (world.point - origin);
  receiver.normal = glm::normalize(to_bake * world.normal);
  return receiver;
}

Volume volumeAtWorldScale(const Volume& volume, double scale) {
  Volume scaled = volume;
  if (scale == 1.0) return scaled;
  scaled.grid.bounds_min *= scale;
  scaled.grid.bounds_max *= scale;
  const auto times = [](Field& field, double factor) {
    for (float& v : field.data) v = static_cast<float>(v * factor);
  };
  if (auto it = scaled.fields.find("ior_grad"); it != scaled.fields.end()) times(it->second, 1.0 / scale);
  if (auto it = scaled.fields.find("interfaces"); it != scaled.fields.end()) {
    times(it->second, scale);
    InterfaceTable table = interfaceTable(volume);
    table.band *= scale;
    scaled.metadata["interfaces"] = table.toJson();
  }
  return scaled;
}

void bakeToVolumeFrame(BakeResult& result, LightSpec& light, double scale) {
  for (ReceiverMap& map : result.receivers) {
    map.point /= scale;
    map.origin /= scale;
    map.pitch /= scale;
  }
  light.position /= scale;
}

}  // namespace eik
