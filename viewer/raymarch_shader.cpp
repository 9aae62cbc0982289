// Assembly of the viewer's ray-casting shader (see raymarch_shader.h).
#include "viewer/raymarch_shader.h"

#include <algorithm>
#include <cstdio>

#include <algorithm>
#include <regex>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"

namespace eik {
namespace {

constexpr const char* kMainTemplate = "viewer/raymarch.frag";
constexpr const char* kObjectTemplate = "viewer/object.glsl";
constexpr const char* kVolumeAccessors = "common/volume.glsl";
constexpr std::string_view kObjectsSegment = "// @OBJECTS@";
constexpr std::string_view kEachObjectMark = "// @EACH_OBJECT@";

std::string replaceAll(std::string text, std::string_view from, std::string_view to) {
  for (std::size_t pos = 0; (pos = text.find(from, pos)) != std::string::npos; pos += to.size())
    text.replace(pos, from.size(), to);
  return text;
}

// `line` with every '@' replaced by each object's index in turn, the copies side by side after
// the line's indentation.
std::string repeatForEachObject(std::string_view line, std::size_t objects) {
  const std::size_t indent = std::min(line.find_first_not_of(' '), line.size());
  std::string copies(line.substr(0, indent));
  for (std::size_t k = 0; k < objects; ++k) {
    if (k) copies += ' ';
    copies += replaceAll(std::string(line.substr(indent)), "@", std::to_string(k));
  }
  return copies;
}

// Every line of `text` that ends in kEachObjectMark, repeated on that line once per object.
std::string expandEachObjectLines(const std::string& text, std::size_t objects) {
  std::string out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t mark = line.find(kEachObjectMark);
    if (mark != std::string::npos) {
      std::string_view body(line.data(), mark);
      while (!body.empty() && body.back() == ' ') body.remove_suffix(1);
      line = repeatForEachObject(body, objects);
    }
    out += line + "\n";
  }
  return out;
}

// The names of the functions a GLSL file defines (a return type at the start of the line).
std::vector<std::string> functionsDefinedIn(const std::string& text) {
  static const std::regex kFunction(R"(^(?:float|int|bool|[iu]?vec[234]|mat[234])\s+([A-Za-z_]\w*)\s*\()");
  std::vector<std::string> names;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::smatch match;
    if (std::regex_search(line, match, kFunction)) names.push_back(match[1].str());
  }
  return names;
}

// The names a block of "#define NAME VALUE" lines defines.
std::vector<std::string> definedNames(const std::string& defines) {
  std::vector<std::string> names;
  std::istringstream lines(defines);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string directive, name;
    if (words >> directive >> name && directive == "#define") names.push_back(name.substr(0, name.find('(')));
  }
  return names;
}

}  // namespace

std::string objectTextureSampler(std::size_t object, int texture) {
  return "uO" + std::to_string(object) + "Tex" + std::to_string(texture);
}

std::string objectBricksSampler(std::size_t object) { return "uO" + std::to_string(object) + "Bricks"; }

gl::ShaderDefines raymarchDefines(const RenderSettings& settings, const RaymarchScene& scene) {
  gl::ShaderDefines d;
  d.emplace_back("OBJECT_COUNT", std::to_string(scene.objects));
  // Segments of the march through the boxes: each box entered once or twice, and as many again
  // for the reflection traced after the ray (REFLECT_OBJECTS).
  const bool reflect_objects =
      settings.fresnel && settings.reflect_objects && settings.output == RenderOutput::Radiance;
  d.emplace_back("MAX_SEGMENTS", std::to_string((reflect_objects ? 2 : 1) * (2 * scene.objects + 1)));
  d.emplace_back("LIGHT_COUNT", std::to_string(std::min(scene.lights, kMaxLights)));
  if (settings.ground && scene.ground) d.emplace_back("GROUND", "1");
  if (settings.ground && scene.ground && scene.ground_map) d.emplace_back("GROUND_MAP", "1");
  if (settings.fresnel) d.emplace_back("FRESNEL", "1");
  if (reflect_objects) d.emplace_back("REFLECT_OBJECTS", "1");
  if (settings.attenuation) d.emplace_back("ATTENUATION", "1");
  if (settings.emission) d.emplace_back("EMISSION", "1");
  if (settings.scattering) d.emplace_back("SCATTERING", "1");
  if (!settings.refraction) d.emplace_back("NO_REFRACTION", "1");
  if (settings.integrator == RayIntegrator::RK4) d.emplace_back("RK4", "1");
  if (settings.homogeneous_bricks) d.emplace_back("SKIP_HOMOGENEOUS", "1");
  if (settings.skip_empty_space) d.emplace_back("SKIP_TO_SURFACES", "1");
  if (settings.output == RenderOutput::ExitPosition) d.emplace_back("OUTPUT_EXIT_POSITION", "1");
  else if (settings.output == RenderOutput::ExitDirection) d.emplace_back("OUTPUT_EXIT_DIRECTION", "1");
  else if (settings.dispersion && scene.dispersive) {
    d.emplace_back("DISPERSION", "1");
    if (settings.bands != 3) d.emplace_back("DISPERSION_BANDS", std::to_string(settings.bands));
  }
  for (const auto& e : scene.environment) d.push_back(e);
  return d;
}

