#include "viewer/scene_renderer.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "gl/framebuffer.h"
#include "gl/gl.h"
#include "gl/program.h"
#include "gl/vertex_array.h"
#include "gl/volume_textures.h"
#include "viewer/environment.h"

namespace eik {
namespace {

constexpr int kMaxLights = 8;
constexpr const char* kObjectsMarker = "// @OBJECTS@";

// The box (in the volume's own coordinates) of the voxels where something happens: n ≠ 1, ∇n ≠ 0,
// absorption, emission, scattering or an opaque embedding; one voxel of margin for the trilinear
// filter. Outside it a ray goes straight and gathers nothing (empty-space skipping). Returns false
// when the volume is empty throughout.
bool activeRegion(const Volume& volume, glm::dvec3& lo, glm::dvec3& hi) {
  const GridSpec& grid = volume.grid;
  const glm::ivec3 dims = grid.dims;
  glm::ivec3 imin(dims), imax(-1);
  auto mark = [&](std::size_t index) {
    const int x = static_cast<int>(index % static_cast<std::size_t>(dims.x));
    const int y = static_cast<int>((index / static_cast<std::size_t>(dims.x)) % static_cast<std::size_t>(dims.y));
    const int z = static_cast<int>(index / (static_cast<std::size_t>(dims.x) * static_cast<std::size_t>(dims.y)));
    imin = glm::min(imin, glm::ivec3(x, y, z));
    imax = glm::max(imax, glm::ivec3(x, y, z));
  };
  const std::size_t count = grid.count();
  const double h = std::min({grid.voxelSize().x, grid.voxelSize().y, grid.voxelSize().z});
  auto scan = [&](const char* name, auto&& nontrivial) {
    const Field* f = volume.find(name);
    if (!f) return;
    for (std::size_t i = 0; i < count; ++i)
      if (nontrivial(f->voxel(i))) mark(i);
  };
  scan("ior", [](const float* v) { return std::abs(v[0] - 1.0f) > 1e-5f; });
  scan("ior_grad", [&](const float* v) { return (std::abs(v[0]) + std::abs(v[1]) + std::abs(v[2])) * h > 1e-6; });
  scan("sigma_a", [](const float* v) { return v[0] > 0 || v[1] > 0 || v[2] > 0; });
  scan("emission", [](const float* v) { return v[0] > 0 || v[1] > 0 || v[2] > 0; });
  scan("scatter", [](const float* v) { return v[0] > 0; });
  scan("opaque", [](const float* v) { return v[3] > 0; });
  if (imax.x < 0) return false;
  const glm::dvec3 voxel = grid.voxelSize();
  lo = glm::max(grid.bounds_min, grid.bounds_min + glm::dvec3(imin - 1) * voxel);
  hi = glm::min(grid.bounds_max, grid.bounds_min + glm::dvec3(imax + 2) * voxel);
  return true;
}

// Bricks of kBrickVoxels³ voxels where the medium is homogeneous: n constant and ∇n ≈ 0, σa
// constant, no emission, scattering or opaque embedding, over the brick and kBrickMargin voxels
// around it (the trilinear filter and the last step's reach). A ray crossing such a brick goes
// straight, with T·exp(−σa·L): it crosses it in one step (thesis §6.3 leaves the step size free;
// DESIGN asks for skipping the interior of homogeneous glass). 1 = homogeneous, 0 = march.
constexpr int kBrickVoxels = 4;
constexpr int kBrickMargin = 2;

std::vector<float> homogeneousBricks(const Volume& volume, glm::ivec3& brick_dims) {
  const GridSpec& grid = volume.grid;
  const glm::ivec3 dims = grid.dims;
  brick_dims = (dims + kBrickVoxels - 1) / kBrickVoxels;
  const double h = std::min({grid.voxelSize().x, grid.voxelSize().y, grid.voxelSize().z});
  const Field* ior = volume.find("ior");
  const Field* grad = volume.find("ior_grad");
  const Field* sigma = volume.find("sigma_a");
  const Field* emission = volume.find("emission");
  const Field* scatter = volume.find("scatter");
  const Field* opaque = volume.find("opaque");
  // Per voxel: does it break homogeneity by itself (∇n, emission, scattering, opaque)?
  std::vector<unsigned char> busy(grid.count(), 0);
  for (std::size_t i = 0; i < grid.count(); ++i) {
    const float* g = grad->voxel(i);
    bool b = (std::abs(g[0]) + std::abs(g[1]) + std::abs(g[2])) * h > 1e-4;
    if (emission) b = b || emission->voxel(i)[0] > 0 || emission->voxel(i)[1] > 0 || emission->voxel(i)[2] > 0;
    if (scatter) b = b || scatter->voxel(i)[0] > 0;
    if (opaque) b = b || opaque->voxel(i)[3] > 0;
    busy[i] = b;
  }
  std::vector<float> bricks(static_cast<std::size_t>(brick_dims.x) * brick_dims.y * brick_dims.z, 0.0f);
  for (int bz = 0; bz < brick_dims.z; ++bz)
    for (int by = 0; by < brick_dims.y; ++by)
      for (int bx = 0; bx < brick_dims.x; ++bx) {
        const glm::ivec3 lo = glm::max(glm::ivec3(bx, by, bz) * kBrickVoxels - kBrickMargin, glm::ivec3(0));
        const glm::ivec3 hi = glm::min(glm::ivec3(bx, by, bz) * kBrickVoxels + kBrickVoxels + kBrickMargin, dims) - 1;
        const std::size_t first = grid.index(lo.x, lo.y, lo.z);
        bool homogeneous = true;
        for (int k = lo.z; k <= hi.z && homogeneous; ++k)
          for (int j = lo.y; j <= hi.y && homogeneous; ++j)
            for (int i = lo.x; i <= hi.x && homogeneous; ++i) {
              const std::size_t v = grid.index(i, j, k);
              if (busy[v] || std::abs(ior->data[v] - ior->data[first]) > 1e-4f) homogeneous = false;
              if (sigma)
                for (int c = 0; c < 3; ++c)
                  if (std::abs(sigma->voxel(v)[c] - sigma->voxel(first)[c]) > 1e-6f * (1.0f + sigma->voxel(first)[c]))
                    homogeneous = false;
            }
        bricks[(static_cast<std::size_t>(bz) * brick_dims.y + by) * brick_dims.x + bx] = homogeneous ? 1.0f : 0.0f;
      }
  return bricks;
}

// The box (volume coordinates) of the voxels with σa > 0, one voxel of margin; false when none.
// Rays fetch σa only inside it (a second texture fetch a step is what absorption costs).
// Whether the material touches the box: n ≠ 1 in a voxel of one of its faces. Such faces are sharp
// interfaces (object.glsl, SHARP_FACES), as smoothing never saw the air beyond them.
bool materialTouchesBox(const Volume& volume) {
  const GridSpec& grid = volume.grid;
  const Field* ior = volume.find("ior");
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const bool face = i == 0 || j == 0 || k == 0 || i == grid.dims.x - 1 || j == grid.dims.y - 1 ||
                          k == grid.dims.z - 1;
        if (face && std::abs(ior->data[grid.index(i, j, k)] - 1.0f) > 1e-3f) return true;
      }
  return false;
}

bool absorbingRegion(const Volume& volume, glm::dvec3& lo, glm::dvec3& hi) {
  const Field* sigma = volume.find("sigma_a");
  if (!sigma) return false;
  const GridSpec& grid = volume.grid;
  glm::ivec3 imin(grid.dims), imax(-1);
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const float* v = sigma->voxel(grid.index(i, j, k));
        if (v[0] > 0 || v[1] > 0 || v[2] > 0) {
          imin = glm::min(imin, glm::ivec3(i, j, k));
          imax = glm::max(imax, glm::ivec3(i, j, k));
        }
      }
  if (imax.x < 0) return false;
  const glm::dvec3 voxel = grid.voxelSize();
  lo = glm::max(grid.bounds_min, grid.bounds_min + glm::dvec3(imin - 1) * voxel);
  hi = glm::min(grid.bounds_max, grid.bounds_min + glm::dvec3(imax + 2) * voxel);
  return true;
}

