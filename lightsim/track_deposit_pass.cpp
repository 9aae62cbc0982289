// The track-length deposit pass, ALGORITHM.md step 4 "Track deposits" (see track_deposit_pass.h).
#include "lightsim/track_deposit_pass.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <string>

#include "core/error.h"
#include "gl/debug.h"
#include "gl/scoped_state.h"

namespace eik::gpu {

namespace {

// Texture units: the two corner lists (8 samplers each, PatchTextures::bind) and the flux/flag texture.
constexpr int kBeforeUnit = 0;
constexpr int kAfterUnit = kBeforeUnit + PatchTextures::kAttachments;
constexpr int kTrackInfoUnit = kAfterUnit + PatchTextures::kAttachments;

// GL_PROGRAM_POINT_SIZE on for one draw (the vertex shader sets gl_PointSize), restored after;
// scoped_state.h has no guard for an enable, so this one lives here.
class ScopedProgramPointSize {
 public:
  ScopedProgramPointSize() : was_(glIsEnabled(GL_PROGRAM_POINT_SIZE) == GL_TRUE) {
    if (!was_) glEnable(GL_PROGRAM_POINT_SIZE);
  }
  ~ScopedProgramPointSize() {
    if (!was_) glDisable(GL_PROGRAM_POINT_SIZE);
  }
  ScopedProgramPointSize(const ScopedProgramPointSize&) = delete;
  ScopedProgramPointSize& operator=(const ScopedProgramPointSize&) = delete;

 private:
  bool was_;
};

}  // namespace

TrackDepositPass::TrackDepositPass(const gl::ShaderLibrary& library, const AtlasLayout& layout)
    : vao_(gl::VertexArray::create()), layout_(layout) {
  program_ = library.program("lightsim/track_deposit.vert", "lightsim/track_deposit.frag", layout.defines());
  // A point covers at most (maxExtentVoxels + 2)² texels, so that is the largest size it needs.
  // GL_POINT_SIZE_RANGE is the core profile's range for non-antialiased points written by the
  // shader (GL_ALIASED_POINT_SIZE_RANGE is compatibility-only).
  GLfloat range[2] = {1.0f, 1.0f};
  glGetFloatv(GL_POINT_SIZE_RANGE, range);
  gl::checkErrors("TrackDepositPass (GL_POINT_SIZE_RANGE)");
  maxExtent_ = static_cast<int>(std::floor(range[1])) - 2;
}

void TrackDepositPass::run(const PatchTextures& before, const PatchTextures& after, const gl::Texture2D& trackInfo,
                           std::size_t count, AtlasTargets& atlas, const TrackDepositUniforms& uniforms) const {
  if (atlas.mode() != DepositMode::Accumulate)
    throw RuntimeError("TrackDepositPass: the track kernel deposits in accumulate mode only (the atlas is in max mode)");
  const AtlasLayout& target = atlas.layout();
  if (target.dims != layout_.dims || target.tiles != layout_.tiles || target.size != layout_.size)
    throw RuntimeError("TrackDepositPass: the atlas has another layout than the pass was built for");
  if (uniforms.maxExtentVoxels < 0 || uniforms.maxExtentVoxels > maxExtent_) {
    throw RuntimeError("TrackDepositPass: maxExtentVoxels " + std::to_string(uniforms.maxExtentVoxels) +
                       " needs points of " + std::to_string(uniforms.maxExtentVoxels + 2) +
                       " texels, but this GL draws points of at most " + std::to_string(maxExtent_ + 2) +
                       " (GL_POINT_SIZE_RANGE); use a smaller bound (at most " + std::to_string(maxExtent_) + ")");
  }
  if (uniforms.grid.dims != layout_.dims)
    throw RuntimeError("TrackDepositPass: the grid uniforms' dims differ from the atlas layout's");
  if (count == 0) return;

  gl::ScopedPassBindings unbind;
  atlas.framebuffer().bind();
  program_.use();
  before.bind(program_, "uBefore", kBeforeUnit);
  after.bind(program_, "uAfter", kAfterUnit);
  trackInfo.bind(kTrackInfoUnit);
  program_.setSampler("uTrackInfo", kTrackInfoUnit);
  uniforms.grid.set(program_);
  program_.set("uInvVoxelVolume", 1.0f / uniforms.grid.voxelVolume);
  program_.set("uDimIrradiance", uniforms.dimIrradiance);
  program_.set("uClipEnabled", uniforms.receiverEnabled);
  program_.set("uReceiverPoint", uniforms.receiverPoint);
  program_.set("uReceiverNormal", uniforms.receiverNormal);
  const int slices = uniforms.maxExtentVoxels + 2;  // S: z-slices (and the largest point side) a patch needs
  program_.set("uSpan", slices);
  vao_.bind();
  {
    gl::ScopedBlendAdd blend;
    ScopedProgramPointSize pointSize;
    // One vertex per (patch, slice): patch = uFirstPatch + gl_VertexID / S. Batches keep
    // gl_VertexID within an int however long the list.
    const std::size_t perBatch = static_cast<std::size_t>(INT_MAX) / static_cast<std::size_t>(slices);
    for (std::size_t first = 0; first < count; first += perBatch) {
      const std::size_t n = std::min(perBatch, count - first);
      program_.set("uFirstPatch", static_cast<int>(first));
      glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(n * static_cast<std::size_t>(slices)));
    }
  }
  gl::checkErrors("TrackDepositPass");
}

}  // namespace eik::gpu
