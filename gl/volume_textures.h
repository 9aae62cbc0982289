// Volume upload: the fields of an eik::Volume (docs/volume-format.md) packed into as few 3D float textures
// as a fixed, co-sampling-friendly grouping allows, and the layout as GLSL #defines so shaders are
// specialised per volume (no uniform branches, docs/architecture.md). The grouping (thesis §6.1 T1–T8):
//
//   texture     channels                         sampled together when
//   optics      ior (r), ior_grad (gba)          every ray step (Eq. 5.11/5.12)
//   absorption  sigma_a (rgb), dispersion (a)    attenuation / per-wavelength n
//   emission    emission (rgb)
//   scatter     scatter (rg: albedo, HG g)
//   irradiance  irradiance (rgb)                 in-scattering, with scatter and light_dir
//   light_dir   light_dir (rgb)
//   opaque      opaque (rgba)
//   reflect     reflect (rgba)
//   interfaces  interfaces (rgba; or the used slots' r, rg: VolumeTextureOptions::interface_slots)
//                                                crossing sharp interfaces (core/interfaces.h)
//
// Groups with no field present are dropped and the rest numbered 0, 1, ...; within a group the
// fields present take consecutive channels in the order above (ior_grad alone is rgb). Each
// texture gets the float format of its channel count (R32F ... RGBA32F; 16-bit with `half`; RGBA
// always with `padToRGBA`).
// Fields that docs/volume-format.md does not define are not uploaded (listed in ignored()).
// Texture coordinates: voxel (i,j,k) is sampled at ((i,j,k) + 0.5) / dims, x fastest.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/volume.h"
#include "gl/program.h"
#include "gl/texture.h"

namespace eik::gl {

struct VolumeFieldSlot {
  std::string field;   // "ior_grad"
  int texture = 0;     // index into the volume's textures
  int channel = 0;     // first channel (0 = r)
  int components = 1;  // channels used
  std::string swizzle() const;  // "gba"
};

struct VolumeTextureSlot {
  std::string group;                   // "optics"
  int channels = 0;                    // channels the texture has
  std::vector<VolumeFieldSlot> fields;
};

class VolumeTextureLayout {
 public:
  // The grouping above applied to the fields present (name, components); RuntimeError when a
  // known field has the wrong number of components.
  static VolumeTextureLayout plan(const std::vector<std::pair<std::string, int>>& fields, bool padToRGBA = false);
  // `interface_slots` > 0: the interfaces field's first that many distances alone (the used slots').
  static VolumeTextureLayout plan(const Volume& volume, bool padToRGBA = false,
                                  const std::vector<std::string>& leave_out = {}, int interface_slots = 0);

  const std::vector<VolumeTextureSlot>& textures() const { return textures_; }
  int textureCount() const { return static_cast<int>(textures_.size()); }
  const VolumeFieldSlot* find(std::string_view field) const;
  const std::vector<std::string>& ignored() const { return ignored_; }

  // The sampler uniform of texture i: "uVolumeTex0", "uVolumeTex1", ...
  static std::string samplerName(int texture);

  // For each field present, e.g. for sigma_a in texture 1:
  //   #define HAS_SIGMA_A 1
  //   #define SIGMA_A_TEX 1
  //   #define SIGMA_A_SAMPLER uVolumeTex1
  //   #define SIGMA_A_CHANNEL 0
  //   #define SIGMA_A_SWZ rgb
  // plus VOLUME_TEXTURE_COUNT. Absent fields get nothing. shaders/common/volume.glsl declares the
  // samplers and sampling functions from these.
  std::string glslDefines() const;

 private:
  std::vector<VolumeTextureSlot> textures_;
  std::vector<std::string> ignored_;
};

struct VolumeTextureOptions {
  bool half = false;        // RGBA16F & co. instead of 32-bit floats
  bool padToRGBA = false;   // every texture RGBA (some drivers store RGB as RGBA anyway)
  Sampling sampling{};      // linear, clamp to edge
  // Texture memory the volume may take; 0 = defaultTextureBudget().
  std::size_t budgetBytes = 0;
  std::string source = "volume";  // for error messages: the manifest path
  // Fields not uploaded (and not in the layout): what a shader takes elsewhere, e.g. the viewer's
  // σa where every material has one constant (MEDIUM_SIGMA_A).
  std::vector<std::string> leave_out;
  // > 0: only the first this many of the interfaces' four distances are uploaded (the used slots';
  // the shader fills in the others' constant, INTERFACES_UNUSED): one or two slots make an R32F or
  // RG32F texture, a quarter or half of RGBA32F.
  int interface_slots = 0;
};

// EIKONAL_GL_TEXTURE_BUDGET_MB, else 4096 MiB.
std::size_t defaultTextureBudget();

class VolumeTextures {
 public:
  VolumeTextures() = default;
  // Checks dims against GL_MAX_3D_TEXTURE_SIZE and the memory against the budget (InputError
  // naming the volume size and the limit), then uploads every known field.
  explicit VolumeTextures(const Volume& volume, const VolumeTextureOptions& options = {});

  const VolumeTextureLayout& layout() const { return layout_; }
  const std::vector<Texture3D>& textures() const { return textures_; }
  const Texture3D& texture(int index) const { return textures_.at(static_cast<std::size_t>(index)); }
  std::size_t bytes() const;
  glm::ivec3 dims() const { return dims_; }

  // Binds texture i to unit firstUnit + i and points `program`'s uVolumeTex<i> at it.
  // Returns the next free unit.
  int bind(const Program& program, int firstUnit = 0) const;

 private:
  VolumeTextureLayout layout_;
  std::vector<Texture3D> textures_;
  glm::ivec3 dims_{0};
};

}  // namespace eik::gl
