// The environment: the radiance arriving from infinitely far away in each direction, seen where a
// viewing ray leaves every volume (thesis Eq. 5.10, the L(x_e) term) and in reflections.
// Kinds (docs/scene-format.md "environment"):
//   uniform      {"uniform": [r, g, b]}
//   map          {"file": "sky.exr", "intensity": 1, "rotate_deg": 0}: an equirectangular
//                (latitude/longitude) HDR/EXR/PNG, read by core/image_io and mipmapped; rays
//                that diverged through glass look it up at a coarser level (footprint LOD)
//   sky          {"procedural": "sky"}: an analytic daylight sky, brighter towards the horizon and
//                the sun (the scene's first directional light), over a dim ground-coloured lower half
//   checker      {"procedural": "checker"} or --env checker:R,G,B:
//                24 × 12 latitude/longitude cells, bright ones `uniform`, dark ones 0.2 of it
// `intensity` scales every kind; `rotate_deg` turns it about the world up (+y) axis.
// GLSL side: shaders/viewer/environment.glsl (variant by #define ENV_UNIFORM / ENV_MAP / ENV_SKY /
// ENV_CHECKER).
#pragma once

#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <glm/glm.hpp>

#include "core/image_io.h"
#include "core/scene.h"
#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/texture.h"

namespace eik {

enum class EnvironmentKind { Uniform, Map, Sky, Checker };

// Parses --env: FILE | uniform:R,G,B | checker[:R,G,B] | sky, into `env` (keeping its intensity
// and rotation unless the flag gives a kind that has none). InputError naming --env.
void applyEnvironmentFlag(const std::string& text, SceneEnvironmentSpec& env);

class Environment {
 public:
  // `base_dir` resolves a relative map path. Reads and uploads the map (needs a current GL context
  // then): InputError naming `source`, "environment.file" and the path when it cannot be read.
  Environment(const SceneEnvironmentSpec& spec, const std::filesystem::path& base_dir,
              const std::string& source = "environment");

  EnvironmentKind kind() const { return kind_; }
  // The #define that selects the GLSL variant.
  gl::ShaderDefines defines() const;
  // Sets the uniforms (uEnv*) and binds the map to `unit`; returns the next free unit.
  // `sun_direction` is the direction the sky's sun light travels, `sun_irradiance` what it delivers.
  int bind(const gl::Program& program, int unit, glm::vec3 sun_direction, glm::vec3 sun_irradiance) const;

  // The same radiance on the CPU (tests; the sky and the checker match the shader's formulas).
  // `d` is the direction a viewing ray looks along (light arrives from there).
  glm::vec3 radiance(glm::dvec3 d, glm::dvec3 sun_direction = glm::dvec3(0, -1, 0), bool include_sun = true,
                     glm::dvec3 sun_irradiance = glm::dvec3(1.0)) const;
  // ρ·this is the radiance of a Lambertian surface of albedo ρ facing `normal` under the
  // environment alone, unoccluded: (1/π)∫ L(ω) max(0, N·ω) dω (the sky's sun disk left out: it is
  // the scene's directional light, added separately).
  glm::vec3 diffuseRadiance(glm::dvec3 normal, glm::dvec3 sun_direction = glm::dvec3(0, -1, 0)) const;

 private:
  EnvironmentKind kind_ = EnvironmentKind::Uniform;
  glm::vec3 colour_{1.0f};
  float intensity_ = 1.0f;
  float rotate_rad_ = 0.0f;
  Image image_;            // the map at full resolution (CPU lookups)
  gl::Texture2D texture_;  // mipmapped, RGBA32F
  int levels_ = 1;
  // diffuseRadiance's last answers (an integral over the sphere): normal, sun, value.
  mutable std::vector<std::tuple<glm::dvec3, glm::dvec3, glm::vec3>> diffuse_cache_;
};

}  // namespace eik
