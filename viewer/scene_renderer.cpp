// The renderer of viewer/scene_renderer.h: uploads, program variants, uniforms, the draw.
#include "viewer/scene_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/spectrum.h"
#include "core/interfaces.h"
#include "gl/framebuffer.h"
#include "gl/gl.h"
#include "gl/program.h"
#include "gl/vertex_array.h"
#include "gl/volume_textures.h"
#include "viewer/environment.h"
#include "viewer/ground_map.h"
#include "viewer/shadow_edge.h"
#include "viewer/raymarch_shader.h"
#include "viewer/volume_analysis.h"

namespace eik {

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
    std::string defines;   // RaymarchObject::defines: its interfaces, HAS_RECEIVER
    // The receiver map of the scene's ground, when its bake made one (volume space).
    bool has_receiver = false;
    bool receiver_grey = false;  // the texture is RG16F: R = G = B, and the clearance (receiverTexelsHalf)
    ReceiverMap receiver;   // geometry (the data is in receiver_texture)
    gl::Texture2D receiver_texture;
    glm::vec4 receiver_light_pos{0.0f};
    glm::vec3 receiver_light_power{0.0f};
    glm::vec4 receiver_light_spot{0.0f};
    float receiver_light_spot_scale = 0.0f;
    std::vector<ReceiverLayer::Light> receiver_other_lights;  // the map's other lights (ReceiverLayer)
  };

  const gl::ShaderLibrary& shaders;
  Scene scene;
  RenderSettings settings;
  std::vector<Object> objects;
  Environment environment;
  glm::dvec3 light_direction{0.0, -1.0, 0.0};
  glm::vec3 sun_irradiance{0.0f};
  // The ground map (ground_map.h) where two or more objects have a receiver map.
  bool has_ground_map = false;
  GroundMap ground_map;  // geometry (the data is in ground_texture)
  gl::Texture2D ground_texture;
  gl::Program program;
  std::string program_key;  // the defines the program was built with
  // DISPERSION in two passes (draw): `program` traces green and marks in the depth buffer where it
  // met dispersive glass; `red_blue` traces red and blue there only (the depth test keeps the rest
  // from being shaded), or with N spectral bands all of them, the spectrum's ends traced and the
  // bands between interpolated, green's ray having stopped at the glass (raymarch.frag). `single`
  // traces red, green and blue in one pass, for a target without depth (made when first needed).
  bool two_pass = false;
  gl::Program red_blue, single;
  std::vector<RaymarchObject> shapes;  // of the last build, for `single`
  gl::ShaderDefines program_defines;
  gl::FullscreenTriangle triangle;

  Impl(const gl::ShaderLibrary& library, const LoadedScene& loaded)
      : shaders(library), scene(loaded.scene), environment(loaded.scene.environment, loaded.scene.base_dir, loaded.source) {}

  // The object's receiver map of the scene's ground (core/receiver_map.h), if its volume has one in
  // the ground's plane (in the volume's own space), with the light it was baked with.
  struct GroundReceiver {
    const ReceiverMap* map = nullptr;
    glm::vec4 light_pos{0.0f};
    glm::vec3 light_power{0.0f};
    glm::vec4 light_spot{0.0f};  // a spot light's axis and cos θ_outer (ReceiverLayer)
    float light_spot_scale = 0.0f;
    bool light_disc = false;  // a directional light with an angular size: the map's soft shadow as baked
    std::vector<ReceiverLayer::Light> other_lights;  // the other lights summed into the map ("lights")
  };
  static GroundReceiver findGroundReceiver(const LoadedObject& loaded, const SceneGroundSpec& ground) {
    const glm::dmat4 to_volume = glm::inverse(loaded.object_to_world);
    const glm::dvec3 point = glm::dvec3(to_volume * glm::dvec4(ground.point, 1.0));
    const glm::dvec3 normal = glm::normalize(glm::transpose(glm::dmat3(loaded.object_to_world)) * ground.normal);
    for (const ReceiverMap& map : loaded.volume.receivers) {
      const double scale = map.pitch * 4.0;
      if (glm::dot(normal, map.normal) < 0.9999 || std::abs(glm::dot(point - map.point, map.normal)) > scale) continue;
      const nlohmann::json& light = loaded.volume.metadata.value("light", nlohmann::json());
      if (!light.is_object() || !light.contains("type")) continue;
      GroundReceiver found;
      found.map = &map;
      found.light_disc = light.value("angular_diameter_deg", 0.0) > 0.0 && light.value("type", "") == "directional";
      const ReceiverLayer::Light first = bakedLight(loaded, light, "light");
      found.light_pos = glm::vec4(first.pos);
      found.light_power = glm::vec3(first.power);
      found.light_spot = glm::vec4(first.spot);
      found.light_spot_scale = static_cast<float>(first.spot_scale);
      // A scene's lights summed (lightsim SCENE.json): the map holds them all; the first is "light".
      const nlohmann::json& lights = loaded.volume.metadata.value("lights", nlohmann::json());
      if (!lights.is_null()) {
        if (!lights.is_array() || lights.empty() || lights.front() != light)
          throw InputError(loaded.source, "lights", "must be a list of the baked lights beginning with \"light\"");
        for (std::size_t k = 1; k < lights.size(); ++k)
          found.other_lights.push_back(bakedLight(loaded, lights[k], "lights[" + std::to_string(k) + "]"));
      }
      return found;
    }
    return {};
  }

  // A baked light of the manifest (lightsim's LightSpec::toJson), as the ground's shading takes it.
  static ReceiverLayer::Light bakedLight(const LoadedObject& loaded, const nlohmann::json& light, const std::string& key) {
    ReceiverLayer::Light out;
    try {
      auto vec3Of = [&](const char* name) {
        const nlohmann::json& a = light.at(name);
        return glm::dvec3(a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>());
      };
      if (light.at("type") == "directional") {
        out.pos = glm::dvec4(glm::normalize(vec3Of("direction")), 0.0);
        out.power = vec3Of("irradiance");
      } else {
        out.pos = glm::dvec4(vec3Of("position"), 1.0);
        out.power = vec3Of("intensity");
        if (light.at("type") == "spot") {
          const SpotCone cone =
              spotCone(vec3Of("direction"), light.at("inner_cone_deg").get<double>(), light.at("outer_cone_deg").get<double>());
          out.spot = cone.axis_cos_outer;
          out.spot_scale = cone.scale;
        }
      }
    } catch (const nlohmann::json::exception&) {
      throw InputError(loaded.source, key, "the baked light is malformed");
    }
    if (!std::isfinite(glm::dot(out.pos, out.pos)) || !std::isfinite(glm::dot(out.power, out.power)))
      throw InputError(loaded.source, key, "the baked light is malformed");
    return out;
  }

  // The receiver texture's texels: the map with its shadow's edge to the pixel (shadow_edge.h:
  // directional light without an angular size, sharp interfaces; a light's disc makes the edge a
  // penumbra, which the map holds as baked). No GL: SceneRenderer::prepare runs it before a context.
  static std::vector<std::uint16_t> groundTexels(const LoadedObject& loaded, const GroundReceiver& found) {
    const glm::dmat4 to_volume = glm::inverse(loaded.object_to_world);
    ReceiverLayer layer{found.map,
                        to_volume,
                        loaded.object_to_world,
                        glm::dvec4(found.light_pos),
                        glm::dvec3(found.light_power),
                        glm::dvec4(found.light_spot),
                        found.light_spot_scale,
                        nullptr,
                        found.other_lights};
    const std::vector<float> clearance =
        found.light_pos.w == 0.0f && !found.light_disc ? shadowClearance(loaded.volume, *found.map, glm::dvec3(found.light_pos))
                                  : std::vector<float>();
    return receiverTexelsHalf(layer, clearance);
  }

  // `for_ground_map`: keep the map's irradiance, which only a ground map of two or more objects' maps
  // reads (buildGroundMap); a lone object's is uploaded as its texels and not kept twice.
  static void attachReceiver(Object& o, const LoadedObject& loaded, const SceneGroundSpec& ground,
                             const std::vector<std::uint16_t>* prepared, bool for_ground_map) {
    const GroundReceiver found = findGroundReceiver(loaded, ground);
    if (!found.map) return;
    o.receiver_light_pos = found.light_pos;
    o.receiver_light_power = found.light_power;
    o.receiver_light_spot = found.light_spot;
    o.receiver_light_spot_scale = found.light_spot_scale;
    o.receiver_other_lights = found.other_lights;
    // With its irradiance for the ground map only (a lone object's is uploaded as its texels; the
    // copy would be 12 MB of fresh memory at 1024² texels).
    o.receiver = for_ground_map ? *found.map : found.map->geometry();
    // RGBA16F: sampled once a ground hit, half the memory of RGBA32F; RG16F (R = G = B, and A)
    // for a grey map of grey lights (receiverTexelsHalf).
    const std::vector<std::uint16_t> texels = prepared ? std::vector<std::uint16_t>() : groundTexels(loaded, found);
    const std::vector<std::uint16_t>& half = prepared ? *prepared : texels;
    o.receiver_grey = half.size() == 2 * found.map->texelCount();
    o.receiver_texture =
        gl::Texture2D(found.map->texels, o.receiver_grey ? gl::TextureFormat::RG16F : gl::TextureFormat::RGBA16F);
    o.receiver_texture.uploadRaw(half.data(), half.size() * sizeof(std::uint16_t), o.receiver_grey ? GL_RG : GL_RGBA,
                                 GL_HALF_FLOAT);
    o.has_receiver = true;
  }

  // One object's textures, bounds and shader defines, from its volume (the constructor, replaceVolume).
  Object makeObject(const LoadedObject& loaded, const std::vector<std::uint16_t>* prepared_texels = nullptr) const {
    const InterfaceTable table = interfaceTable(loaded.volume, loaded.source);
    refractiveIndex(loaded.volume, table, loaded.source);
    iorGradient(loaded.volume, table, loaded.source);
    Object o;
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
    const SlotMedia media = slotMedia(loaded.volume, table);
    o.defines = interfaceDefines(table) + slotMediumDefines(media);
    // σa one constant in every material: the shader takes it from MEDIUM_SIGMA_A and never samples
    // the field, so it is not uploaded (unless dispersion shares its texture): a texture unit and
    // its memory saved an absorbing object (nine objects in one shader, the thesis' Fig. 7.5a).
    if (loaded.volume.has("sigma_a") && media.sigma_a_constant) {
      o.defines += "#define SIGMA_A_BY_MATERIAL 1\n";
      if (!loaded.volume.has("dispersion")) options.leave_out.push_back("sigma_a");
    }
    // Sharp materials of constant n (CONSTANT_SLOTS): n is the slot's and ∇n = 0 wherever a ray
    // is, so the shader never samples the ior texture and it is not uploaded (at 132³ its RGBA32F
    // texture and the staging copy are 2 × 37 MB that the kernel would zero).
    const bool constant_slots = constantSlots(table);
    if (constant_slots) {
      options.leave_out.push_back("ior");
      options.leave_out.push_back("ior_grad");
    }
    // The used slots' distances alone: one or two (R32F, RG32F; a quarter or half of the RGBA32F
    // texture), or three of a field that holds one per slot (RGB padded to RGBA); the unused slots'
    // one value a constant of the shader.
    const Field* distances = loaded.volume.find("interfaces");
    if (const int used = static_cast<int>(table.slots.size()); distances && (used < 3 || distances->components < 4)) {
      if (const std::optional<float> unused = unusedSlotDistance(*distances, used, table.band)) {
        options.interface_slots = used;
        char value[48];
        std::snprintf(value, sizeof value, "%.9g", static_cast<double>(*unused));
        o.defines += "#define INTERFACES_UNUSED " + std::string(value) + "\n";
      }
    }
    o.textures = gl::VolumeTextures(loaded.volume, options);
    const gl::VolumeFieldSlot* ior = o.textures.layout().find("ior");
    const gl::VolumeFieldSlot* grad = o.textures.layout().find("ior_grad");
    if (!constant_slots && (!ior || !grad || ior->texture != grad->texture || ior->channel != 0 || grad->channel != 1))
      throw RuntimeError("viewer: expected ior and ior_grad together in one RGBA texture");
    if (scene.ground) attachReceiver(o, loaded, *scene.ground, prepared_texels, scene.objects.size() > 1);
    if (o.has_receiver) o.defines += "#define HAS_RECEIVER 1\n";
    if (o.has_receiver && o.receiver_grey) o.defines += "#define RECEIVER_GREY 1\n";
    // The homogeneous bricks only where the march skips them (SKIP_HOMOGENEOUS, `--bricks`): at 132³
    // their analysis reads every voxel's n and σa through 15 MB of fresh arrays. Otherwise one brick
    // that is not homogeneous, which a program built with them later (setSettings) reads as no skip.
    std::vector<float> bricks(1, 0.0f);
    if (settings.homogeneous_bricks)
      bricks = homogeneousBricks(loaded.volume, o.brick_dims);
    else
      o.brick_dims = glm::ivec3(1);
    o.bricks = gl::Texture3D(o.brick_dims, gl::TextureFormat::R32F, bricks, 1, gl::Sampling{gl::Filter::Nearest});
    return o;
  }

  gl::ShaderDefines defines() const {
    RaymarchScene variant;
    variant.objects = objects.size();
    variant.lights = scene.lights.size();
    variant.ground = scene.ground.has_value();
    variant.ground_map = has_ground_map;
    variant.dispersive = std::any_of(objects.begin(), objects.end(), [](const Object& o) { return o.has_dispersion; });
    variant.environment = environment.defines();
    return raymarchDefines(settings, variant);
  }

  // The ground's in-plane axes (raymarch.frag onGround, GROUND_MAP).
  static void groundAxes(const glm::dvec3& normal, glm::dvec3& u, glm::dvec3& v) {
    const glm::dvec3 helper = std::abs(normal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    u = glm::normalize(glm::cross(helper, normal));
    v = glm::cross(normal, u);
  }

  // Two or more receiver maps: their changes summed on one lattice, so the ground is shaded with
  // one lookup (ground_map.h); one map is read directly.
  void buildGroundMap() {
    has_ground_map = false;
    ground_texture = gl::Texture2D();
    if (!scene.ground) return;
    std::vector<ReceiverLayer> layers;
    for (const Object& o : objects)
      if (o.has_receiver) {
        layers.push_back({&o.receiver, o.to_volume, o.to_world, glm::dvec4(o.receiver_light_pos),
                          glm::dvec3(o.receiver_light_power), glm::dvec4(o.receiver_light_spot),
                          o.receiver_light_spot_scale, nullptr, o.receiver_other_lights});
      }
    if (layers.size() < 2) return;
    glm::dvec3 u, v;
    const glm::dvec3 normal = glm::normalize(scene.ground->normal);
    groundAxes(normal, u, v);
    ground_map = combineReceiverMaps(layers, scene.ground->point, u, v);
    ground_texture = gl::Texture2D(ground_map.texels, gl::TextureFormat::RGBA32F, ground_map.rgba, 4);
    ground_map.rgba.clear();
    has_ground_map = true;
  }

  void buildProgram() {
    const gl::ShaderDefines defs = defines();
    std::string key;
    for (const auto& [name, value] : defs) key += name + "=" + value + ";";
    if (program && key == program_key) return;
    shapes.clear();
    for (const Object& o : objects) shapes.push_back({o.textures.layout(), o.sharp_faces, o.defines});
    gl::ShaderSource vertex = shaders.source("common/fullscreen.vert");
    two_pass = std::any_of(defs.begin(), defs.end(), [](const auto& d) { return d.first == "DISPERSION"; });
    program_defines = defs;
    single = gl::Program();
    if (two_pass) {
      gl::ShaderDefines green = defs, rb = defs;
      green.emplace_back("DISPERSION_GREEN_PASS", "1");
      rb.emplace_back("DISPERSION_RED_BLUE_PASS", "1");
      program = gl::Program(vertex, raymarchFragmentSource(shaders, green, shapes));
      red_blue = gl::Program(shaders.source("common/fullscreen.vert"), raymarchFragmentSource(shaders, rb, shapes));
    } else {
      program = gl::Program(vertex, raymarchFragmentSource(shaders, defs, shapes));
      red_blue = gl::Program();
    }
    program_key = key;
  }
  const gl::Program& singlePass() {
    if (!single) single = gl::Program(shaders.source("common/fullscreen.vert"), raymarchFragmentSource(shaders, program_defines, shapes));
    return single;
  }

  void setUniforms(const gl::Program& p, const Camera& camera, glm::ivec2 size) {
    const double aspect = static_cast<double>(size.x) / static_cast<double>(size.y);
    p.set("uInvViewProj", glm::mat4(camera.inverseViewProjection(aspect)));
    p.set("uEye", glm::vec3(camera.eye));
    const float pixel_spread = static_cast<float>(2.0 * std::tan(glm::radians(camera.fov_y_deg) / 2) / size.y);
    p.set("uPixelSpread", pixel_spread);
    if (p.hasUniform("uTraceLegs")) p.set("uTraceLegs", 2);  // REFLECT_OBJECTS
    if (p.hasUniform("uBandCount")) {  // DISPERSION_BANDS
      const std::vector<SpectralBand> bands = spectralBands(settings.bands);
      p.set("uBandCount", static_cast<int>(bands.size()));
      p.set("uInterpolateBands", settings.interpolate_bands ? 1 : 0);
      for (std::size_t b = 0; b < bands.size(); ++b) {
        const std::string index = "[" + std::to_string(b) + "]";
        const double lambda = bands[b].lambda_um;
        p.set("uBandCauchy" + index, static_cast<float>(cauchyTerm(lambda)));
        p.set("uBandRgb" + index, glm::vec3(bands[b].rgb));
      }
    }
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
        p.setSampler(objectTextureSampler(k, t), unit);
        ++unit;
      }
      o.bricks.bind(unit);
      p.setSampler(objectBricksSampler(k), unit);
      ++unit;
      if (o.has_receiver) {
        if (!has_ground_map) {  // else the ground map holds its change (groundRadiance)
          o.receiver_texture.bind(unit);
          p.setSampler(objectReceiverSampler(k), unit);
          ++unit;
        }
        p.set("uObjRecvPoint" + i, glm::vec3(o.receiver.point));
        p.set("uObjRecvU" + i, glm::vec3(o.receiver.u));
        p.set("uObjRecvV" + i, glm::vec3(o.receiver.v));
        p.set("uObjRecvOrigin" + i, glm::vec2(o.receiver.origin));
        p.set("uObjRecvSize" + i, glm::vec2(glm::dvec2(o.receiver.texels) * o.receiver.pitch));
        p.set("uObjRecvLightPos" + i, o.receiver_light_pos);
        p.set("uObjRecvLightPower" + i, o.receiver_light_power);
        p.set("uObjRecvLightSpot" + i, o.receiver_light_spot);
        p.set("uObjRecvLightSpotScale" + i, o.receiver_light_spot_scale);
      }
      p.set("uObjBrickSize" + i, glm::vec3(o.grid.extent() / glm::dvec3(o.grid.dims) * double(kBrickVoxels)));
      // The placement's uniform scale (docs/scene-format.md): a volume unit is this many world units.
      p.set("uObjLengthScale" + i, static_cast<float>(std::cbrt(std::abs(glm::determinant(glm::dmat3(o.to_world))))));
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
      const SpotCone cone = light.type == SceneLightSpec::Type::Spot
                                ? spotCone(light.direction, light.inner_cone_deg, light.outer_cone_deg)
                                : SpotCone{};
      p.set("uLightSpot" + i, glm::vec4(cone.axis_cos_outer));
      p.set("uLightSpotScale" + i, static_cast<float>(cone.scale));
    }

    const glm::vec3 ambient = environment.diffuseRadiance(glm::dvec3(0, 1, 0), light_direction);
    p.set("uAmbientRadiance", ambient);
    if (scene.ground) {
      const SceneGroundSpec& g = *scene.ground;
      const glm::dvec3 normal = glm::normalize(g.normal);
      glm::dvec3 u, v;
      groundAxes(normal, u, v);
      p.set("uGroundPoint", glm::vec3(g.point));
      p.set("uGroundNormal", glm::vec3(normal));
      p.set("uGroundAxisU", glm::vec3(u));
      p.set("uGroundAxisV", glm::vec3(v));
      p.set("uGroundHalfExtent", static_cast<float>(g.half_extent));
      p.set("uGroundAlbedo", glm::vec3(g.albedo));
      p.set("uGroundAmbient", glm::vec3(g.albedo) * environment.diffuseRadiance(normal, light_direction));
      if (has_ground_map) {
        ground_texture.bind(unit);
        p.setSampler("uGroundMap", unit);
        ++unit;
        p.set("uGroundMapOrigin", glm::vec2(ground_map.origin));
        p.set("uGroundMapSize", glm::vec2(ground_map.size()));
      }
    }
    p.set("uEnvLodBias", static_cast<float>(settings.environment_lod_bias));
    p.set("uReflectionLod", static_cast<float>(std::max(0.0, settings.environment_lod_bias)));
    environment.bind(p, unit, glm::vec3(light_direction), sun_irradiance);
  }
};

