#include "viewer/environment.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "gl/gl.h"

namespace eik {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSunRadiusRad = 1.0 * kPi / 180.0;  // the sky's sun disk: 1° angular radius

bool parseColour(const std::string& text, glm::dvec3& out) {
  std::istringstream in(text);
  char c1 = 0, c2 = 0;
  glm::dvec3 v;
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof()) return false;
  if (!(v.x >= 0 && v.y >= 0 && v.z >= 0) || !std::isfinite(v.x + v.y + v.z)) return false;
  out = v;
  return true;
}

// The sky's colours (also in shaders/viewer/environment.glsl: keep them equal).
const glm::dvec3 kZenith(0.18, 0.33, 0.75);
const glm::dvec3 kHorizon(0.75, 0.85, 1.0);
const glm::dvec3 kSkyGround(0.22, 0.2, 0.18);
const glm::dvec3 kSunGlow(1.0, 0.85, 0.6);

glm::dvec3 mix3(glm::dvec3 a, glm::dvec3 b, double t) { return a + (b - a) * t; }
double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

}  // namespace

void applyEnvironmentFlag(const std::string& text, SceneEnvironmentSpec& env) {
  const auto colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  const std::string rest = colon == std::string::npos ? std::string() : text.substr(colon + 1);
  auto colour = [&](glm::dvec3 fallback) {
    glm::dvec3 v = fallback;
    if (colon != std::string::npos && !parseColour(rest, v))
      throw InputError("--env", text, "the colour must be three non-negative numbers R,G,B");
    return v;
  };
  if (kind == "uniform") {
    env = SceneEnvironmentSpec{};
    env.uniform = colour(glm::dvec3(1.0));
  } else if (kind == "checker") {
    env = SceneEnvironmentSpec{};
    env.procedural = "checker";
    env.uniform = colour(glm::dvec3(1.0));
  } else if (kind == "sky") {
    if (colon != std::string::npos) throw InputError("--env", text, "sky takes no parameters");
    const double intensity = env.intensity, rotate = env.rotate_deg;
    env = SceneEnvironmentSpec{};
    env.uniform.reset();
    env.procedural = "sky";
    env.intensity = intensity;
    env.rotate_deg = rotate;
  } else if (!text.empty() && text.find('.') != std::string::npos) {
    env = SceneEnvironmentSpec{};
    env.uniform.reset();
    env.file = text;  // resolved against the working directory (main.cpp makes it absolute)
  } else {
    throw InputError("--env", text, "expected FILE (.exr, .hdr or .png), uniform:R,G,B, checker[:R,G,B] or sky");
  }
}

Environment::Environment(const SceneEnvironmentSpec& spec, const std::filesystem::path& base_dir,
                         const std::string& source)
    : intensity_(static_cast<float>(spec.intensity)),
      rotate_rad_(static_cast<float>(spec.rotate_deg * kPi / 180.0)) {
  if (!(spec.intensity >= 0) || !std::isfinite(spec.intensity))
    throw InputError(source, "environment.intensity", "must be a non-negative number");
  if (!spec.file.empty()) {
    kind_ = EnvironmentKind::Map;
    std::filesystem::path path = spec.file;
    if (path.is_relative()) path = base_dir / path;
    try {
      image_ = readImage(path);
    } catch (const InputError& e) {
      throw InputError(source, "environment.file", e.what());
    }
    if (image_.width < 2 || image_.height < 1)
      throw InputError(source, "environment.file", path.string() + " is too small for an environment map");
    // RGBA floats for the texture, whatever the file's channel count.
    std::vector<float> rgba(static_cast<std::size_t>(image_.width) * image_.height * 4, 1.0f);
    for (std::size_t i = 0; i < static_cast<std::size_t>(image_.width) * image_.height; ++i)
      for (int c = 0; c < 4; ++c) {
        const int src = std::min(c, image_.channels - 1);
        rgba[i * 4 + c] = c < 3 ? std::max(0.0f, image_.pixels[i * image_.channels + (image_.channels >= 3 ? src : 0)])
                                : 1.0f;
      }
    Image full = image_;
    full.channels = 4;
    full.pixels = rgba;
    image_ = std::move(full);
    gl::checkTexture2DSize({image_.width, image_.height}, path.string());
    texture_ = gl::Texture2D({image_.width, image_.height}, gl::TextureFormat::RGBA32F, image_.pixels, 4);
    // Mipmaps: rays that diverged through glass look the map up at a coarser level.
    texture_.bind(0);
    levels_ = 1 + static_cast<int>(std::floor(std::log2(std::max(image_.width, image_.height))));
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, levels_ - 1);  // before generating: it bounds the levels made
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
  } else if (spec.procedural == "sky") {
    kind_ = EnvironmentKind::Sky;
  } else if (spec.procedural == "checker") {
    kind_ = EnvironmentKind::Checker;
    colour_ = glm::vec3(spec.uniform.value_or(glm::dvec3(1.0)));
  } else if (!spec.procedural.empty()) {
    throw InputError(source, "environment.procedural", "'" + spec.procedural + "' is not known; expected \"sky\" or \"checker\"");
  } else {
    kind_ = EnvironmentKind::Uniform;
    colour_ = glm::vec3(spec.uniform.value_or(glm::dvec3(0.0)));
  }
}

gl::ShaderDefines Environment::defines() const {
  switch (kind_) {
    case EnvironmentKind::Map: return {{"ENV_MAP", "1"}};
    case EnvironmentKind::Sky: return {{"ENV_SKY", "1"}};
    case EnvironmentKind::Checker: return {{"ENV_CHECKER", "1"}};
    case EnvironmentKind::Uniform: break;
  }
  return {{"ENV_UNIFORM", "1"}};
}

