// Volume upload: grouping, GLSL layout defines, limits and packing (see volume_textures.h).
#include "gl/volume_textures.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"

namespace eik::gl {
namespace {

struct GroupSpec {
  const char* group;
  std::vector<std::pair<const char*, int>> fields;  // name, components, in channel order
};

// The fixed preferred grouping (volume_textures.h): co-sampled fields share a texture.
const std::vector<GroupSpec>& groups() {
  static const std::vector<GroupSpec> table = {
      {"optics", {{"ior", 1}, {"ior_grad", 3}}},
      {"absorption", {{"sigma_a", 3}, {"dispersion", 1}}},
      {"emission", {{"emission", 3}}},
      {"scatter", {{"scatter", 2}}},
      {"irradiance", {{"irradiance", 3}}},
      {"light_dir", {{"light_dir", 3}}},
      {"opaque", {{"opaque", 4}}},
      {"reflect", {{"reflect", 4}}},
      {"interfaces", {{"interfaces", 4}}},
  };
  return table;
}

std::string upper(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::toupper(c); });
  return out;
}

std::string dimsText(glm::ivec3 dims) {
  return std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" + std::to_string(dims.z);
}

std::string bytesText(std::size_t bytes) {
  char buffer[64];
  if (bytes >= (std::size_t(1) << 30)) {
    std::snprintf(buffer, sizeof buffer, "%.2f GiB", static_cast<double>(bytes) / double(1 << 30));
  } else {
    std::snprintf(buffer, sizeof buffer, "%.1f MiB", static_cast<double>(bytes) / double(1 << 20));
  }
  return buffer;
}

}  // namespace

std::string VolumeFieldSlot::swizzle() const { return std::string("rgba").substr(static_cast<std::size_t>(channel), static_cast<std::size_t>(components)); }

VolumeTextureLayout VolumeTextureLayout::plan(const std::vector<std::pair<std::string, int>>& fields, bool padToRGBA) {
  VolumeTextureLayout layout;
  auto componentsOf = [&](std::string_view name) {
    for (const auto& [fieldName, components] : fields) {
      if (fieldName == name) return components;
    }
    return 0;
  };
  for (const GroupSpec& group : groups()) {
    VolumeTextureSlot slot;
    slot.group = group.group;
    int channel = 0;
    for (const auto& [name, components] : group.fields) {
      int have = componentsOf(name);
      if (have != 0) {
        // The interfaces' distances may be uploaded for the used slots alone (their first channels).
        const bool prefix = std::string_view(name) == "interfaces" && have < components;
        if (have != components && !prefix) {
          throw RuntimeError("field " + std::string(name) + " has " + std::to_string(have) +
                             " components, expected " + std::to_string(components));
        }
        slot.fields.push_back({name, static_cast<int>(layout.textures_.size()), channel, have});
        channel += have;
        slot.channels = channel;
      }
    }
    if (slot.fields.empty()) continue;
    // Padded to RGBA; not a texture of one or two channels holding the used slots' distances
    // (R32F and RG32F are native formats; RGB is what llvmpipe samples slowly).
    const bool used_slots = slot.group == std::string_view("interfaces") && slot.channels < 3;
    if (padToRGBA && !used_slots) slot.channels = 4;
    layout.textures_.push_back(std::move(slot));
  }
  for (const auto& [name, components] : fields) {
    if (!layout.find(name)) layout.ignored_.push_back(name);
  }
  return layout;
}

VolumeTextureLayout VolumeTextureLayout::plan(const Volume& volume, bool padToRGBA,
                                              const std::vector<std::string>& leave_out, int interface_slots) {
  std::vector<std::pair<std::string, int>> fields;
  for (const auto& [name, field] : volume.fields) {
    if (std::find(leave_out.begin(), leave_out.end(), name) != leave_out.end()) continue;
    const bool first_slots = name == "interfaces" && interface_slots > 0 && interface_slots < field.components;
    fields.emplace_back(name, first_slots ? interface_slots : field.components);
  }
  return plan(fields, padToRGBA);
}

const VolumeFieldSlot* VolumeTextureLayout::find(std::string_view field) const {
  for (const VolumeTextureSlot& texture : textures_) {
    for (const VolumeFieldSlot& slot : texture.fields) {
      if (slot.field == field) return &slot;
    }
  }
  return nullptr;
}

std::string VolumeTextureLayout::samplerName(int texture) { return "uVolumeTex" + std::to_string(texture); }

std::string VolumeTextureLayout::glslDefines() const {
  std::string text = "#define VOLUME_TEXTURE_COUNT " + std::to_string(textures_.size()) + "\n";
  for (const VolumeTextureSlot& texture : textures_) {
    for (const VolumeFieldSlot& slot : texture.fields) {
      const std::string name = upper(slot.field);
      text += "#define HAS_" + name + " 1\n";
      text += "#define " + name + "_TEX " + std::to_string(slot.texture) + "\n";
      text += "#define " + name + "_SAMPLER " + samplerName(slot.texture) + "\n";
      text += "#define " + name + "_CHANNEL " + std::to_string(slot.channel) + "\n";
      text += "#define " + name + "_SWZ " + slot.swizzle() + "\n";
    }
  }
  return text;
}

