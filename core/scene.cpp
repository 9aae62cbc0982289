#include "core/scene.h"

#include "core/limits.h"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/paths.h"
#include "core/json_input.h"

namespace eik {
namespace {

using nlohmann::json;

// Strict reader of one JSON object: every key must be known, every value of the right type.
class ObjectReader {
 public:
  ObjectReader(const json& j, std::string source, std::string path, std::initializer_list<const char*> keys)
      : j_(j), source_(std::move(source)), path_(std::move(path)) {
    if (!j.is_object()) fail(path_, "expected an object, got " + std::string(j.type_name()));
    std::set<std::string> allowed(keys.begin(), keys.end());
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (!allowed.count(it.key())) {
        std::string list;
        for (const auto& k : allowed) list += (list.empty() ? "" : ", ") + k;
        fail(child(it.key()), "unknown key (expected one of: " + list + ")");
      }
    }
  }

  bool has(const char* key) const { return j_.contains(key); }
  const json& at(const char* key) const { return j_.at(key); }
  std::string child(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError(source_, field, what);
  }

  double number(const char* key, double fallback) const {
    if (!has(key)) return fallback;
    const json& v = at(key);
    if (!v.is_number()) fail(child(key), "expected a number, got " + std::string(v.type_name()));
    double d = v.get<double>();
    if (!std::isfinite(d)) fail(child(key), "not a finite number");
    if (!finiteAsFloat(d)) fail(child(key), "beyond the range of a 32-bit float");
    return d;
  }

  std::string string(const char* key, const std::string& fallback) const {
    if (!has(key)) return fallback;
    const json& v = at(key);
    if (!v.is_string()) fail(child(key), "expected a string, got " + std::string(v.type_name()));
    return v.get<std::string>();
  }

  glm::dvec3 vec3(const char* key, const glm::dvec3& fallback) const {
    if (!has(key)) return fallback;
    const json& v = at(key);
    if (!v.is_array() || v.size() != 3) fail(child(key), "expected an array of 3 numbers");
    glm::dvec3 out;
    for (int i = 0; i < 3; ++i) {
      if (!v[static_cast<std::size_t>(i)].is_number()) fail(child(key), "expected an array of 3 numbers");
      out[i] = v[static_cast<std::size_t>(i)].get<double>();
      if (!std::isfinite(out[i])) fail(child(key), "not a finite number");
      if (!finiteAsFloat(out[i])) fail(child(key), "beyond the range of a 32-bit float");
    }
    return out;
  }

  glm::ivec2 ivec2(const char* key, const glm::ivec2& fallback) const {
    if (!has(key)) return fallback;
    const json& v = at(key);
    if (!v.is_array() || v.size() != 2 || !v[0].is_number_integer() || !v[1].is_number_integer())
      fail(child(key), "expected an array of 2 integers");
    // Read as 64-bit and range-checked: get<int>() would wrap 4294967312 to 16.
    for (int i = 0; i < 2; ++i) {
      const bool fits = v[i].is_number_unsigned() ? v[i].get<std::uint64_t>() <= 0x7fffffffu
                                                   : v[i].get<std::int64_t>() >= -0x7fffffffLL - 1;
      if (!fits) fail(child(key), "has a value out of the integer range");
    }
    return {v[0].get<int>(), v[1].get<int>()};
  }

  const std::string& source() const { return source_; }

 private:
  const json& j_;
  std::string source_;
  std::string path_;
};

glm::dvec3 requireUnit(const ObjectReader& r, const char* key, const glm::dvec3& v) {
  double len = glm::length(v);
  if (!(len > 1e-12)) r.fail(r.child(key), "must not be the zero vector");
  return v / len;
}

void requireNonNegative(const ObjectReader& r, const char* key, const glm::dvec3& v) {
  if (v.x < 0 || v.y < 0 || v.z < 0) r.fail(r.child(key), "must not be negative");
}

void requireLightPower(const ObjectReader& r, const char* key, const glm::dvec3& v) {
  if (std::max(v.x, std::max(v.y, v.z)) > kMaxLightPower)
    r.fail(r.child(key), "must be at most 1e30 (bakes store 32-bit floats, which a caustic would overflow)");
}

}  // namespace

