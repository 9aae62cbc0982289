#include "lightsim/scene_bake.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "core/interfaces.h"
#include "lightsim/receiver.h"

namespace eik {

BakeFrame BakeFrame::of(const SceneObjectSpec& object) {
  if (!object.uniformScale())
    throw std::invalid_argument("BakeFrame::of: an object scaled differently along its axes (takeInAxisScale first)");
  return of(objectToWorld(object));
}

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

Volume volumeAtWorldScale(const Volume& volume, const glm::dvec3& scale, std::vector<std::string>* dropped) {
  if (scale.x == scale.y && scale.y == scale.z) return volumeAtWorldScale(volume, scale.x);
  Volume scaled = volume;
  scaled.field_files.clear();  // the data changes: nothing is copied from the files read
  scaled.grid.bounds_min *= scale;
  scaled.grid.bounds_max *= scale;
  const auto perAxis = [](Field& field, const glm::dvec3& factor, bool renormalise) {
    if (field.components != 3) return;
    for (std::size_t i = 0; i + 2 < field.data.size(); i += 3) {
      glm::dvec3 v(field.data[i], field.data[i + 1], field.data[i + 2]);
      const double length = glm::length(v);
      v *= factor;
      if (renormalise && length > 0.0) v *= length / glm::length(v);
      for (int c = 0; c < 3; ++c) field.data[i + c] = static_cast<float>(v[c]);
    }
  };
  if (auto it = scaled.fields.find("ior_grad"); it != scaled.fields.end()) perAxis(it->second, 1.0 / scale, false);
  if (auto it = scaled.fields.find("light_dir"); it != scaled.fields.end()) perAxis(it->second, scale, true);
  const double shortest = std::min(scale.x, std::min(scale.y, scale.z));
  if (auto it = scaled.fields.find("interfaces"); it != scaled.fields.end()) {
    for (float& v : it->second.data) v = static_cast<float>(v * shortest);
    InterfaceTable table = interfaceTable(volume);
    table.band *= shortest;
    scaled.metadata["interfaces"] = table.toJson();
  }
  // A map's plane p = point + a·u + b·v goes to S·point + a·S·u + b·S·v: a square lattice again
  // when S·u and S·v are as long as each other and still perpendicular.
  std::vector<ReceiverMap> kept;
  for (ReceiverMap map : scaled.receivers) {
    const glm::dvec3 su = scale * map.u, sv = scale * map.v;
    const double stretch = glm::length(su);
    if (std::abs(glm::length(sv) - stretch) > 1e-9 * stretch || std::abs(glm::dot(su, sv)) > 1e-9 * stretch * stretch) {
      if (dropped) dropped->push_back(map.name);
      continue;
    }
    map.point *= scale;
    map.u = su / stretch;
    map.v = sv / stretch;
    map.normal = glm::normalize(map.normal / scale);
    map.origin *= stretch;
    map.pitch *= stretch;
    kept.push_back(std::move(map));
  }
  scaled.receivers = std::move(kept);
  // The light the volume was baked with, in its coordinates: a position to S·p, a direction along
  // S·d, a ball's radius × the mean stretch (an ellipsoid has none).
  const auto carryLight = [&](nlohmann::json& light) {
    if (!light.is_object()) return;
    const auto vec = [&](const char* key, bool direction) {
      const auto it = light.find(key);
      if (it == light.end() || !it->is_array() || it->size() != 3) return;
      glm::dvec3 v;
      for (int c = 0; c < 3; ++c) {
        if (!(*it)[c].is_number()) return;
        v[c] = (*it)[c].get<double>();
      }
      v *= scale;
      if (direction && glm::length(v) > 0.0) v = glm::normalize(v);
      *it = nlohmann::json::array({v.x, v.y, v.z});
    };
    vec("position", false);
    vec("direction", true);
    if (const auto it = light.find("radius"); it != light.end() && it->is_number())
      *it = it->get<double>() * std::cbrt(scale.x * scale.y * scale.z);
  };
  if (auto it = scaled.metadata.find("light"); it != scaled.metadata.end()) carryLight(*it);
  if (auto it = scaled.metadata.find("lights"); it != scaled.metadata.end() && it->is_array())
    for (nlohmann::json& light : *it) carryLight(light);
  return scaled;
}

bool takeInAxisScale(Volume& volume, SceneObjectSpec& object, const std::function<void(const std::string&)>& warn) {
  if (object.uniformScale()) return false;
  std::vector<std::string> dropped;
  volume = volumeAtWorldScale(volume, object.scale, &dropped);
  object.scale = glm::dvec3(1.0);
  if (warn)
    for (const std::string& map : dropped) warn(map);
  return true;
}

void bakeToVolumeFrame(BakeResult& result, LightSpec& light, double scale) {
  for (ReceiverMap& map : result.receivers) {
    map.point /= scale;
    map.origin /= scale;
    map.pitch /= scale;
  }
  light.position /= scale;
  light.radius /= scale;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double maxChannel(const glm::dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// A patch carried from one frame to another: corners by `to·x + shift`, directions by `to·w`.
Patch carried(const Patch& patch, const glm::dmat3& to, const glm::dvec3& shift) {
  Patch out = patch;
  for (int c = 0; c < 4; ++c) {
    out.x[c] = to * patch.x[c] + shift;
    out.w[c] = to * patch.w[c];
  }
  return out;
}
Patch toWorld(const Patch& patch, const BakeFrame& frame) { return carried(patch, frame.rotation, frame.origin); }
Patch toFrame(const Patch& patch, const BakeFrame& frame) {
  const glm::dmat3 to = glm::transpose(frame.rotation);
  return carried(patch, to, -(to * frame.origin));
}

// The box's corner k in the world.
glm::dvec3 worldCorner(const SceneLightChain::Object& o, int k) {
  const glm::dvec3 p((k & 1) ? o.hi.x : o.lo.x, (k & 2) ? o.hi.y : o.lo.y, (k & 4) ? o.hi.z : o.lo.z);
  return o.frame.origin + o.frame.rotation * p;
}

}  // namespace

SceneLightChain::SceneLightChain(std::vector<Object> objects, const LightSpec& world_light,
                                 std::optional<ReceiverSpec> ground, std::optional<LightSpec> order_light)
    : objects_(std::move(objects)), light_(world_light), ground_(std::move(ground)) {
  const LightSpec& by = order_light ? *order_light : light_;
  const std::size_t n = objects_.size();
  std::vector<double> key(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const Object& o = objects_[k];
    if (by.type == LightSpec::Type::Directional) {
      const glm::dvec3 L = glm::normalize(by.direction);
      key[k] = kInf;
      for (int c = 0; c < 8; ++c) key[k] = std::min(key[k], glm::dot(worldCorner(o, c), L));
    } else {
      const glm::dvec3 p = glm::transpose(o.frame.rotation) * (by.position - o.frame.origin);
      key[k] = glm::length(p - glm::clamp(p, o.lo, o.hi));
    }
  }
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), std::size_t{0});
  std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  rank_.resize(n);
  for (std::size_t r = 0; r < n; ++r) rank_[order_[r]] = r;
  inbox_.resize(n);
  left_out_.resize(n);
  taken_in_.resize(n);
  exchange_.resize(n);
}

