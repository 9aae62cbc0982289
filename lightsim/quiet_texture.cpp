// The quiet map's table on the GPU (see quiet_texture.h).
#include "lightsim/quiet_texture.h"

namespace eik::gpu {

QuietTexture::QuietTexture(const QuietMap& map) : brick_(map.brickVoxels()) {
  if (map.empty()) return;
  const glm::ivec3 dims = map.bricks() + 1;
  gl::checkTexture3DSize(dims, "the quiet map's table");
  texture_ = gl::Texture3D(dims, gl::TextureFormat::R32UI, gl::Sampling{gl::Filter::Nearest, gl::Wrap::ClampToEdge});
  const std::vector<std::uint32_t>& table = map.table();
  texture_.uploadRaw(table.data(), table.size() * sizeof(std::uint32_t), GL_RED_INTEGER, GL_UNSIGNED_INT);
}

void QuietTexture::bind(const gl::Program& program, std::string_view name, int unit) const {
  texture_.bind(unit);
  program.setSampler(name, unit);
  program.set("uQuietBrick", brick_);
}

}  // namespace eik::gpu
