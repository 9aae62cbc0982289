// What a bake adds to a volume, and reading the light to bake (see bake.h).
#include "lightsim/bake.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "core/gaussian_filter.h"
#include "core/scene.h"
#include "lightsim/wavefront.h"

namespace eik {

namespace {

nlohmann::json vec3Json(const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

// Comma-separated finite numbers; InputError naming `source` otherwise.
std::vector<double> parseNumbers(const std::string& text, const std::string& source, const std::string& what) {
  std::vector<double> values;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const char* begin = item.c_str();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(begin, &end);
    while (end && (*end == ' ' || *end == '\t')) ++end;
    if (item.empty() || end == begin || *end != '\0' || errno == ERANGE || !std::isfinite(v))
      throw InputError(source, what, "'" + item + "' is not a finite number (in '" + text + "')");
    values.push_back(v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return values;
}

}  // namespace

nlohmann::json LightSpec::toJson() const {
  if (type == Type::Directional) {
    nlohmann::json j = {{"type", "directional"}, {"direction", vec3Json(direction)}, {"irradiance", vec3Json(power)}};
    if (angular_diameter_deg > 0.0) j["angular_diameter_deg"] = angular_diameter_deg;
    return j;
  }
  nlohmann::json j = {{"type", "point"}, {"position", vec3Json(position)}, {"intensity", vec3Json(power)}};
  if (type == Type::Spot)
    j = {{"type", "spot"},
         {"position", vec3Json(position)},
         {"direction", vec3Json(direction)},
         {"intensity", vec3Json(power)},
         {"inner_cone_deg", inner_cone_deg},
         {"outer_cone_deg", outer_cone_deg}};
  if (radius > 0.0) j["radius"] = radius;
  return j;
}

double LightSpec::attenuation(const glm::dvec3& dir) const {
  if (type != Type::Spot) return 1.0;
  return spotAttenuation(glm::dot(glm::normalize(direction), dir), std::cos(glm::radians(inner_cone_deg)),
                         std::cos(glm::radians(outer_cone_deg)));
}

double SimulationStats::ledgerResidual() const {
  const glm::dvec3 accounted =
      flux_out + flux_absorbed + flux_reflected + flux_killed + flux_unfinished + flux_received + flux_blocked;
  const double scale = std::max(std::fabs(flux_in.x), std::max(std::fabs(flux_in.y), std::fabs(flux_in.z)));
  const glm::dvec3 residual = flux_in - accounted;
  const double worst = std::max(std::fabs(residual.x), std::max(std::fabs(residual.y), std::fabs(residual.z)));
  return scale > 0.0 ? worst / scale : 0.0;
}

nlohmann::json SimulationStats::toJson() const {
  nlohmann::json j;
  j["steps"] = steps;
  j["initial_patches"] = initial_patches;
  j["peak_patches"] = peak_patches;
  j["total_patches"] = total_patches;
  j["splits"] = splits;
  j["kills"] = {{"flux", kills.flux},         {"exited", kills.exited},     {"folded", kills.folded},
                {"depth", kills.depth},       {"received", kills.received}, {"blocked", kills.blocked},
                {"trapped", kills.trapped}};
  j["reflections"] = reflections;
  j["rollbacks"] = rollbacks;
  j["flights"] = flights;
  if (!patch_steps_by_bounce.empty()) j["patch_steps_by_bounce"] = patch_steps_by_bounce;
  if (!flux_received_by_bounce.empty()) {
    nlohmann::json orders = nlohmann::json::array();
    for (const glm::dvec3& f : flux_received_by_bounce) orders.push_back(vec3Json(f));
    j["flux_received_by_bounce"] = std::move(orders);
  }
  // The energy ledger: flux_in = out + absorbed + reflected + killed + unfinished + received +
  // blocked (W, RGB).
  j["flux"] = {{"in", vec3Json(flux_in)},
               {"out", vec3Json(flux_out)},
               {"absorbed", vec3Json(flux_absorbed)},
               {"reflected", vec3Json(flux_reflected)},
               {"killed", vec3Json(flux_killed)},
               {"unfinished", vec3Json(flux_unfinished)},
               {"received", vec3Json(flux_received)},
               {"blocked", vec3Json(flux_blocked)},
               {"ledger_relative_residual", ledgerResidual()}};
  j["phase_seconds"] = nlohmann::json::object();
  for (const auto& [name, seconds] : phase_seconds) j["phase_seconds"][name] = seconds;
  j["backend"] = backend;
  j["renderer"] = renderer;
  if (!simd.empty()) j["simd"] = simd;
  nlohmann::json warnings = nlohmann::json::array();
  if (initial_patches == 0) warnings.push_back("the light misses the volume: the bake is empty");
  if (flux_unfinished.x + flux_unfinished.y + flux_unfinished.z > 0.0)
    warnings.push_back("max_steps reached with patches still alive (flux_unfinished)");
  j["warnings"] = warnings;
  return j;
}

void applyBake(Volume& volume, BakeResult&& result, const LightSpec& light) {
  const std::size_t n = volume.grid.count();
  auto check = [n](const Field& f, const char* name) {
    if (f.components != 3 || f.data.size() != n * 3)
      throw std::invalid_argument(std::string("applyBake: ") + name + " does not match the volume's grid");
  };
  if (result.irradiance.data.empty() && result.light_dir.data.empty()) {
    // A bake without volume deposits: none of an earlier bake's fields may stay behind.
    volume.fields.erase("irradiance");
    volume.fields.erase("light_dir");
  } else {
    check(result.irradiance, "irradiance");
    check(result.light_dir, "light_dir");
    volume.fields["irradiance"] = std::move(result.irradiance);
    volume.fields["light_dir"] = std::move(result.light_dir);
  }
  volume.receivers = std::move(result.receivers);
  // A map whose three channels agree everywhere (a white light through clear glass) is kept grey:
  // a third of its memory, of its file and of what the viewer reads (ReceiverMap::makeGrey).
  for (ReceiverMap& map : volume.receivers) map.makeGrey();
  volume.metadata["light"] = light.toJson();
  volume.metadata.erase("lights");
  volume.metadata["bake_stats"] = result.stats.toJson();
}

void applyBake(Volume& volume, BakeResult&& result, const std::vector<LightSpec>& lights) {
  applyBake(volume, std::move(result), lights.at(0));
  if (lights.size() < 2) return;
  nlohmann::json all = nlohmann::json::array();
  for (const LightSpec& light : lights) all.push_back(light.toJson());
  volume.metadata["lights"] = all;
}

void applyBake(Volume& volume, const BakeResult& result, const LightSpec& light) {
  BakeResult copy = result;
  applyBake(volume, std::move(copy), light);
}

void applyBake(Volume& volume, const BakeResult& result, const std::vector<LightSpec>& lights) {
  BakeResult copy = result;
  applyBake(volume, std::move(copy), lights);
}

bool viewerReadsVolumeLight(const Volume& volume, bool receiver_map) {
  if (!receiver_map) return true;
  // Any voxel whose component `channel` of `name` is non-zero.
  auto anyNonZero = [&](const char* name, int channel) {
    const Field* f = volume.find(name);
    if (!f || channel >= f->components) return false;
    for (std::size_t i = static_cast<std::size_t>(channel); i < f->data.size(); i += static_cast<std::size_t>(f->components))
      if (f->data[i] != 0.0f) return true;
    return false;
  };
  return anyNonZero("scatter", 0) || anyNonZero("opaque", 3);
}

nlohmann::json bakeOptionsToJson(const SimulationOptions& o) {
  nlohmann::json j;
  j["deposit"] = o.deposit == DepositMode::Max ? "max" : "accumulate";
  j["deposit_kernel"] = o.deposit_kernel == DepositKernel::Point ? "point" : "track";
  j["bounces"] = o.bounces;
  j["integrator"] = o.integrator == Integrator::RK4 ? "rk4" : o.integrator == Integrator::RK2 ? "rk2" : "euler";
  j["step_voxels"] = o.step_voxels;
  j["patch_voxels"] = o.patch_voxels;
  j["split_voxels"] = o.split_voxels;
  j["split_rule"] = o.split_rule == SplitRule::Quad ? "quad" : "axis";
  j["max_depth"] = o.max_depth;
  j["at_max_depth"] = o.at_max_depth == DepthLimit::Kill ? "kill" : "keep";
  j["flux_threshold"] = o.flux_threshold;
  j["max_steps"] = o.max_steps;
  j["free_flight"] = o.free_flight;
  j["volume_deposits"] = o.volume_deposits;
  j["straight_step_voxels"] = o.straight_step_voxels;
  j["boundary_on"] = o.boundary_on;
  j["boundary_off"] = o.boundary_off;
  if (o.receiver) {
    const ReceiverSpec& r = *o.receiver;
    j["receiver"] = {{"name", r.name},
                     {"point", vec3Json(r.point)},
                     {"normal", vec3Json(r.normal)},
                     {"half_extent", r.half_extent},
                     {"pitch_voxels", r.pitch_voxels}};
  }
  return j;
}

SimulationOptions bakeOptionsFromJson(const nlohmann::json& j, const std::string& source, SimulationOptions o) {
  if (!j.is_object()) throw InputError(source, "bake_options", "expected an object");
  auto where = [](const std::string& key) { return "bake_options." + key; };
  auto number = [&](const nlohmann::json& in, const std::string& key, double& out, const std::string& path) {
    if (!in.contains(key)) return;
    const nlohmann::json& v = in.at(key);
    if (!v.is_number() || !std::isfinite(v.get<double>())) throw InputError(source, path, "expected a finite number");
    out = v.get<double>();
  };
  auto integer = [&](const std::string& key, int& out) {
    if (!j.contains(key)) return;
    const nlohmann::json& v = j.at(key);
    if (!v.is_number_integer() || v.get<std::int64_t>() < -1000000000 || v.get<std::int64_t>() > 1000000000)
      throw InputError(source, where(key), "expected an integer");
    out = v.get<int>();
  };
  auto choice = [&](const std::string& key, std::initializer_list<const char*> names) -> int {
    if (!j.contains(key)) return -1;
    const nlohmann::json& v = j.at(key);
    int index = 0;
    for (const char* name : names) {
      if (v.is_string() && v.get<std::string>() == name) return index;
      ++index;
    }
    throw InputError(source, where(key), "unknown value " + v.dump(-1, ' ', true));
  };
  if (int c = choice("deposit", {"accumulate", "max"}); c >= 0) o.deposit = c ? DepositMode::Max : DepositMode::Accumulate;
  if (int c = choice("deposit_kernel", {"track", "point"}); c >= 0)
    o.deposit_kernel = c ? DepositKernel::Point : DepositKernel::Track;
  if (int c = choice("integrator", {"euler", "rk2", "rk4"}); c >= 0)
    o.integrator = c == 2 ? Integrator::RK4 : c == 1 ? Integrator::RK2 : Integrator::Euler;
  if (int c = choice("split_rule", {"axis", "quad"}); c >= 0) o.split_rule = c ? SplitRule::Quad : SplitRule::Axis;
  if (int c = choice("at_max_depth", {"keep", "kill"}); c >= 0) o.at_max_depth = c ? DepthLimit::Kill : DepthLimit::Keep;
  integer("bounces", o.bounces);
  integer("max_depth", o.max_depth);
  integer("max_steps", o.max_steps);
  number(j, "step_voxels", o.step_voxels, where("step_voxels"));
  number(j, "patch_voxels", o.patch_voxels, where("patch_voxels"));
  number(j, "split_voxels", o.split_voxels, where("split_voxels"));
  number(j, "straight_step_voxels", o.straight_step_voxels, where("straight_step_voxels"));
  number(j, "flux_threshold", o.flux_threshold, where("flux_threshold"));
  number(j, "boundary_on", o.boundary_on, where("boundary_on"));
  number(j, "boundary_off", o.boundary_off, where("boundary_off"));
  auto boolean = [&](const std::string& key, bool& out) {
    if (!j.contains(key)) return;
    if (!j.at(key).is_boolean()) throw InputError(source, where(key), "expected true or false");
    out = j.at(key).get<bool>();
  };
  boolean("free_flight", o.free_flight);
  boolean("volume_deposits", o.volume_deposits);
  if (j.contains("receiver")) {
    const nlohmann::json& r = j.at("receiver");
    if (!r.is_object()) throw InputError(source, where("receiver"), "expected an object");
    ReceiverSpec spec;
    if (r.contains("name")) {
      if (!r.at("name").is_string()) throw InputError(source, where("receiver.name"), "expected a string");
      spec.name = r.at("name").get<std::string>();
    }
    auto vec3 = [&](const char* key, glm::dvec3& out) {
      const std::string path = where(std::string("receiver.") + key);
      if (!r.contains(key)) throw InputError(source, path, "missing");
      const nlohmann::json& a = r.at(key);
      if (!a.is_array() || a.size() != 3) throw InputError(source, path, "expected three numbers");
      for (int i = 0; i < 3; ++i) {
        if (!a.at(static_cast<std::size_t>(i)).is_number() || !std::isfinite(a.at(static_cast<std::size_t>(i)).get<double>()))
          throw InputError(source, path, "expected three finite numbers");
        out[i] = a.at(static_cast<std::size_t>(i)).get<double>();
      }
    };
    vec3("point", spec.point);
    vec3("normal", spec.normal);
    const double length = glm::length(spec.normal);
    if (!(length > 0.0) || !std::isfinite(length)) throw InputError(source, where("receiver.normal"), "must not be zero");
    spec.normal /= length;
    number(r, "half_extent", spec.half_extent, where("receiver.half_extent"));
    number(r, "pitch_voxels", spec.pitch_voxels, where("receiver.pitch_voxels"));
    if (!(spec.half_extent > 0.0)) throw InputError(source, where("receiver.half_extent"), "must be positive");
    if (!(spec.pitch_voxels >= 0.01 && spec.pitch_voxels <= 8.0))  // lightsim --receiver-pitch's range
      throw InputError(source, where("receiver.pitch_voxels"), "must lie in [0.01, 8]");
    o.receiver = spec;
  }
  try {
    validateOptions(o);
  } catch (const InputError& e) {
    throw InputError(source + ": bake_options: " + e.what());
  }
  return o;
}

void smoothIrradiance(BakeResult& result, const GridSpec& grid, double sigma_voxels) {
  gaussianSmoothComponents(result.irradiance, grid, sigma_voxels);
}

LightSpec parseLight(const std::string& light_text, const std::string& power_text) {
  LightSpec light;
  const std::size_t colon = light_text.find(':');
  const std::string kind = light_text.substr(0, colon);
  if (colon == std::string::npos || (kind != "directional" && kind != "point"))
    throw InputError("--light", "", "'" + light_text + "': expected directional:DX,DY,DZ or point:X,Y,Z");
  const std::vector<double> v = parseNumbers(light_text.substr(colon + 1), "--light", kind);
  if (v.size() != 3) throw InputError("--light", kind, "'" + light_text + "': expected three numbers");
  const glm::dvec3 xyz(v[0], v[1], v[2]);
  if (kind == "directional") {
    const double len = glm::length(xyz);
    if (!(len > 0.0) || !std::isfinite(len))
      throw InputError("--light", "directional", "'" + light_text + "': the direction must not be zero");
    light.type = LightSpec::Type::Directional;
    light.direction = xyz / len;
  } else {
    light.type = LightSpec::Type::Point;
    light.position = xyz;
  }
  const std::vector<double> p = parseNumbers(power_text, "--power", "");
  if (p.size() != 1 && p.size() != 3) throw InputError("--power", "", "'" + power_text + "': expected R,G,B or one value");
  light.power = p.size() == 1 ? glm::dvec3(p[0]) : glm::dvec3(p[0], p[1], p[2]);
  if (light.power.x < 0.0 || light.power.y < 0.0 || light.power.z < 0.0)
    throw InputError("--power", "", "'" + power_text + "': must not be negative");
  if (std::max(light.power.x, std::max(light.power.y, light.power.z)) > kMaxLightPower)
    throw InputError("--power", "", "'" + power_text + "': must be at most 1e30 (bakes store 32-bit floats, which a caustic would overflow)");
  if (light.power.x == 0.0 && light.power.y == 0.0 && light.power.z == 0.0)
    throw InputError("--power", "", "'" + power_text + "': must not be zero in every channel");
  return light;
}

std::vector<LightSpec> lightsFromScene(const std::filesystem::path& file) {
  Scene scene = readScene(file);
  if (scene.lights.empty()) throw InputError(file.string(), "lights", "the scene has no light to bake");
  std::vector<LightSpec> lights;
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const SceneLightSpec& l = scene.lights[i];
    LightSpec light;
    if (l.type == SceneLightSpec::Type::Directional) {
      light.type = LightSpec::Type::Directional;
      light.direction = l.direction;
      light.power = l.irradiance;
      light.angular_diameter_deg = l.angular_diameter_deg;
    } else {
      light.type = l.type == SceneLightSpec::Type::Spot ? LightSpec::Type::Spot : LightSpec::Type::Point;
      light.position = l.position;
      light.power = l.intensity;
      light.direction = l.direction;
      light.inner_cone_deg = l.inner_cone_deg;
      light.outer_cone_deg = l.outer_cone_deg;
      light.radius = l.radius;
    }
    if (!(light.power.x > 0 || light.power.y > 0 || light.power.z > 0))
      throw InputError(file.string(), "lights[" + std::to_string(i) + "]", "the light has no power");
    lights.push_back(light);
  }
  return lights;
}

LightSpec lightFromScene(const std::filesystem::path& file) { return lightsFromScene(file).front(); }

ReceiverSpec parseReceiver(const std::string& text) {
  ReceiverSpec spec;
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t colon; (colon = text.find(':', start)) != std::string::npos; start = colon + 1)
    parts.push_back(text.substr(start, colon - start));
  parts.push_back(text.substr(start));
  if (parts.size() < 2 || parts.size() > 3)
    throw InputError("--receiver", "", "'" + text + "': expected PX,PY,PZ:NX,NY,NZ[:HALF_EXTENT]");
  const std::vector<double> p = parseNumbers(parts[0], "--receiver", "point");
  const std::vector<double> n = parseNumbers(parts[1], "--receiver", "normal");
  if (p.size() != 3 || n.size() != 3) throw InputError("--receiver", "", "'" + text + "': expected three numbers for P and N");
  spec.point = glm::dvec3(p[0], p[1], p[2]);
  const glm::dvec3 normal(n[0], n[1], n[2]);
  const double len = glm::length(normal);
  if (!(len > 0.0) || !std::isfinite(len)) throw InputError("--receiver", "normal", "'" + text + "': must not be zero");
  spec.normal = normal / len;
  if (parts.size() == 3) {
    const std::vector<double> e = parseNumbers(parts[2], "--receiver", "half extent");
    if (e.size() != 1 || !(e[0] > 0.0)) throw InputError("--receiver", "half extent", "'" + text + "': must be positive");
    spec.half_extent = e[0];
  }
  return spec;
}

std::optional<ReceiverSpec> receiverFromScene(const std::filesystem::path& file) {
  const Scene scene = readScene(file);
  if (!scene.ground) return std::nullopt;
  ReceiverSpec spec;
  spec.point = scene.ground->point;
  spec.normal = glm::normalize(scene.ground->normal);
  spec.half_extent = scene.ground->half_extent;
  return spec;
}

}  // namespace eik
