// The viewer's image formation against analytic answers (thesis §5, docs/testing.md): Beer–Lambert with
// Fresnel at normal incidence, Fresnel reflectance at several angles, total internal reflection,
// Snell's lateral shift through a tilted slab, a ball lens inverting the environment, and a baked
// sphere's caustic and shadow on the ground. Volumes are built in memory with analytically smoothed
// boundaries: n = 1 + (n₁ − 1)·s, s = ½ erfc(dist / (σ√2)) of a signed distance, ∇n exact.
#include <gtest/gtest.h>

#include "gl/framebuffer.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "core/image_io.h"
#include "core/testing.h"
#include "core/volume.h"
#include "lightsim/bake.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/test_scenes.h"
#include "tests/reference/exact_optics.h"
#include "viewer/environment.h"
#include "viewer/loaded_scene.h"
#include "viewer/gl_test_fixture.h"
#include "viewer/scene_renderer.h"

namespace eik {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSmoothVoxels = 0.75;  // σ of the boundary smoothing these tests assume

// Signed distance to a region (negative inside) and its gradient.
using SignedDistance = std::function<double(const glm::dvec3&, glm::dvec3&)>;

SignedDistance halfSpaceBelow(glm::dvec3 normal, double offset) {  // {x : x·N < offset}
  normal = glm::normalize(normal);
  return [normal, offset](const glm::dvec3& p, glm::dvec3& grad) {
    grad = normal;
    return glm::dot(p, normal) - offset;
  };
}

SignedDistance slab(double half_thickness) {  // |z| < half_thickness
  return [half_thickness](const glm::dvec3& p, glm::dvec3& grad) {
    grad = glm::dvec3(0, 0, p.z >= 0 ? 1.0 : -1.0);
    return std::abs(p.z) - half_thickness;
  };
}

SignedDistance ball(glm::dvec3 centre, double radius) {
  return [centre, radius](const glm::dvec3& p, glm::dvec3& grad) {
    const glm::dvec3 q = p - centre;
    const double r = glm::length(q);
    grad = r > 1e-12 ? q / r : glm::dvec3(0.0);
    return r - radius;
  };
}

// A material of index n1 and absorption sigma_a in `region`, air elsewhere, on the box `lo`–`hi`
// with res voxels along x (cubic voxels).
Volume smoothedVolume(const SignedDistance& region, double n1, glm::dvec3 sigma_a, int res,
                      glm::dvec3 lo = glm::dvec3(-1.0), glm::dvec3 hi = glm::dvec3(1.0),
                      double smooth_voxels = kSmoothVoxels) {
  Volume v;
  const double h = (hi.x - lo.x) / res;
  v.grid.dims = glm::ivec3(glm::round((hi - lo) / h));
  v.grid.bounds_min = lo;
  v.grid.bounds_max = lo + glm::dvec3(v.grid.dims) * h;
  Field& ior = v.addField("ior", 1);
  Field& grad = v.addField("ior_grad", 3);
  Field* absorption = sigma_a != glm::dvec3(0.0) ? &v.addField("sigma_a", 3) : nullptr;
  const double sigma = smooth_voxels * h;
  for (int k = 0; k < v.grid.dims.z; ++k)
    for (int j = 0; j < v.grid.dims.y; ++j)
      for (int i = 0; i < v.grid.dims.x; ++i) {
        const std::size_t index = v.grid.index(i, j, k);
        glm::dvec3 g;
        const double dist = region(v.grid.center(i, j, k), g);
        const double s = 0.5 * std::erfc(dist / (sigma * std::sqrt(2.0)));
        const double ds = -std::exp(-dist * dist / (2 * sigma * sigma)) / (sigma * std::sqrt(2 * kPi));
        ior.data[index] = static_cast<float>(1.0 + (n1 - 1.0) * s);
        for (int c = 0; c < 3; ++c) grad.voxel(index)[c] = static_cast<float>((n1 - 1.0) * ds * g[c]);
        if (absorption)
          for (int c = 0; c < 3; ++c) absorption->voxel(index)[c] = static_cast<float>(sigma_a[c] * s);
      }
  return v;
}

class SceneRendererTest : public GlSuiteTest {
 protected:

  static LoadedScene oneObject(Volume volume, const std::string& env, const SceneObjectSpec& placement = {}) {
    Scene scene;
    scene.objects.push_back(placement);
    LoadedScene loaded = sceneFromVolumes(scene, {std::move(volume)});
    loaded.scene.lights.clear();
    applyEnvironmentFlag(env, loaded.scene.environment);
    return loaded;
  }

  static Image render(const LoadedScene& scene, const Camera& camera, glm::ivec2 size,
                      const RenderSettings& settings = {}) {
    SceneRenderer renderer(*shaders_, scene, settings);
    return renderer.render(camera, size);
  }

  static void save(const Image& image, const std::string& name) {
    writeImage(std::filesystem::temp_directory_path() / ("eikonal-viewer-" + name + ".png"), image);
  }

};

Camera lookAt(glm::dvec3 eye, glm::dvec3 target, double fov_deg, glm::dvec3 up = {0, 1, 0}) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.up = up;
  c.fov_y_deg = fov_deg;
  return c;
}

TEST_F(SceneRendererTest, BeerLambertThroughASlabAtNormalIncidence) {
  // Slab |z| < 0.5 (d = 1), n = 1.5, σa = (0, 0.5, 1), seen along −z against a white sky: the front
  // reflection R plus what crosses both faces, (1 − R)²·exp(−σa·d), R = ((n − 1)/(n + 1))² = 0.04.
  const glm::dvec3 sigma_a(0.0, 0.5, 1.0);
  LoadedScene scene = oneObject(smoothedVolume(slab(0.5), 1.5, sigma_a, 48), "uniform:1,1,1");
  const Image image = render(scene, lookAt({0, 0, 4}, {0, 0, 0}, 10.0), {33, 33});
  const double R = 0.04;
  const float* centre = image.at(16, 16);
  for (int c = 0; c < 3; ++c) {
    const double expected = R + (1 - R) * (1 - R) * std::exp(-sigma_a[c]);
    EXPECT_NEAR(centre[c], expected, 0.01 * expected) << "channel " << c;
    RecordProperty("channel" + std::to_string(c), std::to_string(centre[c]) + " expected " + std::to_string(expected));
  }
  // Without Fresnel: exp(−σa·d) alone.
  RenderSettings no_fresnel;
  no_fresnel.fresnel = false;
  const Image plain = render(scene, lookAt({0, 0, 4}, {0, 0, 0}, 10.0), {33, 33}, no_fresnel);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(plain.at(16, 16)[c], std::exp(-sigma_a[c]), 0.01 * std::exp(-sigma_a[c]));
}