bool SceneLightChain::overlap(std::size_t a, std::size_t b) const {
  // Separating axes of two oriented boxes: the 3 + 3 face normals and their 9 cross products.
  const Object& A = objects_[a];
  const Object& B = objects_[b];
  const glm::dvec3 ca = A.frame.origin + A.frame.rotation * (0.5 * (A.lo + A.hi));
  const glm::dvec3 cb = B.frame.origin + B.frame.rotation * (0.5 * (B.lo + B.hi));
  const glm::dvec3 ea = 0.5 * (A.hi - A.lo), eb = 0.5 * (B.hi - B.lo);
  auto radius = [](const Object& o, const glm::dvec3& e, const glm::dvec3& axis) {
    return e.x * std::fabs(glm::dot(o.frame.rotation[0], axis)) + e.y * std::fabs(glm::dot(o.frame.rotation[1], axis)) +
           e.z * std::fabs(glm::dot(o.frame.rotation[2], axis));
  };
  auto separates = [&](const glm::dvec3& axis) {
    if (glm::dot(axis, axis) < 1e-18) return false;  // parallel edges: covered by the face normals
    return std::fabs(glm::dot(cb - ca, axis)) > radius(A, ea, axis) + radius(B, eb, axis);
  };
  for (int i = 0; i < 3; ++i) {
    if (separates(A.frame.rotation[i]) || separates(B.frame.rotation[i])) return false;
    for (int j = 0; j < 3; ++j)
      if (separates(glm::cross(A.frame.rotation[i], B.frame.rotation[j]))) return false;
  }
  return true;
}

