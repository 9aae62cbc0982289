// Fragment-shader ray casting of one refractive volume into an HDR image (thesis §6.3): the
// volume's fields in 3D textures (gl::VolumeTextures), one curved ray per pixel
// (shaders/viewer/raymarch.frag), read back as linear float RGBA.
#pragma once

#include <glm/glm.hpp>

#include "core/image_io.h"
#include "core/volume.h"
#include "gl/framebuffer.h"
#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/vertex_array.h"
#include "gl/volume_textures.h"
#include "viewer/camera.h"

namespace eik {

struct RenderSettings {
  double step_voxels = 0.5;          // arc length per ray step, in voxels
  glm::vec3 environment{1.0f};       // uniform environment radiance (or the checker's bright cells)
  bool environment_checker = false;  // latitude/longitude checkerboard environment
};

class RefractiveRenderer {
 public:
  // Needs a current GL context. Uploads the volume; InputError if it is too large for the GPU.
  RefractiveRenderer(const gl::ShaderLibrary& shaders, const Volume& volume, const RenderSettings& settings,
                     const std::string& source = "volume");

  // Renders with the volume placed by `object_to_world`; rows top to bottom.
  Image render(const Camera& camera, glm::ivec2 size, const glm::dmat4& object_to_world = glm::dmat4(1.0));

 private:
  GridSpec grid_;
  RenderSettings settings_;
  gl::VolumeTextures textures_;
  gl::Program program_;
  gl::FullscreenTriangle triangle_;
};

}  // namespace eik
