// The receiver-map deposit pass and its target (see receiver_pass.h; ALGORITHM.md "Receivers").
#include "lightsim/receiver_pass.h"

#include <limits>
#include <string>

#include "core/error.h"
#include "gl/context.h"
#include "gl/debug.h"
#include "gl/scoped_state.h"
#include "lightsim/morton.h"

namespace eik::gpu {

namespace {

std::string sizeText(glm::ivec2 s) { return std::to_string(s.x) + "x" + std::to_string(s.y); }

// 12 vertices a patch: two footprint triangles, each a quad of two GL triangles.
constexpr std::size_t kVerticesPerPatch = 12;

}  // namespace

ReceiverTarget::ReceiverTarget(glm::ivec2 texels) : texels_(texels) {
  const gl::GlContext* context = gl::GlContext::current();
  if (!context) throw RuntimeError("ReceiverTarget: no current OpenGL context");
  const int limit = context->info().maxTextureSize;
  if (texels.x < 1 || texels.y < 1)
    throw InputError("receiver", "texels", "the map of " + sizeText(texels) + " texels is empty");
  if (texels.x > limit || texels.y > limit)
    throw InputError("receiver", "texels",
                     "a map of " + sizeText(texels) + " texels exceeds GL_MAX_TEXTURE_SIZE (" + std::to_string(limit) +
                         ") of " + context->info().renderer + "; use a coarser pitch or --backend cpu");
  const gl::Sampling nearest{gl::Filter::Nearest, gl::Wrap::ClampToEdge};
  texture_ = gl::Texture2D(texels, gl::TextureFormat::RGBA32F, nearest);
  framebuffer_ = gl::Framebuffer(texels);
  framebuffer_.attach(0, texture_);
  framebuffer_.checkComplete();
  clear();
}

void ReceiverTarget::clear() { framebuffer_.clear(0, glm::vec4(0.0f)); }

std::vector<glm::dvec3> ReceiverTarget::readFlux() const {
  // Rows come back bottom first: row j is v index j, so the order is u fastest, as ReceiverMap's.
  const std::vector<float> rgba = texture_.download(4);
  std::vector<glm::dvec3> flux(texelCount());
  for (std::size_t t = 0; t < flux.size(); ++t) flux[t] = glm::dvec3(rgba[4 * t], rgba[4 * t + 1], rgba[4 * t + 2]);
  return flux;
}

void ReceiverTarget::fill(ReceiverMap& map, const std::vector<glm::dvec3>& extra_flux) const {
  if (map.texels != texels_)
    throw RuntimeError("ReceiverTarget::fill: a map of " + sizeText(map.texels) + " texels from a target of " +
                       sizeText(texels_));
  // The irradiance of a texel is its flux over its area (CpuSimulator::run, receiver.h).
  std::vector<glm::dvec3> flux = readFlux();
  for (std::size_t t = 0; t < extra_flux.size() && t < flux.size(); ++t) flux[t] += extra_flux[t];
  const double inv_area = 1.0 / (map.pitch * map.pitch);
  map.irradiance.resize(flux.size() * 3);
  for (std::size_t t = 0; t < flux.size(); ++t)
    for (int c = 0; c < 3; ++c)
      map.irradiance[3 * t + static_cast<std::size_t>(c)] = static_cast<float>(flux[t][c] * inv_area);
}

ReceiverPass::ReceiverPass(const gl::ShaderLibrary& library)
    : program_(library.program("lightsim/receiver.vert", "lightsim/receiver.frag")),
      vao_(gl::VertexArray::create()) {}

void ReceiverPass::run(const PatchTextures& after, const gl::Texture2D& receiveInfo, std::size_t count,
                       ReceiverTarget& target, const ReceiverMap& map, const glm::dvec3& origin) const {
  if (target.texels() != map.texels)
    throw RuntimeError("ReceiverPass: a target of " + sizeText(target.texels()) + " texels for a map of " +
                       sizeText(map.texels));
  if (count > after.capacity() ||
      count > static_cast<std::size_t>(std::numeric_limits<GLsizei>::max()) / kVerticesPerPatch)
    throw RuntimeError("ReceiverPass: " + std::to_string(count) + " patches in a list of " +
                       std::to_string(after.capacity()));
  if (count == 0) return;
  const glm::ivec2 live = mortonBox(count);
  if (receiveInfo.size().x < live.x || receiveInfo.size().y < live.y)
    throw RuntimeError("ReceiverPass: receive info of " + sizeText(receiveInfo.size()) + " texels for " +
                       std::to_string(count) + " patches (" + sizeText(live) + " needed)");
  // The plane in grid-local coordinates, anchored at the map's corner (map.point + origin.x·u +
  // origin.y·v, a point of the plane): texel coordinates are then dot(p − corner, u|v)/pitch,
  // which equals (planeCoordinates(p) − map.origin)/pitch, computed here in double.
  const glm::dvec3 corner = map.point + map.origin.x * map.u + map.origin.y * map.v - origin;
  gl::ScopedPassBindings unbind;
  target.framebuffer().bind();  // viewport = the map
  program_.use();
  const int unit = after.bind(program_, "uPatch", 0);
  receiveInfo.bind(unit);
  program_.setSampler("uReceiveInfo", unit);
  program_.set("uCorner", glm::vec3(corner));
  program_.set("uNormal", glm::vec3(map.normal));
  program_.set("uAxisU", glm::vec3(map.u));
  program_.set("uAxisV", glm::vec3(map.v));
  program_.set("uPitch", static_cast<float>(map.pitch));
  program_.set("uTexels", glm::vec2(map.texels));
  vao_.bind();
  {
    gl::ScopedBlendAdd blend;
    gl::ScopedDisable cull(GL_CULL_FACE), depth(GL_DEPTH_TEST), scissor(GL_SCISSOR_TEST);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(count * kVerticesPerPatch));
  }
  gl::checkErrors("ReceiverPass");
}

}  // namespace eik::gpu
