// The GPU patch list: Morton placement, allocation, upload and readback (see patch_textures.h).
#include "lightsim/patch_textures.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

#include "core/error.h"
#include "gl/context.h"

namespace eik {

void viewportLiveBox(std::size_t count) {
  const glm::ivec2 box = mortonBox(count);
  glViewport(0, 0, box.x, box.y);
}

int patchSideFor(std::size_t count, int minimum) {
  int side = std::max(1, minimum);
  while (static_cast<std::size_t>(side) * static_cast<std::size_t>(side) < count) side *= 2;
  return side;
}

PatchTexels packPatch(const Patch& p, PatchLayout layout) {
  PatchTexels t;
  for (std::size_t c = 0; c < 4; ++c) t[c] = glm::vec4(glm::vec3(p.x[c]), static_cast<float>(p.w[c].x));
  t[4] = glm::vec4(p.w[0].y, p.w[0].z, p.w[1].y, p.w[1].z);
  t[5] = glm::vec4(p.w[2].y, p.w[2].z, p.w[3].y, p.w[3].z);
  t[6] = glm::vec4(glm::vec3(p.flux), static_cast<float>(p.area0));
  if (layout == PatchLayout::Sharp) {
    int media = 0;
    for (std::size_t c = 0; c < 4; ++c) media |= (p.medium[c] + 1) << (3 * c);
    media |= p.crossed << 12;
    media |= p.reflected << 16;  // < 2²⁰: exact in float
    t[7] = glm::vec4(static_cast<float>(p.depth + 64.0 * (std::min(p.reflections, 255) + 256 * p.bounce)),
                     static_cast<float>(media), static_cast<float>(p.reflect_pending), static_cast<float>(p.t_fresnel));
  } else {
    t[7] = glm::vec4(static_cast<float>(p.depth), static_cast<float>(p.n_in), static_cast<float>(p.cos_in),
                     static_cast<float>(p.t_fresnel));
  }
  return t;
}

Patch unpackPatch(const PatchTexels& t, PatchLayout layout) {
  Patch p;
  for (std::size_t c = 0; c < 4; ++c) p.x[c] = glm::dvec3(t[c]);
  p.w[0] = glm::dvec3(t[0].w, t[4].x, t[4].y);
  p.w[1] = glm::dvec3(t[1].w, t[4].z, t[4].w);
  p.w[2] = glm::dvec3(t[2].w, t[5].x, t[5].y);
  p.w[3] = glm::dvec3(t[3].w, t[5].z, t[5].w);
  p.flux = glm::dvec3(t[6]);
  p.area0 = t[6].w;
  if (layout == PatchLayout::Sharp) {
    const double rest = std::floor(static_cast<double>(t[7].x) / 64.0);
    p.depth = static_cast<double>(t[7].x) - 64.0 * rest;
    p.bounce = static_cast<int>(rest) / 256;
    p.reflections = static_cast<int>(rest) - 256 * p.bounce;
    const int media = static_cast<int>(std::lround(t[7].y));
    for (std::size_t c = 0; c < 4; ++c) p.medium[c] = ((media >> (3 * c)) & 7) - 1;
    p.crossed = (media >> 12) & 15;
    p.reflected = (media >> 16) & 15;
    p.reflect_pending = t[7].z;
    const double event = std::floor(static_cast<double>(t[7].w) / 2.0);  // a stored list has none
    p.t_fresnel = static_cast<double>(t[7].w) - 2.0 * event;
    return p;
  }
  p.depth = static_cast<double>(t[7].x);  // a multiple of ½, exact in float
  p.n_in = t[7].y;
  p.cos_in = t[7].z;
  p.t_fresnel = t[7].w;
  return p;
}

std::string PatchTextures::samplerName(const std::string& prefix, int slot) {
  return prefix + "[" + std::to_string(slot) + "]";
}

PatchTextures::PatchTextures(int side) : side_(side) {
  if (side < 1 || (side & (side - 1)) != 0) {
    throw std::invalid_argument("PatchTextures: side " + std::to_string(side) + " is not a power of two");
  }
  const gl::Sampling nearest{gl::Filter::Nearest, gl::Wrap::ClampToEdge};
  framebuffer_ = gl::Framebuffer({side, side});
  for (int slot = 0; slot < kAttachments; ++slot) {
    textures_[static_cast<std::size_t>(slot)] = gl::Texture2D({side, side}, gl::TextureFormat::RGBA32F, nearest);
    framebuffer_.attach(slot, textures_[static_cast<std::size_t>(slot)]);
  }
  framebuffer_.checkComplete();
}

int PatchTextures::bind(const gl::Program& program, const std::string& prefix, int firstUnit) const {
  for (int slot = 0; slot < kAttachments; ++slot) {
    texture(slot).bind(firstUnit + slot);
    program.setSampler(samplerName(prefix, slot), firstUnit + slot);
  }
  return firstUnit + kAttachments;
}

void PatchTextures::upload(std::span<const PatchTexels> patches) {
  if (patches.size() > capacity()) {
    throw RuntimeError("PatchTextures::upload: " + std::to_string(patches.size()) + " patches in a list of " +
                       std::to_string(capacity()));
  }
  const std::size_t texels = capacity();
  std::vector<float> data(texels * 4);
  for (int slot = 0; slot < kAttachments; ++slot) {
    std::fill(data.begin(), data.end(), 0.0f);
    for (std::size_t k = 0; k < patches.size(); ++k) {
      const glm::ivec2 t = mortonTexel(static_cast<std::uint32_t>(k));
      const std::size_t at = (static_cast<std::size_t>(t.y) * static_cast<std::size_t>(side_) +
                              static_cast<std::size_t>(t.x)) * 4;
      const glm::vec4& v = patches[k][static_cast<std::size_t>(slot)];
      data[at + 0] = v.x;
      data[at + 1] = v.y;
      data[at + 2] = v.z;
      data[at + 3] = v.w;
    }
    textures_[static_cast<std::size_t>(slot)].upload(data, 4);
  }
}

std::vector<PatchTexels> PatchTextures::download(std::size_t count) const {
  if (count > capacity()) count = capacity();
  std::vector<PatchTexels> patches(count);
  for (int slot = 0; slot < kAttachments; ++slot) {
    const std::vector<float> data = texture(slot).download(4);
    for (std::size_t k = 0; k < count; ++k) {
      const glm::ivec2 t = mortonTexel(static_cast<std::uint32_t>(k));
      const std::size_t at = (static_cast<std::size_t>(t.y) * static_cast<std::size_t>(side_) +
                              static_cast<std::size_t>(t.x)) * 4;
      patches[k][static_cast<std::size_t>(slot)] = {data[at], data[at + 1], data[at + 2], data[at + 3]};
    }
  }
  return patches;
}

}  // namespace eik