std::size_t defaultTextureBudget() {
  if (const char* value = std::getenv("EIKONAL_GL_TEXTURE_BUDGET_MB"); value && *value) {
    char* end = nullptr;
    unsigned long long megabytes = std::strtoull(value, &end, 10);
    if (end && *end == '\0' && megabytes > 0) return static_cast<std::size_t>(megabytes) << 20;
    throw InputError("EIKONAL_GL_TEXTURE_BUDGET_MB", "", "'" + std::string(value) + "' is not a positive number");
  }
  return std::size_t(4096) << 20;
}

VolumeTextures::VolumeTextures(const Volume& volume, const VolumeTextureOptions& options)
    : layout_(VolumeTextureLayout::plan(volume, options.padToRGBA, options.leave_out, options.interface_slots)),
      dims_(volume.grid.dims) {
  const GlContext& context = detail::requireContext("uploading a volume");
  const int limit = context.info().max3DTextureSize;
  if (dims_.x < 1 || dims_.y < 1 || dims_.z < 1) {
    throw InputError(options.source, "dims", "volume of " + dimsText(dims_) + " voxels is empty");
  }
  if (dims_.x > limit || dims_.y > limit || dims_.z > limit) {
    throw InputError(options.source, "dims",
                     "volume of " + dimsText(dims_) + " voxels exceeds GL_MAX_3D_TEXTURE_SIZE (" +
                         std::to_string(limit) + ") of " + context.info().renderer);
  }
  const std::size_t voxels = volume.grid.count();
  std::size_t total = 0;
  std::string names;
  for (const VolumeTextureSlot& texture : layout_.textures()) {
    total += voxels * static_cast<std::size_t>(formatInfo(floatFormat(texture.channels, options.half)).bytesPerTexel);
    for (const VolumeFieldSlot& slot : texture.fields) names += (names.empty() ? "" : ", ") + slot.field;
  }
  const std::size_t budget = options.budgetBytes ? options.budgetBytes : defaultTextureBudget();
  if (total > budget) {
    throw InputError(options.source, "dims",
                     "volume of " + dimsText(dims_) + " voxels needs " + bytesText(total) + " of texture memory for " +
                         names + ", over the budget of " + bytesText(budget) +
                         " (EIKONAL_GL_TEXTURE_BUDGET_MB" + (options.half ? "" : "; or half floats") + ")");
  }
  for (const VolumeTextureSlot& texture : layout_.textures()) {
    for (const VolumeFieldSlot& slot : texture.fields) {
      const Field& field = volume.fields.at(slot.field);
      if (field.data.size() != voxels * static_cast<std::size_t>(field.components)) {
        throw InputError(options.source, slot.field,
                         "has " + std::to_string(field.data.size()) + " values, expected " +
                             std::to_string(voxels * static_cast<std::size_t>(field.components)) + " for " +
                             dimsText(dims_) + " voxels of " + std::to_string(field.components) + " components");
      }
    }
  }

  textures_.reserve(layout_.textures().size());
  for (const VolumeTextureSlot& texture : layout_.textures()) {
    const std::size_t channels = static_cast<std::size_t>(texture.channels);
    std::vector<float> packed;
    if (texture.fields.size() == 1 && static_cast<std::size_t>(texture.fields[0].components) == channels &&
        volume.fields.at(texture.fields[0].field).components == texture.channels) {
      const Field& field = volume.fields.at(texture.fields[0].field);
      textures_.emplace_back(dims_, floatFormat(texture.channels, options.half), field.data, texture.channels,
                             options.sampling);
      continue;
    }
    packed.assign(voxels * channels, 0.0f);
    for (const VolumeFieldSlot& slot : texture.fields) {
      const Field& field = volume.fields.at(slot.field);
      const std::size_t components = static_cast<std::size_t>(slot.components);  // the first of the field's
      const std::size_t stride = static_cast<std::size_t>(field.components);
      const std::size_t channel = static_cast<std::size_t>(slot.channel);
      for (std::size_t v = 0; v < voxels; ++v) {
        const float* src = field.data.data() + v * stride;
        float* dst = packed.data() + v * channels + channel;
        for (std::size_t c = 0; c < components; ++c) dst[c] = src[c];
      }
    }
    textures_.emplace_back(dims_, floatFormat(texture.channels, options.half), packed, texture.channels,
                           options.sampling);
  }
}

std::size_t VolumeTextures::bytes() const {
  std::size_t total = 0;
  for (const Texture3D& texture : textures_) total += texture.bytes();
  return total;
}

int VolumeTextures::bind(const Program& program, int firstUnit) const {
  int unit = firstUnit;
  for (std::size_t i = 0; i < textures_.size(); ++i, ++unit) {
    textures_[i].bind(unit);
    program.setSampler(VolumeTextureLayout::samplerName(static_cast<int>(i)), unit);
  }
  return unit;
}

}  // namespace eik::gl