TEST_F(SceneRendererTest, FresnelReflectanceOfAFlatBoundary) {
  // Black glass (σa = 60) below y = 0: only the reflection of the white sky reaches the eye, R(θ).
  LoadedScene scene = oneObject(smoothedVolume(halfSpaceBelow({0, 1, 0}, 0.0), 1.5, glm::dvec3(60.0), 48),
                                "uniform:1,1,1");
  SceneRenderer renderer(*shaders_, scene, RenderSettings{});
  for (double theta_deg : {0.0, 30.0, 50.0, 70.0, 80.0}) {
    const double theta = theta_deg * kPi / 180;
    const glm::dvec3 eye = 3.0 * glm::dvec3(0, std::cos(theta), std::sin(theta));
    const Image image = renderer.render(lookAt(eye, {0, 0, 0}, 4.0, {0, 0, -1}), {9, 9});
    const double expected = reference::fresnelReflectance(1.0, 1.5, std::cos(theta));
    EXPECT_NEAR(image.at(4, 4)[1], expected, 0.02 * expected) << "at " << theta_deg << "°";
    RecordProperty("R_at_" + std::to_string(static_cast<int>(theta_deg)) + "deg",
                   std::to_string(image.at(4, 4)[1]) + " exact " + std::to_string(expected));
  }
  // A `reflect` field tints the reflection (thesis T7): tint (1, 0.5, 0) at full weight.
  Volume tinted = smoothedVolume(halfSpaceBelow({0, 1, 0}, 0.0), 1.5, glm::dvec3(60.0), 48);
  Field& reflect = tinted.addField("reflect", 4);
  for (std::size_t i = 0; i < tinted.grid.count(); ++i) {
    const float t[4] = {1.0f, 0.5f, 0.0f, 1.0f};
    std::copy(t, t + 4, reflect.voxel(i));
  }
  LoadedScene tinted_scene = oneObject(tinted, "uniform:1,1,1");
  const Image image = render(tinted_scene, lookAt({0, 3, 0}, {0, 0, 0}, 4.0, {0, 0, -1}), {9, 9});
  EXPECT_NEAR(image.at(4, 4)[0], 0.04, 0.02 * 0.04);
  EXPECT_NEAR(image.at(4, 4)[1], 0.02, 0.02 * 0.02);
  EXPECT_LT(image.at(4, 4)[2], 1e-4);
}

SignedDistance block(glm::dvec3 lo, glm::dvec3 hi) {  // the box lo–hi (distance of its nearest face)
  return [lo, hi](const glm::dvec3& p, glm::dvec3& grad) {
    const double faces[6] = {p.x - hi.x, lo.x - p.x, p.y - hi.y, lo.y - p.y, p.z - hi.z, lo.z - p.z};
    const glm::dvec3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    int best = 0;
    for (int i = 1; i < 6; ++i)
      if (faces[i] > faces[best]) best = i;
    grad = normals[best];
    return faces[best];
  };
}

TEST_F(SceneRendererTest, TotalInternalReflectionFromInsideABlock) {
  // The eye inside a glass block (n = 1.5, top face y = 0, air all round) looks up at the top:
  // below the critical angle (41.8°) the ray leaves through it, bent by Snell's law; beyond it the
  // top reflects it totally (and so does the parallel bottom), so it never gets out above y = 0:
  // it leaves through the far side z = 0.8, where |d.y| = 1.5·cos θ by Snell's law there.
  LoadedScene scene = oneObject(smoothedVolume(block({-0.8, -0.8, -0.8}, {0.8, 0.0, 0.8}), 1.5, glm::dvec3(0.0), 48),
                                "uniform:1,1,1");
  RenderSettings settings;
  settings.output = RenderOutput::ExitDirection;
  SceneRenderer directions(*shaders_, scene, settings);
  settings.output = RenderOutput::ExitPosition;
  SceneRenderer positions(*shaders_, scene, settings);
  const glm::dvec3 eye(0, -0.3, -0.6);
  for (double theta_deg : {20.0, 35.0, 50.0, 65.0}) {
    const double theta = theta_deg * kPi / 180;
    const glm::dvec3 dir(0, std::cos(theta), std::sin(theta));
    const Camera camera = lookAt(eye, eye + dir, 2.0, {1, 0, 0});
    const Image exit_directions = directions.render(camera, {5, 5});
    const float* exit = exit_directions.at(2, 2);
    const float exit_y = positions.render(camera, {5, 5}).at(2, 2)[1];
    const double sin_t = 1.5 * std::sin(theta);
    if (sin_t < 1) {
      EXPECT_GT(exit_y, 0.0f) << "out through the top at " << theta_deg << "°";
      EXPECT_NEAR(exit[1], std::sqrt(1 - sin_t * sin_t), 0.01) << "refracted at " << theta_deg << "°";
      EXPECT_NEAR(exit[2], sin_t, 0.01) << "refracted at " << theta_deg << "°";
    } else {
      EXPECT_LT(exit_y, -0.05f) << "reflected at " << theta_deg << "°";
      EXPECT_NEAR(std::abs(exit[1]), 1.5 * std::cos(theta), 0.02) << "out through the side at " << theta_deg << "°";
      EXPECT_GT(exit[2], 0.0f);
    }
  }
}

TEST_F(SceneRendererTest, TiltedSlabShiftsTheViewBySnellsLaw) {
  // A slab of thickness t = 0.5 turned by 40° about x, seen along −z: the ray leaves parallel to
  // itself, shifted sideways by t·sin(θ − θt)/cos θt (θt from Snell's law).
  const int res = 48;
  const double h = 2.0 / res;
  SceneObjectSpec placement;
  placement.rotate_deg = glm::dvec3(40.0, 0.0, 0.0);
  LoadedScene scene = oneObject(smoothedVolume(slab(0.25), 1.5, glm::dvec3(0.0), res), "uniform:1,1,1", placement);
  RenderSettings settings;
  const Camera camera = lookAt({0, 0, 5}, {0, 0, 0}, 2.0);
  settings.output = RenderOutput::ExitPosition;
  const Image positions = render(scene, camera, {5, 5}, settings);
  settings.output = RenderOutput::ExitDirection;
  const Image directions = render(scene, camera, {5, 5}, settings);
  const float* p = positions.at(2, 2);
  const float* d = directions.at(2, 2);
  ASSERT_EQ(p[3], 1.0f) << "the ray went through the slab";
  const glm::dvec3 incident = glm::normalize(camera.target - camera.eye);
  const glm::dvec3 exit_dir(d[0], d[1], d[2]);
  EXPECT_GT(glm::dot(exit_dir, incident), 0.99999) << "leaves parallel to itself";
  const glm::dvec3 exit_point(p[0], p[1], p[2]);
  const double shift = glm::length(glm::cross(exit_point - camera.eye, incident));
  const double theta = 40.0 * kPi / 180, theta_t = std::asin(std::sin(theta) / 1.5);
  const double expected = 0.5 * std::sin(theta - theta_t) / std::cos(theta_t);
  EXPECT_NEAR(shift, expected, 0.5 * h);
  // Most of what is left is the smoothing itself (docs/physics.md): the exact shift through the smoothed
  // profile n(z) is ∫ (tan θ₀ − tan θ(z)) dz · cos θ₀ with n(z)·sin θ(z) = sin θ₀. The renderer
  // matches it within a tenth of a voxel.
  const double sigma = kSmoothVoxels * h, dz = 1e-5;
  double smoothed = 0;
  for (double z = -0.6; z < 0.6; z += dz) {
    const double n = 1.0 + 0.5 * 0.5 * std::erfc((std::abs(z) - 0.25) / (sigma * std::sqrt(2.0)));
    const double s = std::sin(theta) / n;
    smoothed += (std::tan(theta) - s / std::sqrt(1 - s * s)) * dz;
  }
  smoothed *= std::cos(theta);
  EXPECT_NEAR(shift, smoothed, 0.1 * h);
  RecordProperty("shift", std::to_string(shift) + " snell " + std::to_string(expected) + " smoothed " +
                              std::to_string(smoothed) + " voxel " + std::to_string(h));
}