SceneRenderer::Preparation SceneRenderer::prepare(const LoadedScene& scene) {
  Preparation prepared;
  prepared.ground_texels.resize(scene.objects.size());
  if (!scene.scene.ground) return prepared;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const Impl::GroundReceiver found = Impl::findGroundReceiver(scene.objects[i], *scene.scene.ground);
    if (found.map) prepared.ground_texels[i] = Impl::groundTexels(scene.objects[i], found);
  }
  return prepared;
}

void SceneRenderer::releasePrepared(LoadedScene& scene, const Preparation& prepared) {
  // Only a lone object's map (attachReceiver keeps the maps of a ground map of several).
  if (scene.objects.size() != 1 || !scene.scene.ground || prepared.ground_texels.empty() || !prepared.ground_texels[0]) return;
  LoadedObject& object = scene.objects[0];
  const Impl::GroundReceiver found = Impl::findGroundReceiver(object, *scene.scene.ground);
  for (ReceiverMap& map : object.volume.receivers)
    if (&map == found.map) std::vector<float>().swap(map.irradiance);
}

SceneRenderer::SceneRenderer(const gl::ShaderLibrary& shaders, const LoadedScene& scene, const RenderSettings& settings,
                             const Preparation* prepared)
    : impl_(std::make_unique<Impl>(shaders, scene)) {
  Impl& s = *impl_;
  s.settings = settings;
  if (scene.objects.empty()) throw InputError(scene.source, "objects", "the scene has no object");
  GLint max_units = 0;
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &max_units);
  int units = s.environment.kind() == EnvironmentKind::Map ? 1 : 0;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const std::vector<std::uint16_t>* texels = nullptr;
    if (prepared && i < prepared->ground_texels.size() && prepared->ground_texels[i]) texels = &*prepared->ground_texels[i];
    Impl::Object o = s.makeObject(scene.objects[i], texels);
    units += o.textures.layout().textureCount() + 1;
    s.objects.push_back(std::move(o));
  }
  // Two receiver maps or more are summed into the ground map, one texture, and the shader samples
  // no object's own (groundRadiance): nine baked spheres (the thesis' Fig. 7.5a) fit in 32 units.
  s.buildGroundMap();
  if (s.has_ground_map) ++units;
  else
    for (const Impl::Object& o : s.objects) units += o.has_receiver ? 1 : 0;
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

