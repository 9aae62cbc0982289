// Flat 3D atlas layout and targets (see atlas.h).
#include "lightsim/atlas.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "gl/context.h"
#include "gl/debug.h"

namespace eik {

namespace {

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

}  // namespace

AtlasLayout AtlasLayout::plan(glm::ivec3 dims, int maxTextureSize, const std::string& source,
                              const std::string& renderer) {
  if (dims.x < 1 || dims.y < 1 || dims.z < 1) {
    throw InputError(source, "dims", "volume of " + dimsText(dims) + " voxels is empty");
  }
  AtlasLayout best;
  long long bestSide = std::numeric_limits<long long>::max(), bestArea = bestSide;
  for (int tx = 1; tx <= dims.z; ++tx) {
    const int ty = (dims.z + tx - 1) / tx;
    if ((ty - 1) * tx >= dims.z) continue;  // a shorter grid with the same columns exists
    const long long w = static_cast<long long>(tx) * dims.x, h = static_cast<long long>(ty) * dims.y;
    if (w > maxTextureSize || h > maxTextureSize) continue;
    const long long side = std::max(w, h), area = w * h;
    if (side < bestSide || (side == bestSide && area < bestArea)) {
      bestSide = side;
      bestArea = area;
      best.dims = dims;
      best.tiles = {tx, ty};
      best.size = {static_cast<int>(w), static_cast<int>(h)};
    }
  }
  if (best.tiles.x == 0) {
    // The most square tiling, for the message.
    const int tx = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(dims.z) * dims.y / dims.x))));
    const int ty = (dims.z + tx - 1) / tx;
    throw InputError(source, "dims",
                     "volume too large for the GPU: a grid of " + dimsText(dims) +
                         " voxels needs a flat-3D atlas of at least " + std::to_string(static_cast<long long>(tx) * dims.x) +
                         "x" + std::to_string(static_cast<long long>(ty) * dims.y) +
                         " texels, over GL_MAX_TEXTURE_SIZE (" + std::to_string(maxTextureSize) + ")" +
                         (renderer.empty() ? std::string() : " of " + renderer) +
                         "; resample the volume or use --backend cpu");
  }
  return best;
}

glm::ivec3 AtlasLayout::voxel(glm::ivec2 t) const {
  if (t.x < 0 || t.y < 0 || t.x >= size.x || t.y >= size.y) return glm::ivec3(-1);
  const int tx = t.x / dims.x, ty = t.y / dims.y;
  const int z = ty * tiles.x + tx;
  if (z >= dims.z) return glm::ivec3(-1);
  return {t.x - tx * dims.x, t.y - ty * dims.y, z};
}

gl::ShaderDefines AtlasLayout::defines() const {
  return {{"ATLAS_DIMS", "ivec3(" + std::to_string(dims.x) + ", " + std::to_string(dims.y) + ", " +
                             std::to_string(dims.z) + ")"},
          {"ATLAS_TILES_X", std::to_string(tiles.x)},
          {"ATLAS_SIZE", "vec2(" + std::to_string(size.x) + ".0, " + std::to_string(size.y) + ".0)"}};
}

AtlasTargets::AtlasTargets(const AtlasLayout& layout, DepositMode mode) : layout_(layout), mode_(mode) {
  const gl::Sampling nearest{gl::Filter::Nearest, gl::Wrap::ClampToEdge};
  energy_ = gl::Texture2D(layout.size, gl::TextureFormat::RGBA32F, nearest);
  direction_ = gl::Texture2D(layout.size, gl::TextureFormat::RGBA32F, nearest);
  framebuffer_ = gl::Framebuffer(layout.size);
  framebuffer_.attach(0, energy_);
  framebuffer_.attach(1, direction_);
  if (mode == DepositMode::Max) {
    depth_ = gl::Texture2D(layout.size, gl::TextureFormat::Depth32F, nearest);
    gl::detail::ScopedBinding binding(GL_FRAMEBUFFER, GL_FRAMEBUFFER_BINDING, gl::detail::bindFramebuffer,
                                      framebuffer_.id());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth_.id(), 0);
    gl::checkErrors("AtlasTargets (depth)");
  }
  framebuffer_.checkComplete();
  clear();
}

void AtlasTargets::clear() {
  framebuffer_.clear(0, glm::vec4(0.0f));
  framebuffer_.clear(1, glm::vec4(0.0f));
  if (mode_ == DepositMode::Max) {
    gl::detail::ScopedBinding binding(GL_DRAW_FRAMEBUFFER, GL_DRAW_FRAMEBUFFER_BINDING, gl::detail::bindFramebuffer,
                                      framebuffer_.id());
    GLboolean mask = GL_TRUE;
    glGetBooleanv(GL_DEPTH_WRITEMASK, &mask);
    glDepthMask(GL_TRUE);
    const float one = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &one);
    glDepthMask(mask);
    gl::checkErrors("AtlasTargets::clear");
  }
}

std::size_t AtlasTargets::bytesFor(const AtlasLayout& layout, DepositMode mode) {
  return layout.texelCount() * (32 + (mode == DepositMode::Max ? 4 : 0));
}

std::size_t AtlasTargets::bytes() const { return bytesFor(layout_, mode_); }

void AtlasTargets::toFields(Field& irradiance, Field& lightDir) const {
  const glm::ivec3 d = layout_.dims;
  const std::size_t voxels = static_cast<std::size_t>(d.x) * static_cast<std::size_t>(d.y) * static_cast<std::size_t>(d.z);
  irradiance.components = 3;
  lightDir.components = 3;
  irradiance.data.assign(voxels * 3, 0.0f);
  lightDir.data.assign(voxels * 3, 0.0f);
  const std::vector<float> energy = energy_.download(4);
  const std::vector<float> direction = direction_.download(4);
  const std::size_t width = static_cast<std::size_t>(layout_.size.x);
  std::size_t v = 0;
  for (int k = 0; k < d.z; ++k) {
    for (int j = 0; j < d.y; ++j) {
      for (int i = 0; i < d.x; ++i, ++v) {
        const glm::ivec2 t = layout_.texel({i, j, k});
        const std::size_t at = (static_cast<std::size_t>(t.y) * width + static_cast<std::size_t>(t.x)) * 4;
        for (int c = 0; c < 3; ++c) irradiance.data[v * 3 + static_cast<std::size_t>(c)] = energy[at + static_cast<std::size_t>(c)];
        glm::dvec3 dir(direction[at], direction[at + 1], direction[at + 2]);
        const double length = glm::length(dir);
        // Accumulate: the normalised direction sum. Max: the stored unit d (renormalised).
        if (length > 0.0 && std::isfinite(length)) dir /= length;
        else dir = glm::dvec3(0.0);
        for (int c = 0; c < 3; ++c) lightDir.data[v * 3 + static_cast<std::size_t>(c)] = static_cast<float>(dir[c]);
      }
    }
  }
}

}  // namespace eik