TEST_F(SceneRendererTest, BallLensShowsTheEnvironmentInverted) {
  // A glass ball (r = 0.5, n = 1.5) seen from 4 away: the eye lies beyond its focal length
  // (f = nR/(2(n − 1)) = 0.75), so rays through its upper half leave heading down, and the
  // environment seen through it is upside down (and left-right reversed).
  LoadedScene scene = oneObject(smoothedVolume(ball({0, 0, 0}, 0.5), 1.5, glm::dvec3(0.0), 48), "checker:1,1,1");
  const Camera camera = lookAt({0, 0, 4}, {0, 0, 0}, 20.0);
  const glm::ivec2 size(64, 64);
  save(render(scene, camera, size), "ball-lens");
  RenderSettings settings;
  settings.output = RenderOutput::ExitDirection;
  const Image exits = render(scene, camera, size, settings);
  // The ball spans ±0.5/(4·tan 10°) of the half image: about 22 pixels of radius.
  int checked = 0;
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) {
      const double px = x + 0.5 - size.x / 2.0, py = size.y / 2.0 - (y + 0.5);  // up is +py
      const double r = std::hypot(px, py);
      if (r < 3 || r > 12) continue;  // the paraxial part, away from the axis
      const float* e = exits.at(x, y);
      ASSERT_EQ(e[3], 1.0f);
      if (std::abs(py) > 2) {
        EXPECT_LT(e[1] * py, 0.0) << "pixel " << x << "," << y;
      }
      if (std::abs(px) > 2) {
        EXPECT_LT(e[0] * px, 0.0) << "pixel " << x << "," << y;
      }
      ++checked;
    }
  EXPECT_GT(checked, 300);
  // Outside the ball the ray goes straight on (it may cross the air of the ball's box).
  const float* corner = exits.at(2, 2);
  const glm::dvec3 corner_dir(corner[0], corner[1], corner[2]);
  EXPECT_GT(corner_dir.y, 0.0);
  EXPECT_LT(corner_dir.x, 0.0);
  EXPECT_GT(glm::dot(corner_dir, glm::normalize(glm::dvec3(-0.65, 0.65, -4.0))), 0.999);
}

// A spot light (glTF KHR_lights_punctual's cone: full intensity within 20° of its axis, none beyond
// 30°) 2 above the ground, pointing down, seen from straight above: the ground's radiance is
// ρ/π·I·a(θ)·cos θ/d² at every pixel, a = ((cos θ − cos 30°)/(cos 20° − cos 30°))² clamped to
// [0, 1] (core/scene.h spotAttenuation), and nothing beyond the cone (a black environment).
TEST_F(SceneRendererTest, ASpotLightsConeOnTheGround) {
  const double ground_y = -0.4, height = 2.0, intensity = 3.0;
  Scene scene;
  SceneObjectSpec far_away{"ball"};
  far_away.translate = {50.0, 0.0, 0.0};  // an object the scene needs, out of the picture
  scene.objects.push_back(far_away);
  SceneLightSpec spot;
  spot.type = SceneLightSpec::Type::Spot;
  spot.position = {0.0, ground_y + height, 0.0};
  spot.direction = {0.0, -1.0, 0.0};
  spot.intensity = glm::dvec3(intensity);
  spot.inner_cone_deg = 20.0;
  spot.outer_cone_deg = 30.0;
  scene.lights.push_back(spot);
  SceneGroundSpec ground;
  ground.point = {0.0, ground_y, 0.0};
  ground.albedo = glm::dvec3(1.0);
  ground.half_extent = 10.0;
  scene.ground = ground;
  LoadedScene loaded = sceneFromVolumes(scene, {smoothedVolume(ball({0.0, 0.0, 0.0}, 0.3), 1.5, glm::dvec3(0.0), 16)});
  applyEnvironmentFlag("uniform:0,0,0", loaded.scene.environment);
  // 65 pixels over 3 units: pixel (32 + k, 32) sees the ground at x = ±3k/65.
  const int pixels = 65;
  const double view = 3.0, distance = 20.0;
  const double fov = 2 * std::atan(view / 2 / distance) * 180 / kPi;
  const Image image = render(loaded, lookAt({0, ground_y + distance, 0}, {0, ground_y, 0}, fov, {0, 0, -1}),
                             {pixels, pixels});
  save(image, "spot-from-above");
  const double cos_inner = std::cos(20.0 * kPi / 180.0), cos_outer = std::cos(30.0 * kPi / 180.0);
  int in_falloff = 0, dark = 0;
  for (int k = 0; k <= pixels / 2; ++k) {
    const double r = k * view / pixels, d = std::hypot(r, height), cos_theta = height / d;
    const double t = std::clamp((cos_theta - cos_outer) / (cos_inner - cos_outer), 0.0, 1.0);
    const double want = intensity * t * t * cos_theta / (d * d) / kPi;
    const double got = image.at(pixels / 2 + k, pixels / 2)[1];
    // 1 %: float arithmetic in the shader and the pixel's ray hitting the ground within 10⁻⁴ of
    // x = 3k/65; past the edge nothing (the black environment's ambient is 0).
    if (want > 0.0) EXPECT_NEAR(got, want, 0.01 * want + 1e-6) << "r = " << r;
    else EXPECT_LT(got, 1e-6) << "r = " << r;
    in_falloff += t > 0.0 && t < 1.0;
    dark += want == 0.0;
  }
  EXPECT_GT(in_falloff, 5);
  EXPECT_GT(dark, 5);
}