std::filesystem::path Scene::resolve(const std::string& key, const std::string& named) const {
  if (!file.empty()) return resolveInsideFolder(file, key, named);
  std::filesystem::path p(named);
  return p.is_absolute() ? p : base_dir / p;
}

glm::dmat4 objectToWorld(const SceneObjectSpec& o) {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), o.translate);
  m = glm::rotate(m, glm::radians(o.rotate_deg.z), glm::dvec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(o.rotate_deg.y), glm::dvec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(o.rotate_deg.x), glm::dvec3(1, 0, 0));
  return glm::scale(m, o.scale);
}

Scene sceneFromJson(const json& j, const std::string& source) {
  Scene scene;
  ObjectReader top(j, source, "", {"camera", "environment", "lights", "ground", "objects", "render", "comment"});

  if (top.has("camera")) {
    ObjectReader r(top.at("camera"), source, "camera", {"eye", "target", "up", "fov_y_deg"});
    scene.camera.eye = r.vec3("eye", scene.camera.eye);
    scene.camera.target = r.vec3("target", scene.camera.target);
    scene.camera.up = requireUnit(r, "up", r.vec3("up", scene.camera.up));
    scene.camera.fov_y_deg = r.number("fov_y_deg", scene.camera.fov_y_deg);
    if (!(scene.camera.fov_y_deg > 0 && scene.camera.fov_y_deg < 180)) r.fail("camera.fov_y_deg", "must be in (0, 180)");
    if (glm::length(scene.camera.target - scene.camera.eye) < 1e-12) r.fail("camera.target", "equals the eye");
  }

  if (top.has("environment")) {
    ObjectReader r(top.at("environment"), source, "environment", {"uniform", "file", "intensity", "rotate_deg", "procedural"});
    int kinds = int(r.has("uniform")) + int(r.has("file")) + int(r.has("procedural"));
    if (kinds > 1) r.fail("environment", "give only one of uniform, file, procedural");
    scene.environment.file = r.string("file", "");
    scene.environment.procedural = r.string("procedural", "");
    if (r.has("uniform")) {
      scene.environment.uniform = r.vec3("uniform", glm::dvec3(0.0));
      requireNonNegative(r, "uniform", *scene.environment.uniform);
    } else if (kinds == 1) {
      scene.environment.uniform.reset();
    }
    scene.environment.intensity = r.number("intensity", 1.0);
    scene.environment.rotate_deg = r.number("rotate_deg", 0.0);
    if (scene.environment.intensity < 0) r.fail("environment.intensity", "must not be negative");
  }

  if (top.has("lights")) {
    const json& lights = top.at("lights");
    if (!lights.is_array()) top.fail("lights", "expected an array");
    for (std::size_t i = 0; i < lights.size(); ++i) {
      std::string path = "lights[" + std::to_string(i) + "]";
      ObjectReader r(lights[i], source, path,
                     {"type", "direction", "irradiance", "position", "intensity", "inner_cone_deg", "outer_cone_deg",
                      "angular_diameter_deg", "radius", "name"});
      SceneLightSpec light;
      std::string type = r.string("type", "");
      if (type == "directional") {
        light.type = SceneLightSpec::Type::Directional;
        light.direction = requireUnit(r, "direction", r.vec3("direction", light.direction));
        light.irradiance = r.vec3("irradiance", light.irradiance);
        requireNonNegative(r, "irradiance", light.irradiance);
        requireLightPower(r, "irradiance", light.irradiance);
        light.angular_diameter_deg = r.number("angular_diameter_deg", 0.0);
        if (!(light.angular_diameter_deg >= 0.0 && light.angular_diameter_deg <= kMaxAngularDiameterDeg))
          r.fail(path + ".angular_diameter_deg", "must be in [0, 20] degrees");
        if (r.has("position") || r.has("intensity")) r.fail(path, "a directional light takes direction and irradiance");
      } else if (type == "point") {
        light.type = SceneLightSpec::Type::Point;
        if (!r.has("position")) r.fail(path + ".position", "missing");
        light.position = r.vec3("position", light.position);
        light.intensity = r.vec3("intensity", light.intensity);
        requireNonNegative(r, "intensity", light.intensity);
        requireLightPower(r, "intensity", light.intensity);
        if (r.has("direction") || r.has("irradiance")) r.fail(path, "a point light takes position and intensity");
      } else if (type == "spot") {
        light.type = SceneLightSpec::Type::Spot;
        if (!r.has("position")) r.fail(path + ".position", "missing");
        if (!r.has("direction")) r.fail(path + ".direction", "missing");
        light.position = r.vec3("position", light.position);
        light.direction = requireUnit(r, "direction", r.vec3("direction", light.direction));
        light.intensity = r.vec3("intensity", light.intensity);
        requireNonNegative(r, "intensity", light.intensity);
        requireLightPower(r, "intensity", light.intensity);
        light.inner_cone_deg = r.number("inner_cone_deg", light.inner_cone_deg);
        light.outer_cone_deg = r.number("outer_cone_deg", light.outer_cone_deg);
        if (!(light.outer_cone_deg > 0.0 && light.outer_cone_deg <= 90.0))
          r.fail(path + ".outer_cone_deg", "must be in (0, 90]");
        if (!(light.inner_cone_deg >= 0.0 && light.inner_cone_deg < light.outer_cone_deg))
          r.fail(path + ".inner_cone_deg", "must be in [0, outer_cone_deg)");
        if (r.has("irradiance")) r.fail(path, "a spot light takes position, direction, intensity and its cone");
      } else {
        r.fail(path + ".type", "expected \"directional\", \"point\" or \"spot\", got \"" + type + "\"");
      }
      if (light.type != SceneLightSpec::Type::Spot && (r.has("inner_cone_deg") || r.has("outer_cone_deg")))
        r.fail(path, "only a spot light has a cone");
      if (light.type != SceneLightSpec::Type::Directional && r.has("angular_diameter_deg"))
        r.fail(path, "only a directional light has an angular diameter (a point or spot light has a radius)");
      if (r.has("radius")) {
        if (light.type == SceneLightSpec::Type::Directional)
          r.fail(path, "only a point or spot light has a radius (a directional light has an angular diameter)");
        light.radius = r.number("radius", 0.0);
        if (!(light.radius >= 0.0 && light.radius <= kMaxLightRadius)) r.fail(path + ".radius", "must be in [0, 1000]");
      }
      scene.lights.push_back(light);
    }
  }

  if (top.has("ground") && !top.at("ground").is_null()) {
    ObjectReader r(top.at("ground"), source, "ground", {"point", "normal", "albedo", "half_extent"});
    SceneGroundSpec g;
    g.point = r.vec3("point", g.point);
    g.normal = requireUnit(r, "normal", r.vec3("normal", g.normal));
    g.albedo = r.vec3("albedo", g.albedo);
    requireNonNegative(r, "albedo", g.albedo);
    g.half_extent = r.number("half_extent", g.half_extent);
    if (!(g.half_extent > 0)) r.fail("ground.half_extent", "must be positive");
    scene.ground = g;
  }

  if (top.has("objects")) {
    const json& objects = top.at("objects");
    if (!objects.is_array()) top.fail("objects", "expected an array");
    for (std::size_t i = 0; i < objects.size(); ++i) {
      std::string path = "objects[" + std::to_string(i) + "]";
      ObjectReader r(objects[i], source, path, {"volume", "translate", "rotate_deg", "scale", "name"});
      SceneObjectSpec o;
      if (!r.has("volume")) r.fail(path + ".volume", "missing");
      o.volume = r.string("volume", "");
      o.translate = r.vec3("translate", o.translate);
      o.rotate_deg = r.vec3("rotate_deg", o.rotate_deg);
      // One number (uniform) or [x, y, z] along the volume's own axes.
      o.scale = r.has("scale") && r.at("scale").is_array() ? r.vec3("scale", o.scale) : glm::dvec3(r.number("scale", 1.0));
      if (!(o.scale.x > 0 && o.scale.y > 0 && o.scale.z > 0)) r.fail(path + ".scale", "must be positive");
      scene.objects.push_back(o);
    }
  }

  if (top.has("render")) {
    ObjectReader r(top.at("render"), source, "render", {"size", "step_voxels", "exposure", "tonemap"});
    scene.render.size = r.ivec2("size", scene.render.size);
    if (scene.render.size.x < 1 || scene.render.size.y < 1 || scene.render.size.x > 16384 || scene.render.size.y > 16384)
      r.fail("render.size", "must be between 1 and 16384 pixels per axis");
    scene.render.step_voxels = r.number("step_voxels", scene.render.step_voxels);
    if (!(scene.render.step_voxels >= 0.01 && scene.render.step_voxels <= 4.0))
      r.fail("render.step_voxels", "must be between 0.01 and 4 (as viewer --step)");
    scene.render.exposure = r.number("exposure", 0.0);
    scene.render.tonemap = r.string("tonemap", scene.render.tonemap);
    if (scene.render.tonemap != "aces" && scene.render.tonemap != "reinhard" && scene.render.tonemap != "linear")
      r.fail("render.tonemap", "expected \"aces\", \"reinhard\" or \"linear\"");
  }
  return scene;
}