std::string replaceAll(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t pos = 0; (pos = text.find(from, pos)) != std::string::npos; pos += to.size())
    text.replace(pos, from.size(), to);
  return text;
}

}  // namespace

struct SceneRenderer::Impl {
  struct Object {
    std::string source;
    GridSpec grid;
    glm::dmat4 to_world{1.0}, to_volume{1.0};
    gl::VolumeTextures textures;
    bool has_region = false;
    glm::dvec3 region_min{0.0}, region_max{0.0};
    glm::dvec3 absorbing_min{1e30}, absorbing_max{-1e30};  // empty unless σa > 0 somewhere
    bool has_dispersion = false;
    bool sharp_faces = false;  // materialTouchesBox
    gl::Texture3D bricks;  // homogeneousBricks, nearest filtering
    glm::ivec3 brick_dims{0};
  };

  const gl::ShaderLibrary& shaders;
  Scene scene;
  RenderSettings settings;
  std::vector<Object> objects;
  Environment environment;
  glm::dvec3 light_direction{0.0, -1.0, 0.0};
  glm::vec3 sun_irradiance{0.0f};
  gl::Program program;
  std::string program_key;  // the defines the program was built with
  gl::FullscreenTriangle triangle;

  Impl(const gl::ShaderLibrary& library, const LoadedScene& loaded)
      : shaders(library), scene(loaded.scene), environment(loaded.scene.environment, loaded.scene.base_dir, loaded.source) {}