TEST_F(SceneRendererTest, BakedSphereCastsItsCausticAndShadowOnTheGround) {
  // A glass ball (r = 0.4, n = 1.5) centred 0.55 above the ground, under a vertical directional
  // light of irradiance 1, baked with lightsim's CPU simulator at 40³. Seen from straight above with
  // refraction off (so the ball does not hide the floor): the caustic's peak lies under the centre
  // and the shadow's edge (half the unoccluded irradiance) at the ball's radius, within 1.5 voxels.
  const double radius = 0.4;
  const glm::dvec3 centre(0.0, 0.15, 0.0);
  const double ground_y = -0.4;
  const int res = 40;
  const double h = 2.0 / res;
  // σ = 0.5 voxel here: grazing rays are bent and reflected away within about 2σ outside the
  // ball, so the shadow's edge lies near R + 2σ (1 voxel); with the usual 0.75 it is 1.7 voxels out.
  Volume volume = smoothedVolume(ball(centre, radius), 1.5, glm::dvec3(0.0), res, glm::dvec3(-1.0), glm::dvec3(1.0), 0.5);
  LightSpec light;
  light.direction = glm::dvec3(0, -1, 0);
  light.power = glm::dvec3(1.0);
  {
    CpuSimulator simulator(volume);
    SimulationOptions options;
    applyBake(volume, simulator.run(light, options), light);
  }
  Scene scene;
  scene.objects.push_back(SceneObjectSpec{"ball"});
  scene.lights.push_back(SceneLightSpec{SceneLightSpec::Type::Directional, light.direction, light.power});
  SceneGroundSpec ground;
  ground.point = glm::dvec3(0, ground_y, 0);
  ground.albedo = glm::dvec3(1.0);
  ground.half_extent = 3.0;
  scene.ground = ground;
  LoadedScene loaded = sceneFromVolumes(scene, {volume});
  applyEnvironmentFlag("uniform:0,0,0", loaded.scene.environment);

  // Straight down at the ground: 96 pixels over 3 units (the box is 2 wide).
  const int pixels = 96;
  const double view = 3.0, distance = 20.0;
  const double fov = 2 * std::atan(view / 2 / distance) * 180 / kPi;
  const Camera camera = lookAt({0, ground_y + distance, 0}, {0, ground_y, 0}, fov, {0, 0, -1});
  save(render(loaded, lookAt({0, 2.2, 3.2}, {0, -0.1, 0}, 40.0), {128, 128}), "caustic-scene");
  RenderSettings settings;
  settings.refraction = false;
  settings.fresnel = false;
  const Image image = render(loaded, camera, {pixels, pixels}, settings);
  save(image, "caustic-from-above");
  const double unlit = 1.0 / kPi;  // ρE/π with E = 1
  auto value = [&](int x, int y) { return image.at(x, y)[1]; };
  // The peak.
  int peak_x = 0, peak_y = 0;
  for (int y = 0; y < pixels; ++y)
    for (int x = 0; x < pixels; ++x)
      if (value(x, y) > value(peak_x, peak_y)) peak_x = x, peak_y = y;
  const double metres_per_pixel = view / pixels;
  const double peak_offset = std::hypot(peak_x + 0.5 - pixels / 2.0, peak_y + 0.5 - pixels / 2.0) * metres_per_pixel;
  EXPECT_LT(peak_offset, h) << "peak at pixel " << peak_x << "," << peak_y;
  RecordProperty("caustic_peak_offset", std::to_string(peak_offset));
  RecordProperty("caustic_peak_over_unlit", std::to_string(value(peak_x, peak_y) / unlit));
  EXPECT_GT(value(peak_x, peak_y), 5 * unlit) << "a caustic concentrates the light";
  // The shadow's edge along the four half-axes: outermost radius where the floor is below half lit.
  for (int axis = 0; axis < 4; ++axis) {
    double edge = 0;
    for (int step = 0; step < pixels / 2; ++step) {
      const int x = pixels / 2 + (axis == 0 ? step : axis == 1 ? -step - 1 : 0);
      const int y = pixels / 2 + (axis == 2 ? step : axis == 3 ? -step - 1 : 0);
      if (axis >= 2 && x != pixels / 2) continue;
      const double r = (step + 0.5) * metres_per_pixel;
      if (value(x, y) < 0.5 * unlit && r < 0.9) edge = r;
    }
    EXPECT_NEAR(edge, radius, 1.5 * h) << "axis " << axis;
    RecordProperty("shadow_edge_axis" + std::to_string(axis), std::to_string(edge));
  }
  // No seam where the floor leaves the baked box (|x| = 1): just inside and just outside agree.
  const int inside = static_cast<int>((pixels / 2.0) + (1.0 - 1.5 * h) / metres_per_pixel);
  const int outside = static_cast<int>((pixels / 2.0) + (1.0 + 1.5 * h) / metres_per_pixel);
  EXPECT_NEAR(value(inside, pixels / 2), unlit, 0.05 * unlit);
  EXPECT_NEAR(value(outside, pixels / 2), unlit, 1e-4);
}

// A slab |z| < 0.5 of air-like n = 1 (no refraction, no Fresnel) with uniform fields, for the
// terms of Eq. 5.10 that have closed forms along a straight ray.
Volume uniformSlab(int res) {
  Volume v = smoothedVolume(slab(0.5), 1.0, glm::dvec3(0.0), res);
  return v;
}

// `value` in the slab (or everywhere with `everywhere`), zero elsewhere.
void fillSlab(Volume& v, const std::string& field, std::vector<float> value, bool everywhere = false) {
  Field& f = v.addField(field, static_cast<int>(value.size()));
  for (int k = 0; k < v.grid.dims.z; ++k)
    for (int j = 0; j < v.grid.dims.y; ++j)
      for (int i = 0; i < v.grid.dims.x; ++i) {
        const bool inside = everywhere || std::abs(v.grid.center(i, j, k).z) < 0.5;
        for (std::size_t c = 0; c < value.size(); ++c)
          f.voxel(v.grid.index(i, j, k))[c] = inside ? value[c] : 0.0f;
      }
}

TEST_F(SceneRendererTest, EmissionIntegratesAlongTheRay) {
  // L_e = (0.3, 0.6, 0.9) per unit length through d = 1, black sky: L = L_e·d (Eq. 5.10).
  Volume v = uniformSlab(32);
  fillSlab(v, "emission", {0.3f, 0.6f, 0.9f});
  LoadedScene scene = oneObject(v, "uniform:0,0,0");
  const Image image = render(scene, lookAt({0, 0, 4}, {0, 0, 0}, 10.0), {9, 9});
  const float expected[3] = {0.3f, 0.6f, 0.9f};
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(image.at(4, 4)[c], expected[c], 0.03f * expected[c]) << c;
  RenderSettings off;
  off.emission = false;
  EXPECT_EQ(render(scene, lookAt({0, 0, 4}, {0, 0, 0}, 10.0), {9, 9}, off).at(4, 4)[1], 0.0f);
}