namespace {
// What the sky's sun disk must emit so that it delivers `irradiance` (the directional light's).
glm::vec3 sunRadiance(const glm::dvec3& irradiance) {
  const double solid_angle = 2.0 * kPi * (1.0 - std::cos(kSunRadiusRad));
  return glm::vec3(irradiance / solid_angle);
}
}  // namespace

int Environment::bind(const gl::Program& program, int unit, glm::vec3 sun_direction, glm::vec3 sun_irradiance) const {
  program.set("uEnvColor", colour_ * intensity_);
  program.set("uEnvIntensity", intensity_);
  program.set("uEnvRotation", glm::vec2(std::cos(rotate_rad_), std::sin(rotate_rad_)));
  const glm::vec3 to_sun = glm::length(sun_direction) > 0 ? -glm::normalize(sun_direction) : glm::vec3(0, 1, 0);
  program.set("uEnvSunDir", to_sun);
  program.set("uEnvSunCos", static_cast<float>(std::cos(kSunRadiusRad)));
  program.set("uEnvSunRadiance", sunRadiance(glm::dvec3(sun_irradiance)));
  if (kind_ == EnvironmentKind::Map) {
    texture_.bind(unit);
    program.setSampler("uEnvMap", unit);
    program.set("uEnvMapSize", glm::vec2(image_.width, image_.height));
    program.set("uEnvMaxLod", static_cast<float>(levels_ - 1));
    return unit + 1;
  }
  return unit;
}

glm::vec3 Environment::radiance(glm::dvec3 d, glm::dvec3 sun_direction, bool include_sun,
                                glm::dvec3 sun_irradiance) const {
  d = glm::normalize(d);
  // Turn the environment by rotate_deg about +y: look up the direction turned back.
  const double c = std::cos(rotate_rad_), s = std::sin(rotate_rad_);
  const glm::dvec3 r(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
  switch (kind_) {
    case EnvironmentKind::Uniform: return colour_ * intensity_;
    case EnvironmentKind::Checker: {
      const double u = std::atan2(r.z, r.x) / (2 * kPi) + 0.5;
      const double v = std::acos(std::clamp(r.y, -1.0, 1.0)) / kPi;
      const double cell = std::fmod(std::floor(u * 24.0) + std::floor(v * 12.0), 2.0);
      return colour_ * intensity_ * static_cast<float>(0.2 + 0.8 * cell);
    }
    case EnvironmentKind::Sky: {
      const glm::dvec3 to_sun = glm::length(sun_direction) > 0 ? -glm::normalize(sun_direction) : glm::dvec3(0, 1, 0);
      glm::dvec3 sky = mix3(kHorizon, kZenith, std::pow(std::clamp(r.y, 0.0, 1.0), 0.45));
      const double mu = glm::dot(r, to_sun);
      sky += kSunGlow * 0.6 * std::pow(std::max(mu, 0.0), 8.0);
      const glm::dvec3 below = kSkyGround * (0.5 + 0.5 * std::clamp(to_sun.y, 0.0, 1.0));
      glm::dvec3 out = mix3(below, sky, smoothstep(-0.02, 0.02, r.y));
      if (include_sun && mu > std::cos(kSunRadiusRad) && r.y > 0) out += glm::dvec3(sunRadiance(sun_irradiance));
      return glm::vec3(out) * intensity_;
    }
    case EnvironmentKind::Map: {
      const double u = 0.5 + std::atan2(r.x, -r.z) / (2 * kPi);
      const double v = std::acos(std::clamp(r.y, -1.0, 1.0)) / kPi;
      const int x = std::clamp(static_cast<int>(u * image_.width), 0, image_.width - 1);
      const int y = std::clamp(static_cast<int>(v * image_.height), 0, image_.height - 1);
      const float* p = image_.at(x, y);
      return glm::vec3(p[0], p[1], p[2]) * intensity_;
    }
  }
  return glm::vec3(0.0f);
}

glm::vec3 Environment::diffuseRadiance(glm::dvec3 normal, glm::dvec3 sun_direction) const {
  if (kind_ == EnvironmentKind::Uniform) return colour_ * intensity_;
  // (1/π)∫ L(ω) max(0, N·ω) dω over the sphere, the sun disk left out (it is a light of the scene).
  normal = glm::normalize(normal);
  for (const auto& [n, sun, value] : diffuse_cache_)
    if (n == normal && (kind_ != EnvironmentKind::Sky || sun == sun_direction)) return value;
  constexpr int kTheta = 64, kPhi = 128;
  glm::dvec3 sum(0.0);
  for (int i = 0; i < kTheta; ++i) {
    const double theta = (i + 0.5) * kPi / kTheta;
    for (int j = 0; j < kPhi; ++j) {
      const double phi = (j + 0.5) * 2 * kPi / kPhi;
      const glm::dvec3 w(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      const double cosine = glm::dot(normal, w);
      if (cosine <= 0) continue;
      const double dw = std::sin(theta) * (kPi / kTheta) * (2 * kPi / kPhi);
      sum += glm::dvec3(radiance(w, sun_direction, false)) * cosine * dw;
    }
  }
  const glm::vec3 value(sum / kPi);
  if (diffuse_cache_.size() >= 4) diffuse_cache_.erase(diffuse_cache_.begin());
  diffuse_cache_.emplace_back(normal, sun_direction, value);
  return value;
}

}  // namespace eik