  gl::ShaderDefines defines() const {
    gl::ShaderDefines d;
    d.emplace_back("OBJECT_COUNT", std::to_string(objects.size()));
    d.emplace_back("MAX_SEGMENTS", std::to_string(2 * objects.size() + 1));
    d.emplace_back("LIGHT_COUNT", std::to_string(std::min<std::size_t>(scene.lights.size(), kMaxLights)));
    if (settings.ground && scene.ground) d.emplace_back("GROUND", "1");
    if (settings.fresnel) d.emplace_back("FRESNEL", "1");
    if (settings.attenuation) d.emplace_back("ATTENUATION", "1");
    if (settings.emission) d.emplace_back("EMISSION", "1");
    if (settings.scattering) d.emplace_back("SCATTERING", "1");
    if (!settings.refraction) d.emplace_back("NO_REFRACTION", "1");
    if (settings.integrator == RayIntegrator::RK4) d.emplace_back("RK4", "1");
    if (settings.homogeneous_bricks) d.emplace_back("SKIP_HOMOGENEOUS", "1");
    const bool dispersive = std::any_of(objects.begin(), objects.end(), [](const Object& o) { return o.has_dispersion; });
    if (settings.output == RenderOutput::ExitPosition) d.emplace_back("OUTPUT_EXIT_POSITION", "1");
    else if (settings.output == RenderOutput::ExitDirection) d.emplace_back("OUTPUT_EXIT_DIRECTION", "1");
    else if (settings.dispersion && dispersive) d.emplace_back("DISPERSION", "1");
    for (const auto& e : environment.defines()) d.push_back(e);
    return d;
  }