TEST_F(SceneRendererTest, InScatteringFollowsHenyeyGreenstein) {
  // Baked irradiance E = 2 with light travelling along l, albedo ω̂ = 0.25, g = 0.6, through
  // d = 1: L = ω̂·p(θ)·E·d with p the 3D-normalised HG and cos θ = l·(−view direction).
  Volume v = uniformSlab(32);
  fillSlab(v, "scatter", {0.25f, 0.6f});
  fillSlab(v, "irradiance", {2.0f, 2.0f, 2.0f}, true);  // the light fills the box, as a bake's does
  const glm::dvec3 l = glm::normalize(glm::dvec3(0.0, -0.6, 0.8));  // towards the eye (+z), downwards
  fillSlab(v, "light_dir", {static_cast<float>(l.x), static_cast<float>(l.y), static_cast<float>(l.z)}, true);
  LoadedScene scene = oneObject(v, "uniform:0,0,0");
  const Image image = render(scene, lookAt({0, 0, 4}, {0, 0, 0}, 10.0), {9, 9});
  const double g = 0.6, cos_theta = glm::dot(l, glm::dvec3(0, 0, 1));
  const double phase = (1 - g * g) / (4 * kPi * std::pow(1 + g * g - 2 * g * cos_theta, 1.5));
  const double expected = 0.25 * phase * 2.0 * 1.0;
  EXPECT_NEAR(image.at(4, 4)[0], expected, 0.03 * expected);
  RenderSettings off;
  off.scattering = false;
  EXPECT_EQ(render(scene, lookAt({0, 0, 4}, {0, 0, 0}, 10.0), {9, 9}, off).at(4, 4)[0], 0.0f);
}

TEST_F(SceneRendererTest, OpaqueEmbeddingShowsAlbedoTimesIrradianceOverPi) {
  // An opaque block (albedo 0.5, 0.25, 1) behind half a unit of absorbing glass, baked E = 3:
  // ρE/π attenuated by the glass in front, exp(−σa·0.5).
  Volume v = smoothedVolume(slab(0.5), 1.0, glm::dvec3(0.0), 32);
  Field& opaque = v.addField("opaque", 4);
  Field& irradiance = v.addField("irradiance", 3);
  Field& sigma = v.addField("sigma_a", 3);
  for (int k = 0; k < v.grid.dims.z; ++k)
    for (int j = 0; j < v.grid.dims.y; ++j)
      for (int i = 0; i < v.grid.dims.x; ++i) {
        const std::size_t index = v.grid.index(i, j, k);
        const double z = v.grid.center(i, j, k).z;
        if (z < 0.0) {
          const float a[4] = {0.5f, 0.25f, 1.0f, 1.0f};
          std::copy(a, a + 4, opaque.voxel(index));
        }
        for (int c = 0; c < 3; ++c) irradiance.voxel(index)[c] = 3.0f;
        for (int c = 0; c < 3; ++c) sigma.voxel(index)[c] = 0.4f;
      }
  LoadedScene scene = oneObject(v, "uniform:0,0,0");
  const Image image = render(scene, lookAt({0, 0, 4}, {0, 0, 0}, 10.0), {9, 9});
  // The ray enters the box at z = 1 and stops where the indicator, linearly interpolated, passes
  // ½: at z = 0 (voxel centres ±h/2 around it), after 1 unit of σa = 0.4.
  const float albedo[3] = {0.5f, 0.25f, 1.0f};
  for (int c = 0; c < 3; ++c) {
    const double expected = albedo[c] * 3.0 / kPi * std::exp(-0.4);
    EXPECT_NEAR(image.at(4, 4)[c], expected, 0.03 * expected) << c;
  }
}

// A block of glass filling its whole box (no air margin, as lightsim's uniform test volumes): the
// box's faces are sharp interfaces.
Volume filledBlock(glm::dvec3 half, int res, double n, glm::dvec3 sigma_a) {
  Volume v;
  const double h = 2 * half.x / res;
  v.grid.dims = glm::ivec3(glm::round(2.0 * half / h));
  v.grid.bounds_min = -half;
  v.grid.bounds_max = half;
  Field& ior = v.addField("ior", 1);
  std::fill(ior.data.begin(), ior.data.end(), static_cast<float>(n));
  v.addField("ior_grad", 3);
  Field& sigma = v.addField("sigma_a", 3);
  for (std::size_t i = 0; i < v.grid.count(); ++i)
    for (int c = 0; c < 3; ++c) sigma.voxel(i)[c] = static_cast<float>(sigma_a[c]);
  return v;
}

// A placed object's σa is per world unit (docs/scene-format.md "Placement of an object"): the slab
// above scaled by 2 is 2 thick in the world and lets exp(−2σa) through, as the bake at world scale
// (lightsim/scene_bake.h) assumes; the volume's own unit would let exp(−σa) through.
TEST_F(SceneRendererTest, AScaledObjectAbsorbsOverItsWorldThickness) {
  const glm::dvec3 sigma_a(0.0, 0.5, 1.0);
  SceneObjectSpec twice;
  twice.scale = glm::dvec3(2.0);
  RenderSettings no_fresnel;
  no_fresnel.fresnel = false;
  const Image smoothed = render(oneObject(smoothedVolume(slab(0.5), 1.5, sigma_a, 48), "uniform:1,1,1", twice),
                                lookAt({0, 0, 6}, {0, 0, 0}, 10.0), {33, 33}, no_fresnel);
  // The sharp block takes the homogeneous bricks' long steps (skipHomogeneousBrick) through its
  // constant σa.
  const Image sharp = render(oneObject(filledBlock({1.0, 1.0, 0.5}, 32, 1.5, sigma_a), "uniform:1,1,1", twice),
                             lookAt({0, 0, 6}, {0, 0, 0}, 10.0), {9, 9}, no_fresnel);
  for (int c = 0; c < 3; ++c) {
    const double expected = std::exp(-2.0 * sigma_a[c]);
    EXPECT_NEAR(smoothed.at(16, 16)[c], expected, 0.01 * expected) << "smoothed slab, channel " << c;
    EXPECT_NEAR(sharp.at(4, 4)[c], expected, 0.01 * expected) << "sharp block, channel " << c;
  }
}