bool SceneLightChain::lineThroughBox(std::size_t k, const glm::dvec3& origin, const glm::dvec3& dir, double& t_near,
                                     double& t_far) const {
  const Object& o = objects_[k];
  const glm::dmat3 to = glm::transpose(o.frame.rotation);
  const glm::dvec3 p = to * (origin - o.frame.origin), d = to * dir;
  t_near = -kInf;
  t_far = kInf;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (p[a] < o.lo[a] || p[a] > o.hi[a]) return false;
      continue;
    }
    double t1 = (o.lo[a] - p[a]) / d[a], t2 = (o.hi[a] - p[a]) / d[a];
    if (t1 > t2) std::swap(t1, t2);
    t_near = std::max(t_near, t1);
    t_far = std::min(t_far, t2);
    if (t_near > t_far) return false;
  }
  return true;
}

void SceneLightChain::attach(std::size_t k, SimulationOptions& options) {
  const std::size_t rank = rank_[k];
  options.initial_patches = [this, k, rank](std::vector<Patch>& patches, const VolumeSampler& sampler) {
    const Object& self = objects_[k];
    Exchange& exchange = exchange_[k];
    // The light's cells an earlier object's box meets first.
    const bool directional = light_.type == LightSpec::Type::Directional;
    std::vector<std::size_t> earlier;
    for (std::size_t r = 0; r < rank; ++r)
      if (!overlap(order_[r], k)) earlier.push_back(order_[r]);
    if (!earlier.empty()) {
      std::vector<Patch> kept;
      kept.reserve(patches.size());
      for (const Patch& cell : patches) {
        const glm::dvec3 m = self.frame.origin + self.frame.rotation * cell.midpoint();
        // A sun's cell along its line; a point light's along the segment from the light (t in [0, 1]).
        const glm::dvec3 origin = directional ? m : light_.position;
        const glm::dvec3 dir = directional ? glm::normalize(light_.direction) : m - light_.position;
        double own_near = kInf, own_far = kInf;
        if (!lineThroughBox(k, origin, dir, own_near, own_far)) own_near = kInf;
        bool shaded = false;
        for (const std::size_t j : earlier) {
          double t_near, t_far;
          if (lineThroughBox(j, origin, dir, t_near, t_far) && t_far <= own_near && (directional || t_far > 0.0)) {
            shaded = true;
            break;
          }
        }
        if (shaded) {
          ++exchange.left_out;
          exchange.flux_left_out += cell.flux;
          left_out_[k].push_back(cell);
        } else {
          kept.push_back(cell);
        }
      }
      patches.swap(kept);
    }
    // The patches earlier objects sent here, flown to half a voxel before the box; those dimmer than
    // kDimHandOn of the light's brightest irradiance on the box go on through it unchanged (they
    // stay on the sender's map, and this object's map does not take them away).
    const double dim = kDimHandOn * brightestIrradiance(self.frame.light(light_), sampler.grid());
    for (const Patch& sent : inbox_[k]) {
      Patch p = toFrame(sent, self.frame);
      if (maxChannel(p.irradiance()) < dim) {
        ++exchange.passed;
        exchange.flux_passed += p.flux;
        continue;
      }
      // In the bake frame the box is axis-aligned: where the midpoint's ray enters it.
      const glm::dvec3 m = p.midpoint(), d = p.direction();
      double t_near = -kInf;
      for (int a = 0; a < 3; ++a)
        if (d[a] != 0.0) t_near = std::max(t_near, std::min((self.lo[a] - m[a]) / d[a], (self.hi[a] - m[a]) / d[a]));
      const double s = std::max(0.0, t_near - 0.5 * self.h);
      for (int c = 0; c < 4; ++c) {
        const glm::dvec3 w = glm::normalize(p.w[c]);
        p.x[c] += s * w;  // straight, in air (|w| = n = 1 there)
        p.medium[c] = sampler.materialAt(p.x[c]);
        p.w[c] = w * sampler.materialOptics(p.medium[c], p.x[c]).x;
      }
      p.area0 = p.area();
      p.depth = 0.0;  // free to split again in this object
      p.n_in = p.cos_in = 0.0;
      p.t_fresnel = 1.0;
      p.reflect_pending = 0.0;
      p.crossed = p.reflected = p.reflections = 0;
      ++exchange.taken_in;
      exchange.flux_in += p.flux;
      patches.push_back(p);
      taken_in_[k].push_back(p);
    }
    inbox_[k].clear();
    inbox_[k].shrink_to_fit();
  };
  if (rank + 1 == order_.size()) return;
  // The patches that leave the box towards a later object's box, first along their rays.
  std::vector<std::size_t> others;
  for (std::size_t j = 0; j < objects_.size(); ++j)
    if (j != k && !overlap(j, k)) others.push_back(j);
  options.on_leave = [this, k, others](const Patch& patch) {
    // A patch may leave in a free flight that takes it far past its box (to the ground): it is taken
    // back along its corners' straight rays (in air) to where its midpoint's ray left the box.
    Patch back = patch;
    double t_near, t_far;
    if (lineThroughBox(k, objects_[k].frame.origin + objects_[k].frame.rotation * patch.midpoint(),
                       objects_[k].frame.rotation * patch.direction(), t_near, t_far) &&
        t_far < 0.0)
      for (int c = 0; c < 4; ++c) back.x[c] += t_far * glm::normalize(back.w[c]);
    const Patch world = toWorld(back, objects_[k].frame);
    const glm::dvec3 m = world.midpoint(), d = world.direction();
    double nearest = kInf;
    std::size_t to = k;
    for (const std::size_t j : others) {
      if (!lineThroughBox(j, m, d, t_near, t_far) || t_far < 0.0) continue;
      const double t = std::max(0.0, t_near);
      if (t < nearest) {
        nearest = t;
        to = j;
      }
    }
    if (to == k || rank_[to] < rank_[k]) return;  // nothing ahead, or light sent back (not followed)
    if (ground_) {
      const double facing = glm::dot(d, ground_->normal);
      if (facing < 0.0 && -glm::dot(m - ground_->point, ground_->normal) / facing < nearest) return;  // the ground first
    }
    inbox_[to].push_back(world);
  };
}