  // raymarch.frag with its "// @OBJECTS@" line replaced by one instance of object.glsl per object
  // (each inside its own volume layout's #defines) and the dispatch functions.
  gl::ShaderSource fragmentSource(const gl::ShaderDefines& defs) const {
    gl::ShaderSource source = shaders.source("viewer/raymarch.frag", defs);
    const std::string main_text = shaders.read("viewer/raymarch.frag");
    const std::size_t marker_in_main = main_text.find(kObjectsMarker);
    const std::size_t marker = source.text.find(kObjectsMarker);
    if (marker == std::string::npos || marker_in_main == std::string::npos)
      throw RuntimeError("viewer/raymarch.frag has no '" + std::string(kObjectsMarker) + "' line");
    const int marker_line = 1 + static_cast<int>(std::count(main_text.begin(), main_text.begin() + marker_in_main, '\n'));
    const std::string object_template = shaders.read("viewer/object.glsl");

    std::ostringstream out;
    for (std::size_t k = 0; k < objects.size(); ++k) {
      const std::string index = std::to_string(k);
      const gl::VolumeTextureLayout& layout = objects[k].textures.layout();
      std::string layout_defines =
          replaceAll(layout.glslDefines(), "uVolumeTex", "uO" + index + "Tex");
      std::vector<std::string> names;
      std::istringstream lines(layout_defines);
      for (std::string line; std::getline(lines, line);) {
        std::istringstream words(line);
        std::string directive, name;
        if (words >> directive >> name && directive == "#define") names.push_back(name);
      }
      if (objects[k].sharp_faces) layout_defines += "#define SHARP_FACES 1\n";
      out << layout_defines << "\n";
      for (int t = 0; t < layout.textureCount(); ++t) out << "uniform sampler3D uO" << index << "Tex" << t << ";\n";
      out << "uniform sampler3D uO" << index << "Bricks;\n";
      out << "#line 1 " << source.files.size() << "\n";
      out << replaceAll(object_template, "@", index) << "\n";
      for (const std::string& name : names) out << "#undef " << name << "\n";
      source.files.push_back("viewer/object.glsl (object " + index + ")");
    }
    out << "void marchObject(int k, inout Ray r, float cauchy) {\n";
    for (std::size_t k = 0; k < objects.size(); ++k)
      out << "  " << (k ? "else " : "") << "if (k == " << k << ") march" << k << "(r, cauchy);\n";
    out << "}\n#ifdef GROUND\nfloat bakedGroundIrradiance(vec3 xw, out vec3 E) {\n  float weight;\n";
    for (std::size_t k = 0; k < objects.size(); ++k)
      out << "  weight = bakedGroundIrradiance" << k << "(xw, E);\n  if (weight > 0.0) return weight;\n";
    out << "  E = vec3(0.0);\n  return 0.0;\n}\n#endif\n";
    out << "#line " << marker_line + 1 << " 0\n";
    const std::size_t line_end = source.text.find('\n', marker);
    source.text.replace(marker, line_end - marker, out.str());
    return source;
  }

  void buildProgram() {
    const gl::ShaderDefines defs = defines();
    std::string key;
    for (const auto& [name, value] : defs) key += name + "=" + value + ";";
    if (program && key == program_key) return;
    gl::ShaderSource vertex = shaders.source("common/fullscreen.vert");
    program = gl::Program(vertex, fragmentSource(defs));
    program_key = key;
  }