// Scaled differently along its axes (docs/scene-format.md): the object is taken in as its volume at
// world scale along each axis (lightsim/scene_bake.h takeInAxisScale) and everything is per world
// length again. The sharp block 1 × 1 × 0.5 scaled 2 : 1 : 3 lets exp(−1.5σa) through along z and
// exp(−2σa) along x. The smoothed slab |z| < 0.25 scaled 1 : 1 : 2 (1 thick) and turned 40° about
// x shifts the view by the Snell shift of a slab 1 thick, t·sin(θ − θt)/cos θt, within half a
// voxel of its stretched z (what the slab 0.5 thick shifts is 0.13 away).
TEST_F(SceneRendererTest, AnUnevenlyScaledObjectIsItsVolumeStretchedAlongEachAxis) {
  const glm::dvec3 sigma_a(0.0, 0.5, 1.0);
  SceneObjectSpec stretched;
  stretched.scale = glm::dvec3(2.0, 1.0, 3.0);
  RenderSettings no_fresnel;
  no_fresnel.fresnel = false;
  const LoadedScene block = oneObject(filledBlock({0.5, 0.5, 0.25}, 32, 1.5, sigma_a), "uniform:1,1,1", stretched);
  EXPECT_EQ(block.objects[0].object_to_world, glm::dmat4(1.0));  // the scale is in the volume now
  const Image along_z = render(block, lookAt({0, 0, 6}, {0, 0, 0}, 10.0), {9, 9}, no_fresnel);
  const Image along_x = render(block, lookAt({6, 0, 0}, {0, 0, 0}, 10.0), {9, 9}, no_fresnel);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(along_z.at(4, 4)[c], std::exp(-1.5 * sigma_a[c]), 0.01 * std::exp(-1.5 * sigma_a[c])) << c;
    EXPECT_NEAR(along_x.at(4, 4)[c], std::exp(-2.0 * sigma_a[c]), 0.01 * std::exp(-2.0 * sigma_a[c])) << c;
  }

  const int res = 48;
  const double h_z = 2.0 * (2.0 / res);  // the slab's voxels, stretched along z
  SceneObjectSpec placement;
  placement.rotate_deg = glm::dvec3(40.0, 0.0, 0.0);
  placement.scale = glm::dvec3(1.0, 1.0, 2.0);
  const LoadedScene slab_scene =
      oneObject(smoothedVolume(slab(0.25), 1.5, glm::dvec3(0.0), res), "uniform:1,1,1", placement);
  RenderSettings settings;
  const Camera camera = lookAt({0, 0, 5}, {0, 0, 0}, 2.0);
  settings.output = RenderOutput::ExitPosition;
  const Image positions = render(slab_scene, camera, {5, 5}, settings);
  const float* p = positions.at(2, 2);
  ASSERT_EQ(p[3], 1.0f) << "the ray went through the slab";
  const glm::dvec3 incident = glm::normalize(camera.target - camera.eye);
  const double shift = glm::length(glm::cross(glm::dvec3(p[0], p[1], p[2]) - camera.eye, incident));
  const double theta = 40.0 * kPi / 180, theta_t = std::asin(std::sin(theta) / 1.5);
  const double expected = 1.0 * std::sin(theta - theta_t) / std::cos(theta_t);
  EXPECT_NEAR(shift, expected, 0.5 * h_z);
  RecordProperty("shift", std::to_string(shift) + " snell " + std::to_string(expected));

  // ∇n per world length: a graded block n = 1.2 + 0.1·x filling [−1, 1]³, scaled 2 : 1 : 1.5, is
  // n = 1.2 + 0.05·x over 4 × 2 × 3 in the world. A ray along −z through its centre gathers
  // n·t_x = ∫ ∂n/∂x ds = 0.05 · 3 (Eq. 6.1; the ray vector's z part stays, n does not vary along
  // z) and leaves into air with t_x = 0.15 (its tangential part kept at the face z = −1.5). The
  // ray drifts 0.19 in x on the way, so n and the path change by about 1 %: 5 % covers that; with
  // ∇n left unscaled the ray leaves at 0.3, with the scale left out at 0.2.
  Volume grin = test_scenes::linearIorVolume(test_scenes::cubicGrid(24, 1.0), 1.2, 0.1);
  SceneObjectSpec graded;
  graded.scale = glm::dvec3(2.0, 1.0, 1.5);
  settings.output = RenderOutput::ExitDirection;
  const Image exit = render(oneObject(std::move(grin), "uniform:1,1,1", graded), lookAt({0, 0, 6}, {0, 0, 0}, 0.5),
                            {5, 5}, settings);
  EXPECT_NEAR(exit.at(2, 2)[0], 0.15, 0.05 * 0.15);
  RecordProperty("grin_exit_tx", std::to_string(exit.at(2, 2)[0]));
}

TEST_F(SceneRendererTest, MaterialTouchingItsBoxRefractsAtTheFaces) {
  // Beer–Lambert through a filled block of thickness 1 at normal incidence: as with a smoothed slab.
  const glm::dvec3 sigma_a(0.0, 0.5, 1.0);
  LoadedScene scene = oneObject(filledBlock({1.0, 1.0, 0.5}, 32, 1.5, sigma_a), "uniform:1,1,1");
  const Image image = render(scene, lookAt({0, 0, 4}, {0, 0, 0}, 10.0), {9, 9});
  const double R = 0.04;
  for (int c = 0; c < 3; ++c) {
    const double expected = R + (1 - R) * (1 - R) * std::exp(-sigma_a[c]);
    EXPECT_NEAR(image.at(4, 4)[c], expected, 0.01 * expected) << "channel " << c;
  }
  // Tilted by 40°: the exact Snell shift of a sharp slab, t·sin(θ − θt)/cos θt.
  SceneObjectSpec placement;
  placement.rotate_deg = glm::dvec3(40.0, 0.0, 0.0);
  LoadedScene tilted = oneObject(filledBlock({1.0, 1.0, 0.25}, 32, 1.5, glm::dvec3(0.0)), "uniform:1,1,1", placement);
  RenderSettings settings;
  const Camera camera = lookAt({0, 0, 5}, {0, 0, 0}, 2.0);
  settings.output = RenderOutput::ExitPosition;
  const Image positions = render(tilted, camera, {5, 5}, settings);
  settings.output = RenderOutput::ExitDirection;
  const Image directions = render(tilted, camera, {5, 5}, settings);
  const glm::dvec3 incident = glm::normalize(camera.target - camera.eye);
  const float* p = positions.at(2, 2);
  const float* d = directions.at(2, 2);
  EXPECT_GT(glm::dot(glm::dvec3(d[0], d[1], d[2]), incident), 0.99999);
  const double shift = glm::length(glm::cross(glm::dvec3(p[0], p[1], p[2]) - camera.eye, incident));
  const double theta = 40.0 * kPi / 180, theta_t = std::asin(std::sin(theta) / 1.5);
  EXPECT_NEAR(shift, 0.5 * std::sin(theta - theta_t) / std::cos(theta_t), 0.05 * 2.0 / 32);  // 1/20 voxel
  // From inside, beyond the critical angle, the face y = 1 reflects totally (60° from its normal);
  // the ray then leaves through z = 1 at 30°, refracted to sin θt = 1.5·sin 30° = 0.75, downwards.
  LoadedScene block = oneObject(filledBlock({1.0, 1.0, 1.0}, 32, 1.5, glm::dvec3(0.0)), "uniform:1,1,1");
  const glm::dvec3 eye(0, 0.3, -0.8);
  const double steep = 60.0 * kPi / 180;
  const glm::dvec3 dir(0, std::cos(steep), std::sin(steep));
  const Image inside = render(block, lookAt(eye, eye + dir, 2.0, {1, 0, 0}), {5, 5}, settings);
  EXPECT_NEAR(inside.at(2, 2)[1], -0.75, 1e-3);
  EXPECT_NEAR(inside.at(2, 2)[2], std::sqrt(1 - 0.75 * 0.75), 1e-3);
}