gl::ShaderSource raymarchFragmentSource(const gl::ShaderLibrary& shaders, const gl::ShaderDefines& defines,
                                        const std::vector<RaymarchObject>& objects) {
  if (objects.empty()) throw RuntimeError("the ray-march shader needs at least one object");
  gl::ShaderSource source = shaders.source(kMainTemplate, defines);
  source.text = expandEachObjectLines(source.text, objects.size());
  const std::string main_text = shaders.read(kMainTemplate);
  const std::size_t marker_in_main = main_text.find(kObjectsSegment);
  const std::size_t marker = source.text.find(kObjectsSegment);
  if (marker == std::string::npos || marker_in_main == std::string::npos)
    throw RuntimeError(std::string(kMainTemplate) + " has no '" + std::string(kObjectsSegment) + "' line");
  const int marker_line = 1 + static_cast<int>(std::count(main_text.begin(), main_text.begin() + marker_in_main, '\n'));
  const std::string object_template = shaders.read(kObjectTemplate);
  const std::string accessors = shaders.read(kVolumeAccessors);
  const std::vector<std::string> accessor_functions = functionsDefinedIn(accessors);

  std::string out;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const std::string index = std::to_string(k);
    // The object's scope: its samplers and accessors renamed, then its volume layout.
    std::string scope;
    for (int t = 0; t < objects[k].layout.textureCount(); ++t)
      scope += "#define " + gl::VolumeTextureLayout::samplerName(t) + " " + objectTextureSampler(k, t) + "\n";
    for (const std::string& function : accessor_functions) scope += "#define " + function + " " + function + index + "\n";
    scope += objects[k].layout.glslDefines();
    if (objects[k].sharp_faces) scope += "#define SHARP_FACES 1\n";
    scope += objects[k].defines;
    const std::vector<std::string> names = definedNames(scope);

    out += scope;
    out += "#line 1 " + std::to_string(source.files.size()) + "\n";
    source.files.push_back(std::string(kVolumeAccessors) + " (object " + index + ")");
    out += accessors + "\n";
    out += "#line 1 " + std::to_string(source.files.size()) + "\n";
    source.files.push_back(std::string(kObjectTemplate) + " (object " + index + ")");
    out += replaceAll(object_template, "@", index) + "\n";
    for (const std::string& name : names) out += "#undef " + name + "\n";
  }
  out += "#line " + std::to_string(marker_line + 1) + " 0\n";
  const std::size_t line_end = source.text.find('\n', marker);
  source.text.replace(marker, line_end == std::string::npos ? std::string::npos : line_end + 1 - marker, out);
  return source;
}

std::string objectReceiverSampler(std::size_t object) { return "uO" + std::to_string(object) + "Receiver"; }

std::string interfaceDefines(const InterfaceTable& table) {
  if (table.empty()) return "";
  auto vec4Of = [&](auto value) {
    std::string text = "vec4(";
    for (int k = 0; k < 4; ++k) {
      char number[32];
      std::snprintf(number, sizeof number, "%.9g", k < static_cast<int>(table.slots.size())
                                                      ? static_cast<double>(value(table.slots[static_cast<std::size_t>(k)]))
                                                      : 0.0);
      text += std::string(k ? ", " : "") + number;
    }
    return text + ")";
  };
  std::string out = "#define INTERFACE_SLOTS " + std::to_string(table.slots.size()) + "\n";
  out += "#define SLOT_IOR " + vec4Of([](const InterfaceSlot& s) { return s.ior; }) + "\n";
  out += "#define SLOT_DISPERSION " + vec4Of([](const InterfaceSlot& s) { return s.dispersion_b; }) + "\n";
  out += "#define SLOT_GRADED " + vec4Of([](const InterfaceSlot& s) { return s.graded ? 1.0 : 0.0; }) + "\n";
  out += "#define SLOT_OPAQUE " + vec4Of([](const InterfaceSlot& s) { return s.opaque ? 1.0 : 0.0; }) + "\n";
  // No graded slot: n is a constant wherever the ray is, and the march never reads the ior field.
  if (constantSlots(table)) out += "#define CONSTANT_SLOTS 1\n";
  return out;
}

std::string slotMediumDefines(const SlotMedia& media) {
  auto number = [](double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", x);
    return std::string(text);
  };
  // A chain of selects on the material k, air last: constants only, so no fetch and no branch.
  auto perMaterial = [&](const char* name, const char* type, auto&& literal) {
    std::string out = std::string("#define ") + name + "(k) (";
    for (std::size_t m = 1; m < media.media.size(); ++m)
      out += "(k) == " + std::to_string(m - 1) + " ? " + type + "(" + literal(media.media[m]) + ") : ";
    return out + type + "(" + literal(media.media[0]) + "))\n";
  };
  std::string out;
  if (media.sigma_a_constant)
    out += perMaterial("MEDIUM_SIGMA_A", "vec3", [&](const MaterialMedium& m) {
      return number(m.sigma_a.x) + ", " + number(m.sigma_a.y) + ", " + number(m.sigma_a.z);
    });
  if (media.scatter_constant)
    out += perMaterial("MEDIUM_SCATTER", "vec2", [&](const MaterialMedium& m) {
      return number(m.scatter.x) + ", " + number(m.scatter.y);
    });
  if (media.air_box) {
    // The air's medium is the smoke's, over the share of each step inside its box (mediumShare@).
    SlotMedia boxed = media;
    boxed.air_box.reset();
    boxed.media[0] = MaterialMedium{media.air_box->sigma_a, media.air_box->scatter};
    auto vec3Of = [&](const glm::dvec3& v) { return "vec3(" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + ")"; };
    return slotMediumDefines(boxed) + "#define AIR_BOX 1\n#define AIR_BOX_MIN " + vec3Of(media.air_box->lo) +
           "\n#define AIR_BOX_MAX " + vec3Of(media.air_box->hi) + "\n";
  }
  return out;
}

}  // namespace eik