  void setUniforms(const Camera& camera, glm::ivec2 size) {
    const double aspect = static_cast<double>(size.x) / static_cast<double>(size.y);
    const gl::Program& p = program;
    p.set("uInvViewProj", glm::mat4(camera.inverseViewProjection(aspect)));
    p.set("uEye", glm::vec3(camera.eye));
    const float pixel_spread = static_cast<float>(2.0 * std::tan(glm::radians(camera.fov_y_deg) / 2) / size.y);
    p.set("uPixelSpread", pixel_spread);
    p.set("uMinTransmittance", static_cast<float>(settings.min_transmittance));
    p.set("uMaxOpticalDepth", static_cast<float>(-std::log(std::max(settings.min_transmittance, 1e-30))));

    int unit = 0;
    for (std::size_t k = 0; k < objects.size(); ++k) {
      const Object& o = objects[k];
      const std::string i = "[" + std::to_string(k) + "]";
      const glm::dvec3 voxel = o.grid.voxelSize();
      const double h = std::min({voxel.x, voxel.y, voxel.z});
      const double step = settings.step_voxels * h;
      const glm::dvec3 lo = settings.skip_empty_space ? o.region_min : o.grid.bounds_min;
      const glm::dvec3 hi = settings.skip_empty_space ? o.region_max : o.grid.bounds_max;
      p.set("uObjWorldToVol" + i, glm::mat4(o.to_volume));
      p.set("uObjVolToWorld" + i, glm::mat4(o.to_world));
      p.set("uObjBoundsMin" + i, glm::vec3(o.grid.bounds_min));
      p.set("uObjBoundsMax" + i, glm::vec3(o.grid.bounds_max));
      // An empty volume: a box no ray meets (it may still hold the ground's baked irradiance).
      p.set("uObjActiveMin" + i, o.has_region ? glm::vec3(lo) : glm::vec3(1e30f));
      p.set("uObjActiveMax" + i, o.has_region ? glm::vec3(hi) : glm::vec3(1e30f));
      p.set("uObjHalfVoxel" + i, glm::vec3(0.5 / glm::dvec3(o.grid.dims)));
      p.set("uObjAbsorbingMin" + i, glm::vec3(o.absorbing_min));
      p.set("uObjAbsorbingMax" + i, glm::vec3(o.absorbing_max));
      p.set("uObjStep" + i, static_cast<float>(step));
      p.set("uObjMaxSteps" + i, static_cast<int>(std::ceil(4.0 * glm::length(o.grid.extent()) / step)) + 16);
      p.set("uObjBoundaryGrad" + i, static_cast<float>(settings.boundary_threshold / h));
      for (int t = 0; t < o.textures.layout().textureCount(); ++t) {
        o.textures.texture(t).bind(unit);
        p.setSampler("uO" + std::to_string(k) + "Tex" + std::to_string(t), unit);
        ++unit;
      }
      o.bricks.bind(unit);
      p.setSampler("uO" + std::to_string(k) + "Bricks", unit);
      ++unit;
      p.set("uObjBrickSize" + i, glm::vec3(o.grid.extent() / glm::dvec3(o.grid.dims) * double(kBrickVoxels)));
    }

    // Lights: the first directional one follows setLightDirection.
    bool first_directional = true;
    const std::size_t light_count = std::min<std::size_t>(scene.lights.size(), kMaxLights);
    for (std::size_t l = 0; l < light_count; ++l) {
      const SceneLightSpec& light = scene.lights[l];
      const std::string i = "[" + std::to_string(l) + "]";
      if (light.type == SceneLightSpec::Type::Directional) {
        const glm::dvec3 dir = first_directional ? light_direction : glm::normalize(light.direction);
        first_directional = false;
        p.set("uLightPos" + i, glm::vec4(glm::vec3(dir), 0.0f));
        p.set("uLightPower" + i, glm::vec3(light.irradiance));
      } else {
        p.set("uLightPos" + i, glm::vec4(glm::vec3(light.position), 1.0f));
        p.set("uLightPower" + i, glm::vec3(light.intensity));
      }
    }

    const glm::vec3 ambient = environment.diffuseRadiance(glm::dvec3(0, 1, 0), light_direction);
    p.set("uAmbientRadiance", ambient);
    if (scene.ground) {
      const SceneGroundSpec& g = *scene.ground;
      const glm::dvec3 normal = glm::normalize(g.normal);
      const glm::dvec3 helper = std::abs(normal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
      const glm::dvec3 u = glm::normalize(glm::cross(helper, normal));
      const glm::dvec3 v = glm::cross(normal, u);
      p.set("uGroundPoint", glm::vec3(g.point));
      p.set("uGroundNormal", glm::vec3(normal));
      p.set("uGroundAxisU", glm::vec3(u));
      p.set("uGroundAxisV", glm::vec3(v));
      p.set("uGroundHalfExtent", static_cast<float>(g.half_extent));
      p.set("uGroundAlbedo", glm::vec3(g.albedo));
      p.set("uGroundAmbient", glm::vec3(g.albedo) * environment.diffuseRadiance(normal, light_direction));
    }
    p.set("uEnvLodBias", static_cast<float>(settings.environment_lod_bias));
    p.set("uReflectionLod", static_cast<float>(std::max(0.0, settings.environment_lod_bias)));
    environment.bind(p, unit, glm::vec3(light_direction), sun_irradiance);
  }
};

SceneRenderer::SceneRenderer(const gl::ShaderLibrary& shaders, const LoadedScene& scene, const RenderSettings& settings)
    : impl_(std::make_unique<Impl>(shaders, scene)) {
  Impl& s = *impl_;
  s.settings = settings;
  if (scene.objects.empty()) throw InputError(scene.source, "objects", "the scene has no object");
  GLint max_units = 0;
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &max_units);
  int units = s.environment.kind() == EnvironmentKind::Map ? 1 : 0;
  for (const LoadedObject& loaded : scene.objects) {
    loaded.volume.require("ior", 1, loaded.source);
    loaded.volume.require("ior_grad", 3, loaded.source);
    Impl::Object o;
    o.source = loaded.source;
    o.grid = loaded.volume.grid;
    o.to_world = loaded.object_to_world;
    o.to_volume = glm::inverse(loaded.object_to_world);
    o.has_dispersion = loaded.volume.has("dispersion");
    o.has_region = activeRegion(loaded.volume, o.region_min, o.region_max);
    absorbingRegion(loaded.volume, o.absorbing_min, o.absorbing_max);
    o.sharp_faces = materialTouchesBox(loaded.volume);
    gl::VolumeTextureOptions options;
    options.source = loaded.source;
    options.padToRGBA = true;  // llvmpipe samples RGBA32F faster than RGB32F (σa: about 10 % a frame)
    o.textures = gl::VolumeTextures(loaded.volume, options);
    const gl::VolumeFieldSlot* ior = o.textures.layout().find("ior");
    const gl::VolumeFieldSlot* grad = o.textures.layout().find("ior_grad");
    if (!ior || !grad || ior->texture != grad->texture || ior->channel != 0 || grad->channel != 1)
      throw RuntimeError("viewer: expected ior and ior_grad together in one RGBA texture");
    units += o.textures.layout().textureCount() + 1;
    {
      const std::vector<float> bricks = homogeneousBricks(loaded.volume, o.brick_dims);
      o.bricks = gl::Texture3D(o.brick_dims, gl::TextureFormat::R32F, bricks, 1, gl::Sampling{gl::Filter::Nearest});
    }
    s.objects.push_back(std::move(o));
  }
  if (units > max_units)
    throw InputError(scene.source, "objects",
                     "the objects' volumes need " + std::to_string(units) + " textures, more than the " +
                         std::to_string(max_units) + " the GL gives one shader: use fewer objects or fields");
  for (const SceneLightSpec& light : s.scene.lights) {
    if (light.type != SceneLightSpec::Type::Directional) continue;
    if (glm::length(light.direction) > 0) s.light_direction = glm::normalize(light.direction);
    s.sun_irradiance = glm::vec3(light.irradiance);
    break;
  }
  s.buildProgram();
}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::setSettings(const RenderSettings& settings) {
  impl_->settings = settings;
  impl_->buildProgram();
}

const RenderSettings& SceneRenderer::settings() const { return impl_->settings; }

void SceneRenderer::setLightDirection(glm::dvec3 world_dir) {
  if (glm::length(world_dir) > 0 && std::isfinite(glm::length(world_dir))) impl_->light_direction = glm::normalize(world_dir);
}

glm::dvec3 SceneRenderer::lightDirection() const { return impl_->light_direction; }

int SceneRenderer::objectCount() const { return static_cast<int>(impl_->objects.size()); }

void SceneRenderer::draw(const Camera& camera, glm::ivec2 size) {
  impl_->setUniforms(camera, size);
  impl_->program.use();
  glViewport(0, 0, size.x, size.y);
  impl_->triangle.draw();
}

Image SceneRenderer::render(const Camera& camera, glm::ivec2 size) {
  gl::Framebuffer target(size, {gl::TextureFormat::RGBA32F});
  target.bind();
  draw(camera, size);
  return readLinearImage(target);
}

Image readLinearImage(const gl::Framebuffer& target) {
  Image image;
  image.width = target.size().x;
  image.height = target.size().y;
  image.channels = 4;
  image.pixels = target.readRGBA(0);
  gl::flipRows(image.pixels, image.width, 4);
  return image;
}

}  // namespace eik