TEST_F(SceneRendererTest, OneObjectIsSeenThroughAnother) {
  // Two absorbing slabs one behind the other, listed far one first: the ray leaving the near slab
  // goes on into the far one. Centre pixel: R + T·(R + T) with T = (1 − R)²·exp(−σa) per slab.
  const glm::dvec3 sigma_a(0.0, 0.5, 1.0);
  Scene scene;
  SceneObjectSpec far, near;
  far.translate = glm::dvec3(0, 0, -1.5);
  near.translate = glm::dvec3(0, 0, 1.5);
  scene.objects = {far, near};
  LoadedScene loaded = sceneFromVolumes(scene, {smoothedVolume(slab(0.5), 1.5, sigma_a, 32),
                                                smoothedVolume(slab(0.5), 1.5, sigma_a, 32)});
  applyEnvironmentFlag("uniform:1,1,1", loaded.scene.environment);
  const Image image = render(loaded, lookAt({0, 0, 6}, {0, 0, 0}, 8.0), {17, 17});
  const double R = 0.04;
  for (int c = 0; c < 3; ++c) {
    const double T = (1 - R) * (1 - R) * std::exp(-sigma_a[c]);
    const double expected = R + T * (R + T);
    EXPECT_NEAR(image.at(8, 8)[c], expected, 0.01 * expected) << "channel " << c;
  }
}

TEST_F(SceneRendererTest, DispersionSplitsTheColours) {
  // A ball with a strong Cauchy B in front of a white checkerboard: with dispersion, red and blue
  // follow different rays and cell edges seen through it get coloured fringes; without, R = G = B.
  Volume volume = smoothedVolume(ball({0, 0, 0}, 0.5), 1.5, glm::dvec3(0.0), 40);
  Field& dispersion = volume.addField("dispersion", 1);
  const Field& ior = *volume.find("ior");
  for (std::size_t i = 0; i < volume.grid.count(); ++i) dispersion.data[i] = 0.04f * (ior.data[i] - 1.0f) / 0.5f;
  LoadedScene scene = oneObject(volume, "checker:1,1,1");
  const Camera camera = lookAt({0, 0, 4}, {0, 0, 0}, 20.0);
  const Image split = render(scene, camera, {48, 48});
  RenderSettings settings;
  settings.dispersion = false;
  const Image plain = render(scene, camera, {48, 48}, settings);
  save(split, "dispersion");
  double split_max = 0, plain_max = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      split_max = std::max(split_max, static_cast<double>(std::abs(split.at(x, y)[0] - split.at(x, y)[2])));
      plain_max = std::max(plain_max, static_cast<double>(std::abs(plain.at(x, y)[0] - plain.at(x, y)[2])));
    }
  EXPECT_GT(split_max, 0.3);
  EXPECT_LT(plain_max, 1e-6);
  // Outside the ball the three rays coincide.
  for (int c = 0; c < 3; ++c) EXPECT_EQ(split.at(1, 1)[c], plain.at(1, 1)[c]);
}

// Dispersion in two passes (SceneRenderer::draw into a target with depth, as render() makes it):
// green everywhere, then red and blue only where green went through dispersive glass, confined by
// the depth test. Into a target without depth the three rays are traced in one pass. The two
// agree to the bit but at the rim of the dispersive pixels, where the environment's level of
// detail comes from a red or blue ray's neighbours (in one pass, pixels outside the glass lend
// green's ray to that derivative): at most 4 % of the ball's pixels there, and the colour split
// the same on average.
TEST_F(SceneRendererTest, DispersionInTwoPassesIsTheOnePassImage) {
  Volume volume = smoothedVolume(ball({0, 0, 0}, 0.5), 1.5, glm::dvec3(0.0), 40);
  Field& dispersion = volume.addField("dispersion", 1);
  const Field& ior = *volume.find("ior");
  for (std::size_t i = 0; i < volume.grid.count(); ++i) dispersion.data[i] = 0.04f * (ior.data[i] - 1.0f) / 0.5f;
  const LoadedScene scene = oneObject(volume, "checker:1,1,1");
  const Camera camera = lookAt({0, 0, 4}, {0, 0, 0}, 20.0);
  const glm::ivec2 size{48, 48};
  SceneRenderer renderer(*shaders_, scene, RenderSettings{});
  const Image two = renderer.render(camera, size);
  gl::Framebuffer noDepth(size, {gl::TextureFormat::RGBA32F});
  noDepth.bind();
  renderer.draw(camera, size);
  const Image one = readLinearImage(noDepth);
  int differing = 0, split = 0;
  double splitTwo = 0.0, splitOne = 0.0;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const float* a = two.at(x, y);
      const float* b = one.at(x, y);
      EXPECT_EQ(a[1], b[1]) << x << ", " << y;  // green: the same ray in both
      if (a[0] != b[0] || a[2] != b[2]) ++differing;
      if (std::abs(b[0] - b[2]) > 1e-6f) ++split;
      splitTwo += std::abs(a[0] - a[2]);
      splitOne += std::abs(b[0] - b[2]);
    }
  }
  std::printf("two passes against one: %d of %d split pixels differ; mean |R − B| %.4f against %.4f\n", differing,
              split, splitTwo / (size.x * size.y), splitOne / (size.x * size.y));
  ASSERT_GT(split, 200);  // the ball splits the colours
  EXPECT_LE(differing, split / 25);
  EXPECT_NEAR(splitTwo, splitOne, 0.05 * splitOne);
}