void SceneRenderer::replaceVolume(int index, const LoadedObject& object) {
  if (index < 0 || index >= objectCount()) throw std::out_of_range("SceneRenderer::replaceVolume: no such object");
  Impl& s = *impl_;
  Impl::Object replacement = s.makeObject(object);
  Impl::Object& old = s.objects[static_cast<std::size_t>(index)];
  const bool same_shader = replacement.defines == old.defines && replacement.sharp_faces == old.sharp_faces &&
                           replacement.textures.layout().glslDefines() == old.textures.layout().glslDefines();
  old = std::move(replacement);
  s.buildGroundMap();  // its receiver map changed with its bake
  if (!same_shader) s.program_key.clear();  // buildProgram compiles anew
  s.buildProgram();
}

int SceneRenderer::objectCount() const { return static_cast<int>(impl_->objects.size()); }

bool SceneRenderer::usesGroundMap() const { return impl_->has_ground_map; }

std::size_t SceneRenderer::volumeTextureBytes() const {
  std::size_t total = 0;
  for (const auto& o : impl_->objects) total += o.textures.bytes();
  return total;
}

namespace {
// Whether the framebuffer bound for drawing has a depth buffer (the default framebuffer: taken as
// not, windows here draw into their own).
bool drawTargetHasDepth() {
  GLint bound = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
  if (bound == 0) return false;
  GLint type = GL_NONE;
  glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, GL_DEPTH_ATTACHMENT,
                                        GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
  return type != GL_NONE;
}
}  // namespace

