#include "viewer/refractive_renderer.h"

#include <algorithm>
#include <cmath>

namespace eik {

RefractiveRenderer::RefractiveRenderer(const gl::ShaderLibrary& shaders, const Volume& volume,
                                       const RenderSettings& settings, const std::string& source)
    : grid_(volume.grid), settings_(settings) {
  gl::VolumeTextureOptions options;
  options.source = source;
  textures_ = gl::VolumeTextures(volume, options);
  gl::ShaderDefines defines;
  if (settings.environment_checker) defines.emplace_back("ENV_CHECKER", "1");
  program_ = shaders.program("common/fullscreen.vert", "viewer/raymarch.frag", defines,
                             textures_.layout().glslDefines());
}

Image RefractiveRenderer::render(const Camera& camera, glm::ivec2 size, const glm::dmat4& object_to_world) {
  gl::Framebuffer target(size, {gl::TextureFormat::RGBA32F});
  target.bind();
  const double aspect = static_cast<double>(size.x) / static_cast<double>(size.y);
  const glm::dmat4 world_to_volume = glm::inverse(object_to_world);
  const glm::dvec3 h = grid_.voxelSize();
  const double step = settings_.step_voxels * std::min({h.x, h.y, h.z});
  const glm::dvec3 extent = grid_.extent();
  const int max_steps = static_cast<int>(std::ceil(4.0 * glm::length(extent) / step)) + 16;

  program_.set("uInvViewProj", glm::mat4(camera.inverseViewProjection(aspect)));
  program_.set("uEye", glm::vec3(camera.eye));
  program_.set("uWorldToVolume", glm::mat4(world_to_volume));
  program_.set("uVolumeToWorldDir", glm::mat3(glm::dmat3(object_to_world)));
  program_.set("uBoundsMin", glm::vec3(grid_.bounds_min));
  program_.set("uBoundsMax", glm::vec3(grid_.bounds_max));
  program_.set("uStep", static_cast<float>(step));
  program_.set("uMaxSteps", max_steps);
  program_.set("uEnvColor", settings_.environment);
  textures_.bind(program_, 0);
  program_.use();
  triangle_.draw();

  Image image;
  image.width = size.x;
  image.height = size.y;
  image.channels = 4;
  image.pixels = target.readRGBA(0);
  gl::flipRows(image.pixels, size.x, 4);
  return image;
}

}  // namespace eik
