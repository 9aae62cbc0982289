#include "core/receiver_map.h"

#include <cmath>
#include <set>

#include "core/error.h"
#include "core/volume.h"

namespace eik {

NrrdHeader ReceiverMap::nrrdHeader() const {
  NrrdHeader header;
  header.components = components;
  header.sizes = {texels.x, texels.y, 1};
  header.origin = texelCenter(0, 0);
  header.directions = glm::dmat3(pitch * u, pitch * v, pitch * normal);
  return header;
}

nlohmann::json ReceiverMap::toJson(const std::string& file) const {
  auto vec3 = [](const glm::dvec3& a) { return nlohmann::json::array({a.x, a.y, a.z}); };
  return {{"name", name},
          {"file", file},
          {"point", vec3(point)},
          {"normal", vec3(normal)},
          {"u", vec3(u)},
          {"v", vec3(v)},
          {"origin", {origin.x, origin.y}},
          {"pitch", pitch},
          {"texels", {texels.x, texels.y}},
          {"quantity", components == 1 ? "planar irradiance, W/m^2, grey (R = G = B)" : "planar irradiance, W/m^2, RGB"}};
}

bool ReceiverMap::makeGrey() {
  if (components == 1) return true;
  const std::size_t n = texelCount();
  if (irradiance.size() != 3 * n) return false;
  for (std::size_t t = 0; t < n; ++t) {
    const float* e = &irradiance[3 * t];
    // Equal values (a NaN never is; a −0 beside a +0 reads back as the first).
    if (!(e[0] == e[1] && e[1] == e[2])) return false;
  }
  for (std::size_t t = 0; t < n; ++t) irradiance[t] = irradiance[3 * t];
  irradiance.resize(n);
  components = 1;
  return true;
}

void ReceiverMap::makeRgb() {
  if (components == 3) return;
  const std::size_t n = irradiance.size();
  irradiance.resize(3 * n);
  for (std::size_t t = n; t-- > 0;) irradiance[3 * t] = irradiance[3 * t + 1] = irradiance[3 * t + 2] = irradiance[t];
  components = 3;
}

void receiverAxes(const glm::dvec3& normal, glm::dvec3& u, glm::dvec3& v) {
  const glm::dvec3 n = glm::normalize(normal);
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(n[a]) < std::abs(n[axis])) axis = a;
  glm::dvec3 e(0.0);
  e[axis] = 1.0;
  u = glm::normalize(e - glm::dot(e, n) * n);
  v = glm::cross(n, u);  // u × v = u × (n × u) = n
}

namespace {

glm::dvec3 triple(const nlohmann::json& j, const std::string& source, const std::string& key) {
  if (!j.is_array() || j.size() != 3) throw InputError(source, key, "expected an array of 3 numbers");
  glm::dvec3 r;
  for (int a = 0; a < 3; ++a) {
    if (!j[static_cast<std::size_t>(a)].is_number()) throw InputError(source, key, "expected an array of 3 numbers");
    r[a] = j[static_cast<std::size_t>(a)].get<double>();
    if (!std::isfinite(r[a])) throw InputError(source, key, "must be finite");
  }
  return r;
}

glm::dvec3 unit(const nlohmann::json& j, const std::string& source, const std::string& key) {
  const glm::dvec3 a = triple(j, source, key);
  if (std::abs(glm::length(a) - 1.0) > 1e-4) throw InputError(source, key, "must be a unit vector");
  return a;
}

}  // namespace

ReceiverMap receiverFromJson(const nlohmann::json& j, const std::string& source, const std::string& key,
                             std::string& file) {
  if (!j.is_object()) throw InputError(source, key, "expected an object");
  static const std::set<std::string> kKeys = {"name", "file", "point", "normal", "u", "v", "origin", "pitch",
                                              "texels", "quantity"};
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!kKeys.count(it.key()))
      throw InputError(source, key + "." + it.key(),
                       "unknown key (expected one of: file, name, normal, origin, pitch, point, quantity, texels, u, v)");
  for (const char* required : {"file", "point", "normal", "u", "v", "origin", "pitch", "texels"})
    if (!j.contains(required)) throw InputError(source, key + "." + required, "missing");
  ReceiverMap map;
  if (j.contains("name")) {
    if (!j.at("name").is_string()) throw InputError(source, key + ".name", "expected a string");
    map.name = j.at("name").get<std::string>();
    if (!isValidFieldName(map.name))
      throw InputError(source, key + ".name", "a receiver name may hold only letters, digits, '_' and '-'");
  }
  if (!j.at("file").is_string() || j.at("file").get<std::string>().empty())
    throw InputError(source, key + ".file", "expected a file name");
  file = j.at("file").get<std::string>();
  map.point = triple(j.at("point"), source, key + ".point");
  map.normal = unit(j.at("normal"), source, key + ".normal");
  map.u = unit(j.at("u"), source, key + ".u");
  map.v = unit(j.at("v"), source, key + ".v");
  if (glm::length(glm::cross(map.u, map.v) - map.normal) > 1e-3)
    throw InputError(source, key + ".u", "u, v and normal must be orthonormal with u × v = normal");
  const nlohmann::json& origin = j.at("origin");
  if (!origin.is_array() || origin.size() != 2 || !origin[0].is_number() || !origin[1].is_number())
    throw InputError(source, key + ".origin", "expected an array of 2 numbers");
  map.origin = {origin[0].get<double>(), origin[1].get<double>()};
  if (!std::isfinite(map.origin.x) || !std::isfinite(map.origin.y))
    throw InputError(source, key + ".origin", "must be finite");
  if (!j.at("pitch").is_number()) throw InputError(source, key + ".pitch", "expected a number");
  map.pitch = j.at("pitch").get<double>();
  if (!(map.pitch > 0.0) || !std::isfinite(map.pitch)) throw InputError(source, key + ".pitch", "must be positive");
  const nlohmann::json& texels = j.at("texels");
  if (!texels.is_array() || texels.size() != 2 || !texels[0].is_number_integer() || !texels[1].is_number_integer())
    throw InputError(source, key + ".texels", "expected an array of 2 integers");
  for (int a = 0; a < 2; ++a) {
    const long long n = texels[static_cast<std::size_t>(a)].get<long long>();
    if (n < 1 || n > 16384) throw InputError(source, key + ".texels", "must be 1 to 16384 per axis");
    map.texels[a] = static_cast<int>(n);
  }
  return map;
}

void checkReceiverHeader(const ReceiverMap& map, const NrrdHeader& header, const std::string& source,
                         const std::string& key, const std::string& nrrd) {
  if (header.components != 1 && header.components != 3)
    throw InputError(source, key, nrrd + ": expected 3 components (RGB) or 1 (grey)");
  if (header.sizes != glm::ivec3(map.texels.x, map.texels.y, 1))
    throw InputError(source, key, nrrd + ": sizes do not match the manifest's texels");
  const NrrdHeader expected = map.nrrdHeader();
  const double tolerance = 1e-4 * map.pitch;
  if (glm::length(header.origin - expected.origin) > tolerance * 10.0)
    throw InputError(source, key, nrrd + ": space origin does not match the manifest's plane and origin");
  for (int a = 0; a < 3; ++a)
    if (glm::length(header.directions[a] - expected.directions[a]) > tolerance)
      throw InputError(source, key, nrrd + ": space directions do not match the manifest's axes and pitch");
}

}  // namespace eik