Scene readScene(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  const json j = parseJsonInput(text.str(), file.string());
  Scene scene = sceneFromJson(j, file.string());
  scene.base_dir = std::filesystem::absolute(file).parent_path();
  scene.file = file;
  return scene;
}

namespace {
json toJson(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }
}  // namespace

json sceneToJson(const Scene& s) {
  json j;
  j["camera"] = {{"eye", toJson(s.camera.eye)},
                 {"target", toJson(s.camera.target)},
                 {"up", toJson(s.camera.up)},
                 {"fov_y_deg", s.camera.fov_y_deg}};
  json env = json::object();
  if (!s.environment.file.empty())
    env["file"] = s.environment.file;
  else if (!s.environment.procedural.empty())
    env["procedural"] = s.environment.procedural;
  else if (s.environment.uniform)
    env["uniform"] = toJson(*s.environment.uniform);
  if (s.environment.intensity != 1.0) env["intensity"] = s.environment.intensity;
  if (s.environment.rotate_deg != 0.0) env["rotate_deg"] = s.environment.rotate_deg;
  j["environment"] = env;
  j["lights"] = json::array();
  for (const auto& l : s.lights) {
    if (l.type == SceneLightSpec::Type::Directional) {
      json d = {{"type", "directional"}, {"direction", toJson(l.direction)}, {"irradiance", toJson(l.irradiance)}};
      if (l.angular_diameter_deg > 0.0) d["angular_diameter_deg"] = l.angular_diameter_deg;
      j["lights"].push_back(d);
    } else if (l.type == SceneLightSpec::Type::Point) {
      j["lights"].push_back({{"type", "point"}, {"position", toJson(l.position)}, {"intensity", toJson(l.intensity)}});
    } else {
      j["lights"].push_back({{"type", "spot"},
                             {"position", toJson(l.position)},
                             {"direction", toJson(l.direction)},
                             {"intensity", toJson(l.intensity)},
                             {"inner_cone_deg", l.inner_cone_deg},
                             {"outer_cone_deg", l.outer_cone_deg}});
    }
    if (l.type != SceneLightSpec::Type::Directional && l.radius > 0.0) j["lights"].back()["radius"] = l.radius;
  }
  if (s.ground)
    j["ground"] = {{"point", toJson(s.ground->point)},
                   {"normal", toJson(s.ground->normal)},
                   {"albedo", toJson(s.ground->albedo)},
                   {"half_extent", s.ground->half_extent}};
  j["objects"] = json::array();
  for (const auto& o : s.objects)
    j["objects"].push_back({{"volume", o.volume},
                            {"translate", toJson(o.translate)},
                            {"rotate_deg", toJson(o.rotate_deg)},
                            {"scale", o.uniformScale() ? json(o.scale.x) : toJson(o.scale)}});
  j["render"] = {{"size", {s.render.size.x, s.render.size.y}},
                 {"step_voxels", s.render.step_voxels},
                 {"exposure", s.render.exposure},
                 {"tonemap", s.render.tonemap}};
  return j;
}

void writeScene(const Scene& scene, const std::filesystem::path& file) {
  writeFileAtomic(file, sceneToJson(scene).dump(2) + "\n");
}

}  // namespace eik