// The dispersion in N spectral bands (RenderSettings::bands, as lightsim --bands): each band
// traced at its n(λ_b) and weighted by its share of R, G and B, in every channel of the second
// pass. One band (λ_d, carrying everything) is the image without dispersion; sixteen bands of a
// glass whose Cauchy B is 0 (the field there, so that every band is traced) are that image too,
// the shares summing to 1 per channel; with B ≠ 0 the sixteen split the colours as the three do.
// Exact but for float rounding of the sixteen-term sum: 10⁻⁵.
TEST_F(SceneRendererTest, DispersionInSpectralBands) {
  Volume volume = smoothedVolume(ball({0, 0, 0}, 0.5), 1.5, glm::dvec3(0.0), 40);
  Volume flat = volume;
  flat.addField("dispersion", 1);  // B = 0: every band bends alike
  Field& dispersion = volume.addField("dispersion", 1);
  const Field& ior = *volume.find("ior");
  for (std::size_t i = 0; i < volume.grid.count(); ++i) dispersion.data[i] = 0.04f * (ior.data[i] - 1.0f) / 0.5f;
  const Camera camera = lookAt({0, 0, 4}, {0, 0, 0}, 20.0);
  const glm::ivec2 size{32, 32};
  RenderSettings plain_settings, one, sixteen;
  plain_settings.dispersion = false;
  one.bands = 1;
  sixteen.bands = 16;
  const Image plain = render(oneObject(volume, "checker:1,1,1"), camera, size, plain_settings);
  const Image single = render(oneObject(volume, "checker:1,1,1"), camera, size, one);
  const Image alike = render(oneObject(flat, "checker:1,1,1"), camera, size, sixteen);
  const Image spectral = render(oneObject(volume, "checker:1,1,1"), camera, size, sixteen);
  double one_worst = 0.0, alike_worst = 0.0, split = 0.0;
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) {
      for (int c = 0; c < 3; ++c) {
        one_worst = std::max(one_worst, static_cast<double>(std::abs(single.at(x, y)[c] - plain.at(x, y)[c])));
        alike_worst = std::max(alike_worst, static_cast<double>(std::abs(alike.at(x, y)[c] - plain.at(x, y)[c])));
      }
      split = std::max(split, static_cast<double>(std::abs(spectral.at(x, y)[0] - spectral.at(x, y)[2])));
    }
  save(spectral, "dispersion-16-bands");
  EXPECT_LT(one_worst, 1e-5);
  EXPECT_LT(alike_worst, 1e-5);
  EXPECT_GT(split, 0.3);
  RecordProperty("worst", std::to_string(one_worst) + " " + std::to_string(alike_worst) + " split " + std::to_string(split));
}

TEST_F(SceneRendererTest, EnvironmentMapIsSeenInvertedThroughABallLens) {
  // An equirectangular map, red above the horizon and blue below: around the ball the sky is red
  // above the centre, through the ball (which inverts) blue.
  test_support::TempDir dir;
  Image map;
  map.width = 64;
  map.height = 32;
  map.channels = 3;
  map.pixels.resize(64 * 32 * 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      float* p = map.at(x, y);
      p[0] = y < 16 ? 1.0f : 0.0f;
      p[1] = 0.0f;
      p[2] = y < 16 ? 0.0f : 1.0f;
    }
  writeImage(dir.path() / "sky.exr", map);
  LoadedScene scene = oneObject(smoothedVolume(ball({0, 0, 0}, 0.5), 1.5, glm::dvec3(0.0), 40), "uniform:0,0,0");
  scene.scene.environment = SceneEnvironmentSpec{};
  scene.scene.environment.uniform.reset();
  scene.scene.environment.file = (dir.path() / "sky.exr").string();
  const Image image = render(scene, lookAt({0, 0, 4}, {0, 0, 0}, 20.0), {48, 48});
  save(image, "envmap-lens");
  const float* above_ball = image.at(24, 2);     // outside the ball, above the centre
  const float* through_ball = image.at(24, 16);  // inside the ball's upper half
  EXPECT_GT(above_ball[0], 0.9f);
  EXPECT_LT(above_ball[2], 0.1f);
  EXPECT_GT(through_ball[2], 0.5f);
  EXPECT_LT(through_ball[0], 0.1f);
  // An unreadable map is an InputError naming the field.
  scene.scene.environment.file = (dir.path() / "missing.exr").string();
  try {
    SceneRenderer renderer(*shaders_, scene, RenderSettings{});
    ADD_FAILURE() << "no error for a missing map";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("environment.file"), std::string::npos) << e.what();
  }
}

TEST_F(SceneRendererTest, SkippingEmptySpaceChangesNothing) {
  // The march restricted to the box of the non-trivial region gives the same picture as the march
  // through the whole box: the same radiance (uniform sky: absorption and Fresnel) and the same exit
  // directions. Only the phase of the steps differs: rays through the outer rim of this small ball
  // (7 voxels of radius, 0.75 voxel of smoothing) are under-resolved at 0.5-voxel steps, so a ring of
  // pixels may differ (at 0.1-voxel steps both modes agree there too, and with RK4).
  LoadedScene scene = oneObject(smoothedVolume(ball({0.2, 0, 0}, 0.3), 1.5, glm::dvec3(0.2, 0.4, 0.8), 48),
                                "uniform:1,1,1");
  const Camera camera = lookAt({1, 1, 4}, {0, 0, 0}, 30.0);
  struct Case {
    RenderOutput output;
    bool bricks;  // homogeneous bricks crossed in one step, too
  };
  for (const Case& c : {Case{RenderOutput::Radiance, false}, Case{RenderOutput::ExitDirection, false},
                        Case{RenderOutput::Radiance, true}}) {
    const RenderOutput output = c.output;
    RenderSettings skip, whole;
    skip.output = whole.output = output;
    whole.skip_empty_space = false;
    skip.homogeneous_bricks = c.bricks;
    const Image skipped = render(scene, camera, {40, 40}, skip);
    const Image full = render(scene, camera, {40, 40}, whole);
    int differ = 0;
    double sum_skipped = 0, sum_full = 0;
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 40; ++x) {
        double diff = 0;
        for (int c = 0; c < 3; ++c) diff = std::max(diff, static_cast<double>(std::abs(skipped.at(x, y)[c] - full.at(x, y)[c])));
        differ += diff > 0.01;
        sum_skipped += skipped.at(x, y)[1];
        sum_full += full.at(x, y)[1];
      }
    const char* what = output == RenderOutput::Radiance ? "radiance" : "exit direction";
    EXPECT_LT(differ, 80) << what << ": pixels that differ by more than 0.01, of 1600 (the ball covers about 90)";
    if (output == RenderOutput::Radiance) {
      EXPECT_NEAR(sum_skipped / sum_full, 1.0, 0.002) << what;
    }
  }
}

TEST_F(SceneRendererTest, Rk4AgreesWithEuler) {
  LoadedScene scene = oneObject(smoothedVolume(ball({0, 0, 0}, 0.5), 1.5, glm::dvec3(0.0), 40), "uniform:1,1,1");
  RenderSettings settings;
  settings.output = RenderOutput::ExitDirection;
  const Camera camera = lookAt({0, 0, 4}, {0, 0, 0}, 20.0);
  const Image euler = render(scene, camera, {32, 32}, settings);
  settings.integrator = RayIntegrator::RK4;
  const Image rk4 = render(scene, camera, {32, 32}, settings);
  // A ray through the ball's upper half, well inside its rim.
  const float* a = euler.at(16, 10);
  const float* b = rk4.at(16, 10);
  EXPECT_LT(a[1], -0.05f) << "the ray is bent down";
  EXPECT_GT(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], 0.9995f);
}

}  // namespace
}  // namespace eik
