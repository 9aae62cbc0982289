// QuietTexture: a QuietMap's summed-area table (lightsim/quiet_map.h) as an R32UI 3D texture of
// (bricks + 1)³ texels, for the update pass's free flights and straight steps
// (shaders/lightsim/flight.glsl boxQuiet: eight texelFetch a box, as QuietMap::quiet).
//
//   in   a QuietMap (VolumeSampler::quietMap, or ::absorberMap: the voxels with σa ≠ 0)
//   out  the texture, bound to a usampler3D with bind(); uQuietBrick (voxels per brick edge) is
//        set with it (the quiet and absorber maps of one grid have the same bricks)
#pragma once

#include <string_view>

#include "gl/program.h"
#include "gl/texture.h"
#include "lightsim/quiet_map.h"

namespace eik::gpu {

class QuietTexture {
 public:
  QuietTexture() = default;
  // An empty map (no grid) gives an empty texture.
  explicit QuietTexture(const QuietMap& map);

  explicit operator bool() const { return bool(texture_); }
  // Binds the table to `unit` as the sampler `name`, and sets uQuietBrick.
  void bind(const gl::Program& program, std::string_view name, int unit) const;
  std::size_t bytes() const { return texture_ ? texture_.bytes() : 0; }

 private:
  gl::Texture3D texture_;
  int brick_ = 1;
};

}  // namespace eik::gpu