SceneLightChain::Exchange& SceneLightChain::Exchange::operator+=(const Exchange& o) {
  taken_in += o.taken_in;
  left_out += o.left_out;
  passed += o.passed;
  flux_in += o.flux_in;
  flux_left_out += o.flux_left_out;
  flux_passed += o.flux_passed;
  return *this;
}

void SceneLightChain::correctMap(std::size_t k, BakeResult& result) {
  if (!result.receivers.empty()) {
    ReceiverMap& map = result.receivers.front();
    map.makeRgb();  // the corrections may be coloured (applyBake makes it grey again where it stays so)
    std::vector<glm::dvec3> flux(map.texelCount(), glm::dvec3(0.0));
    std::array<glm::dvec2, 4> footprint;
    for (const Patch& p : left_out_[k])
      if (patchFootprint(p, map, footprint)) depositFootprint(map, footprint, p.flux, flux);
    for (const Patch& p : taken_in_[k])
      if (patchFootprint(p, map, footprint)) depositFootprint(map, footprint, -p.flux, flux);
    const double inv_area = 1.0 / (map.pitch * map.pitch);
    for (std::size_t t = 0; t < flux.size(); ++t)
      for (int c = 0; c < 3; ++c) {
        float& e = map.irradiance[3 * t + static_cast<std::size_t>(c)];
        e = std::max(0.0f, static_cast<float>(e + flux[t][c] * inv_area));
      }
  }
  left_out_[k] = {};
  taken_in_[k] = {};
}

}  // namespace eik