void SceneRenderer::draw(const Camera& camera, glm::ivec2 size) {
  Impl& s = *impl_;
  glViewport(0, 0, size.x, size.y);
  if (!s.two_pass || !drawTargetHasDepth()) {
    const gl::Program& p = s.two_pass ? s.singlePass() : s.program;
    s.setUniforms(p, camera, size);
    p.use();
    s.triangle.draw();
    return;
  }
  // Green everywhere, its depth 0 where it met dispersive glass and 1 elsewhere; then red and blue,
  // or the N bands, over a triangle at depth ½ that passes (GREATER) only where green wrote 0.
  s.setUniforms(s.program, camera, size);
  s.setUniforms(s.red_blue, camera, size);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_ALWAYS);
  glDepthMask(GL_TRUE);
  s.program.use();
  s.triangle.draw();
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  // Three bands: red and blue here, green's from the first pass; N bands: every channel here (the
  // first pass stopped green's ray where it met dispersive glass).
  glColorMask(GL_TRUE, s.settings.bands == 3 ? GL_FALSE : GL_TRUE, GL_TRUE, GL_FALSE);
  s.red_blue.use();
  s.triangle.draw();
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glDisable(GL_DEPTH_TEST);
}

Image SceneRenderer::render(const Camera& camera, glm::ivec2 size) {
  gl::Framebuffer target(size, {gl::TextureFormat::RGBA32F}, /*depth=*/true);
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
