// The viewer's renderer (thesis §6.3): every object of a LoadedScene as a bounding-box proxy, one
// curved viewing ray per pixel in a single full-screen pass (shaders/viewer/raymarch.frag), carried
// from the eye through the objects it meets, nearest box first, so one object is seen through
// another; in each object's own space (x' = M⁻¹x, ∇n' = M⁻ᵀ∇n, §6.3.1) the ray is marched through
// the box of the volume's non-trivial region (shaders/viewer/object.glsl, one instance per object)
// with the image formation of Eq. 5.10 (in-scattering of the bake, Fresnel, Beer–Lambert,
// emission, opaque embeddings), then it meets the ground plane or the environment
// (viewer/environment.h). Output is linear HDR radiance; tone mapping is the caller's.
// Where a volume's material touches its box, the faces are sharp interfaces (Snell, Fresnel).
// Limit: objects' boxes should not overlap (a ray marches one box at a time).
// The shader is assembled by viewer/raymarch_shader.h, from what viewer/volume_analysis.h finds in
// each volume; viewer/IMAGE_FORMATION.md maps each equation to its code.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "core/image_io.h"
#include "gl/framebuffer.h"
#include "gl/shader_library.h"
#include "viewer/camera.h"
#include "viewer/loaded_scene.h"
#include "viewer/render_settings.h"

namespace eik {

class SceneRenderer {
 public:
  // Needs a current GL context (kept current while the renderer is used and destroyed). Uploads
  // every object's volume and the environment map; InputError naming the file and field if a
  // volume lacks ior/ior_grad, is too large for the GPU, or the environment map cannot be read.
  // Keeps a reference to `shaders` (setSettings recompiles): it must outlive the renderer.
  // What the constructor computes on the CPU and needs no GL context for: each object's ground
  // texels (its receiver map with the shadow's edge, viewer/shadow_edge.h; 0.03 s for an 840² map
  // on two cores), made beforehand — the headless viewer makes them while its driver loads
  // (gl::DriverPreload). A constructor given them builds the renderer it would build without.
  struct Preparation {
    std::vector<std::optional<std::vector<std::uint16_t>>> ground_texels;  // per object, RGBA16F; none: no map
  };
  static Preparation prepare(const LoadedScene& scene);
  // Gives up what the renderer will not read once `prepared` holds it: a lone object's receiver map
  // irradiance (made into its texels; a ground map of two or more objects reads the maps
  // themselves, so theirs are kept). The textures uploaded next reuse its memory (12 MB at 1024²
  // texels). The headless viewer calls it; a window, which may re-bake, keeps its maps.
  static void releasePrepared(LoadedScene& scene, const Preparation& prepared);

  SceneRenderer(const gl::ShaderLibrary& shaders, const LoadedScene& scene, const RenderSettings& settings,
                const Preparation* prepared = nullptr);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // May recompile shader variants (cheap when nothing that selects a variant changed).
  void setSettings(const RenderSettings& settings);
  const RenderSettings& settings() const;

  // The direction the light travels (world), for the parts that are not baked: the ground outside
  // the volumes and the sky's sun. Starts as the scene's first directional light.
  void setLightDirection(glm::dvec3 world_dir);
  glm::dvec3 lightDirection() const;

  // Linear HDR radiance into the currently bound framebuffer (RGBA32F), viewport (0,0,size).
  void draw(const Camera& camera, glm::ivec2 size);
  // Offscreen RGBA32F target + readback; rows top to bottom.
  Image render(const Camera& camera, glm::ivec2 size);

  int objectCount() const;  // objects drawn (all of the scene's)
  // Whether the ground is shaded from one ground map (viewer/ground_map.h: two or more objects
  // have a receiver map) rather than from each object's map.
  bool usesGroundMap() const;
  // The GPU memory the objects' volume fields take (their 3D textures; not the receiver maps,
  // bricks or environment).
  std::size_t volumeTextureBytes() const;
  // Replaces object `index`'s volume (a fresh bake of it: viewer/background_bake.h) and uploads it;
  // recompiles the shader only when what selects its variant changed (its fields, interfaces,
  // receiver). Same errors as the constructor; std::out_of_range for a bad index.
  void replaceVolume(int index, const LoadedObject& object);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Attachment 0 of an RGBA32F framebuffer as a linear RGBA image, rows top to bottom.
Image readLinearImage(const gl::Framebuffer& target);

}  // namespace eik
