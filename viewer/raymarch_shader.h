// The viewer's ray-casting fragment shader, assembled from the GLSL templates of shaders/viewer/
// (no GL needed: the text only; SceneRenderer compiles it). The one place where shader text is
// stitched together:
//
//   viewer/raymarch.frag   the skeleton: a ray per pixel through the objects it meets, then the
//                          ground or the environment (Eq. 5.10), with named segments:
//     "// @OBJECTS@"          replaced by one instance of viewer/object.glsl per object (march0,
//                             march1, ...), every '@' in it the object's index;
//     "... // @EACH_OBJECT@"  a line repeated once per object ('@' its index), on one line so the
//                             line numbers stay: the dispatch marchObject(k) → march<k>.
//
// An object's instance sits in its own scope of #defines, #undef'd after it: its volume layout
// (gl::VolumeTextureLayout::glslDefines: HAS_<FIELD>, <FIELD>_SAMPLER, <FIELD>_SWZ), the renaming
// of common/volume.glsl's samplers (uVolumeTex<t> → uO<k>Tex<t>) and of every function it
// defines (volumeSigmaA → volumeSigmaA<k>), then common/volume.glsl itself and object.glsl. So
// each object samples its own textures through the same accessors, with no branches on uniforms
// (llvmpipe executes uniform branches even when false, so variants are built with #defines) and
// no sampler array (GLSL 3.30 cannot index one with a variable).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/interfaces.h"
#include "gl/shader_library.h"
#include "gl/shader_source.h"
#include "gl/volume_textures.h"
#include "viewer/render_settings.h"
#include "viewer/volume_analysis.h"

namespace eik {

// Lights the shader takes (LIGHT_COUNT); the scene's first ones.
constexpr std::size_t kMaxLights = 8;

// What of the scene, besides RenderSettings, selects the shader variant.
struct RaymarchScene {
  std::size_t objects = 1;
  std::size_t lights = 0;           // the scene's; the shader takes kMaxLights at most
  bool ground = false;              // the scene has a ground plane
  bool ground_map = false;          // and a ground map (ground_map.h: two or more receiver maps)
  bool dispersive = false;          // some object's volume has a dispersion field
  gl::ShaderDefines environment;    // Environment::defines()
};

// The program-wide defines: OBJECT_COUNT, MAX_SEGMENTS, LIGHT_COUNT, the terms of Eq. 5.10 that
// are on (GROUND, FRESNEL, ATTENUATION, EMISSION, SCATTERING, DISPERSION), GROUND_MAP, NO_REFRACTION, RK4,
// SKIP_HOMOGENEOUS, OUTPUT_EXIT_POSITION / OUTPUT_EXIT_DIRECTION and the environment's ENV_*.
gl::ShaderDefines raymarchDefines(const RenderSettings& settings, const RaymarchScene& scene);

// What of one object shapes its instance of object.glsl.
struct RaymarchObject {
  gl::VolumeTextureLayout layout;  // of its volume's textures
  bool sharp_faces = false;        // the material touches the box (volume_analysis.h): SHARP_FACES
  // Further #define lines of its scope (#undef'd after it): its sharp interfaces' slots
  // (INTERFACE_SLOTS, SLOT_IOR, ...; interfaceDefines) and HAS_RECEIVER.
  std::string defines;
};

// The per-object defines of a volume's sharp interfaces (core/interfaces.h): INTERFACE_SLOTS (the
// slot count), SLOT_IOR, SLOT_DISPERSION, SLOT_GRADED and SLOT_OPAQUE (vec4 literals, one entry a
// slot); "" for a table without slots.
std::string interfaceDefines(const InterfaceTable& table);

// The per-object defines of the constant media of its materials (volume_analysis.h slotMedia):
// MEDIUM_SIGMA_A(k) (vec3) where σa is constant in every material, MEDIUM_SCATTER(k) (vec2: ω̂, g)
// where scattering is, k the material the ray is in (−1 air, else the slot); "" where neither is.
std::string slotMediumDefines(const SlotMedia& media);

// The sampler uniform of object k's receiver map (HAS_RECEIVER).
std::string objectReceiverSampler(std::size_t object);

// raymarch.frag with `defines`, its segments filled for `objects` (in the scene's order; at least
// one). RuntimeError when a template lacks its segment.
gl::ShaderSource raymarchFragmentSource(const gl::ShaderLibrary& shaders, const gl::ShaderDefines& defines,
                                        const std::vector<RaymarchObject>& objects);

// The sampler uniforms of object k: its volume's texture t, and its homogeneous bricks.
std::string objectTextureSampler(std::size_t object, int texture);
std::string objectBricksSampler(std::size_t object);

}  // namespace eik
