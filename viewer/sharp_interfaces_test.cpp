// The viewer across sharp interfaces (object.glsl crossInterface) and on a baked receiver map
// (receiverChange), against closed forms: Snell's law through a prism and a sphere, and the
// ground's radiance ρE/π from the map the bake wrote.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <memory>
#include <numbers>

#include "core/image_io.h"
#include "core/spectrum.h"
#include "core/testing.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/bake.h"
#include "lightsim/test_scenes.h"
#include "tests/reference/exact_optics.h"
#include "viewer/loaded_scene.h"
#include "viewer/gl_test_fixture.h"
#include "viewer/scene_renderer.h"
#include "viewer/volume_analysis.h"

namespace eik {
namespace {

using test_scenes::box;
using test_scenes::sharpVolume;

class SharpViewerTest : public GlSuiteTest {
 protected:
  static LoadedScene oneObject(Volume volume) {
    Scene scene;
    scene.objects.push_back({});
    LoadedScene loaded = sceneFromVolumes(scene, {std::move(volume)});
    loaded.scene.lights.clear();
    loaded.scene.environment.uniform = glm::dvec3(1.0);
    return loaded;
  }
  // The volume as one object under a baked light E along l everywhere, black sky.
  static LoadedScene underUniformLight(Volume v, double E, const glm::dvec3& l) {
    Field& irradiance = v.addField("irradiance", 3);
    Field& light_dir = v.addField("light_dir", 3);
    for (std::size_t i = 0; i < v.grid.count(); ++i)
      for (int c = 0; c < 3; ++c) {
        irradiance.voxel(i)[c] = static_cast<float>(E);
        light_dir.voxel(i)[c] = static_cast<float>(l[c]);
      }
    LoadedScene loaded = oneObject(std::move(v));
    loaded.scene.environment.uniform = glm::dvec3(0.0);
    return loaded;
  }
};

Camera lookAlong(const glm::dvec3& eye, const glm::dvec3& dir, double fov_deg, const glm::dvec3& up = {0, 1, 0}) {
  Camera c;
  c.eye = eye;
  c.target = eye + dir;
  c.up = up;
  c.fov_y_deg = fov_deg;
  return c;
}

// The prism of lightsim/exact_optics_test.cpp (n = 1.5, apex 60°, a corner towards −z, the base
// facing +z), seen along the symmetric path: the ray through the centre of the image leaves
// deviated by D = 2·asin(n·sin(A/2)) − A = 37.18°.
TEST_F(SharpViewerTest, APrismDeviatesAViewingRayByTheMinimumDeviation) {
  const double n = 1.5, apex = std::numbers::pi / 3.0;
  const double deviation = 2.0 * std::asin(n * std::sin(apex / 2.0)) - apex;
  const double theta_i = (apex + deviation) / 2.0;
  const double in_angle = std::numbers::pi / 6.0 - theta_i;
  const glm::dvec3 d(std::cos(in_angle), 0.0, std::sin(in_angle));
  LoadedScene scene = oneObject(sharpVolume("procedural:prism,side=0.6,height=1,ior=1.5", 48,
                                            box({-0.5, -0.55, -0.5}, {0.5, 0.55, 0.5})));
  RenderSettings settings;
  settings.output = RenderOutput::ExitDirection;
  SceneRenderer renderer(*shaders_, scene, settings);
  // The centre ray passes through the prism's centre, and so through the middle of both faces
  // (it runs 0.08 from the base inside). A narrow field of 0.2° keeps the centre pixel's ray along d.
  const glm::dvec3 target = glm::dvec3(0.0);
  const Image exits = renderer.render(lookAlong(target - 2.0 * d, d, 0.2, {0, 1, 0}), {5, 5});
  const float* e = exits.at(2, 2);
  ASSERT_EQ(e[3], 1.0f) << "the centre ray did not go through the prism";
  const glm::dvec3 out = glm::normalize(glm::dvec3(e[0], e[1], e[2]));
  const double measured = std::acos(std::min(1.0, glm::dot(out, d)));
  std::printf("viewer prism: deviation %.4f° (minimum deviation %.4f°)\n", glm::degrees(measured),
              glm::degrees(deviation));
  EXPECT_NEAR(glm::degrees(measured), glm::degrees(deviation), 0.1);  // the bound
}

// A glass ball (R = 0.5, n = 1.5) seen by rays at several heights: each leaves in the direction
// exact refraction at the true sphere gives (computed here with the reference tracer's sphere).
TEST_F(SharpViewerTest, RaysThroughABallLeaveAsExactRefractionSays) {
  LoadedScene scene = oneObject(sharpVolume("procedural:sphere,r=0.5,ior=1.5", 64, box({-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6})));
  RenderSettings settings;
  settings.output = RenderOutput::ExitDirection;
  SceneRenderer renderer(*shaders_, scene, settings);
  const reference::Solid ball = reference::Solid::sphere({0, 0, 0}, 0.5, 1.5);
  for (double height : {0.0, 0.1, 0.25, 0.4, 0.47}) {
    const glm::dvec3 eye(height, 0.0, 2.0), dir(0, 0, -1);
    const Image exits = renderer.render(lookAlong(eye, dir, 0.05), {3, 3});
    const float* e = exits.at(1, 1);
    // Exact: into the ball, across, and out (the transmitted path; Fresnel only weighs it).
    reference::Hit hit;
    ASSERT_TRUE(ball.intersect(eye, dir, 1e-9, hit));
    glm::dvec3 p = eye + hit.t * dir;
    glm::dvec3 inside = glm::refract(dir, hit.normal, 1.0 / 1.5);
    ASSERT_TRUE(ball.intersect(p, inside, 1e-9, hit));
    p += hit.t * inside;
    const glm::dvec3 exact = glm::refract(inside, -hit.normal, 1.5);
    const double error = glm::degrees(std::acos(std::min(1.0, glm::dot(glm::normalize(glm::dvec3(e[0], e[1], e[2])), exact))));
    std::printf("viewer ball: height %.2f R·2: exit direction %.3f° off exact refraction\n", height, error);
    // Half a degree: the normal is the voxelised distance's gradient (exact for a sphere to
    // O(h²/R)); at 0.47 the ray meets the surface at 70°, where an error in the normal doubles.
    EXPECT_LT(error, 0.5) << height;
  }
}

// A ball of constant n uploads its slot's distances alone, one float a voxel (R32F): no n or ∇n
// (the shader takes the slot's n, CONSTANT_SLOTS) and not the three unused slots' +band
// (INTERFACES_UNUSED) — from the field of one distance per slot voxelize writes and from the four
// distances and zero ∇n of volumes written before. The picture — radiance and exit directions — is
// the one of the whole RGBA interfaces texture to the bit: the same march, read from less memory.
TEST_F(SharpViewerTest, AVolumeOfConstantNUploadsItsUsedDistancesAlone) {
  const Volume lean = sharpVolume("procedural:sphere,r=0.5,ior=1.5", 48, box({-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}));
  ASSERT_EQ(lean.fields.at("interfaces").components, 1);
  ASSERT_FALSE(lean.has("ior_grad"));
  // The format before: four distances (the unused +band) and a zero ∇n.
  Volume four = lean;
  four.fields.at("interfaces") = fourSlotDistances(lean.fields.at("interfaces"), interfaceTable(lean).band);
  four.addField("ior_grad", 3);
  // That with one unused distance off the format's +band (a hand-made file): the unused slots are
  // no longer one constant, so all four distances are uploaded.
  Volume whole = four;
  Field& d = whole.fields.at("interfaces");
  d.voxel(0)[3] *= 2.0f;  // a corner voxel, far from the ball: the march never reads it
  const std::size_t voxels = lean.grid.count();
  const Camera camera = lookAlong({0.3, 0.4, 2.0}, glm::normalize(glm::dvec3(-0.3, -0.4, -2.0)), 30.0);
  for (RenderOutput output : {RenderOutput::Radiance, RenderOutput::ExitDirection}) {
    RenderSettings settings;
    settings.output = output;
    SceneRenderer whole_renderer(*shaders_, oneObject(whole), settings);
    EXPECT_EQ(whole_renderer.volumeTextureBytes(), voxels * 4 * sizeof(float));
    const Image b = whole_renderer.render(camera, {40, 40});
    const Volume* forms[] = {&lean, &four};
    for (const Volume* v : forms) {
      SceneRenderer renderer(*shaders_, oneObject(*v), settings);
      // Leaving n and ∇n in (or uploading all four distances) fails this.
      EXPECT_EQ(renderer.volumeTextureBytes(), voxels * sizeof(float));
      const Image a = renderer.render(camera, {40, 40});
      ASSERT_EQ(a.pixels.size(), b.pixels.size());
      int differing = 0, lit = 0;
      for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        differing += a.pixels[i] != b.pixels[i] ? 1 : 0;
        lit += a.pixels[i] != 0.0f ? 1 : 0;
      }
      EXPECT_EQ(differing, 0) << "output " << static_cast<int>(output) << (v == &lean ? ", one distance" : ", four");
      EXPECT_GT(lit, 400);  // the ball and the sky are there
    }
  }
}

// A volume of sharp constant-n materials read without its ior field (SceneLoadOptions) gives the
// viewer's analyses n from its interface distances: the n voxelize wrote at every voxel, and so the
// same active region, box faces and homogeneous bricks as the field itself.
TEST(SharpVolumeAnalysis, TakesNFromTheDistancesWhereTheIorFieldIsLeftUnread) {
  // Two spheres of different n well inside the grid; a box of glass that reaches past its faces.
  const Volume inside = sharpVolume(std::vector<std::string>{"procedural:sphere,r=0.3,center=0.1:0:0,ior=1.5",
                                                             "procedural:sphere,r=0.15,center=-0.3:0.1:0,ior=1.3"},
                                    32, test_scenes::cube(0.6));
  const Volume touching = sharpVolume(
      std::vector<std::string>{"procedural:box,size=1.4,ior=1.3", "procedural:sphere,r=0.3,ior=1.7"}, 32,
      test_scenes::cube(0.5));
  for (const Volume* whole : {&inside, &touching}) {
    const InterfaceTable table = interfaceTable(*whole);
    ASSERT_TRUE(constantSlots(table));
    ASSERT_EQ(table.slots.size(), 2u);
    const Field& n = whole->fields.at("ior");
    const Field& d = whole->fields.at("interfaces");
    std::size_t differ = 0, glass = 0;
    for (std::size_t i = 0; i < n.data.size(); ++i) {
      differ += slotIndexAt(table, d.data.data(), d.components, i) != n.data[i] ? 1 : 0;
      glass += n.data[i] != 1.0f ? 1 : 0;
    }
    EXPECT_EQ(differ, 0u);
    EXPECT_GT(glass, 1000u);
    Volume lean = *whole;
    lean.fields.erase("ior");
    lean.unread_fields["ior"] = 1;
    EXPECT_EQ(refractiveIndex(lean, table), nullptr);
    EXPECT_EQ(refractiveIndex(*whole, table), &n);
    glm::dvec3 lo_whole, hi_whole, lo_lean, hi_lean;
    ASSERT_TRUE(activeRegion(*whole, lo_whole, hi_whole));
    ASSERT_TRUE(activeRegion(lean, lo_lean, hi_lean));
    EXPECT_EQ(lo_lean, lo_whole);
    EXPECT_EQ(hi_lean, hi_whole);
    EXPECT_EQ(materialTouchesBox(lean), materialTouchesBox(*whole));
    glm::ivec3 dims_whole, dims_lean;
    const std::vector<float> bricks = homogeneousBricks(*whole, dims_whole);
    EXPECT_EQ(homogeneousBricks(lean, dims_lean), bricks);
    EXPECT_NE(std::count(bricks.begin(), bricks.end(), 1.0f), 0);  // glass and air inside, surfaces between
    EXPECT_NE(std::count(bricks.begin(), bricks.end(), 0.0f), 0);
  }
  glm::dvec3 lo, hi;
  ASSERT_TRUE(activeRegion(inside, lo, hi));
  EXPECT_GT(lo.x, inside.grid.bounds_min.x + 0.1);  // a box within the grid, not the grid
  EXPECT_FALSE(materialTouchesBox(inside));
  EXPECT_TRUE(materialTouchesBox(touching));
}

// A headless render leaves n and ∇n unread in a volume of sharp constant-n materials
// (SceneLoadOptions): the picture is the one of the volume read whole, to the bit (the analyses take
// n from the interface distances); a graded material's n and ∇n are read.
TEST_F(SharpViewerTest, AHeadlessRenderLeavesAConstantNVolumesOpticsUnread) {
  test_support::TempDir dir;
  // With its ∇n (0 throughout), as volumes were written before voxelize left it out.
  Volume ball = sharpVolume("procedural:sphere,r=0.5,ior=1.5", 40, box({-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}));
  ball.addField("ior_grad", 3);
  writeVolume(ball, dir / "ball.vol.json");
  SceneLoadOptions lean_options;
  lean_options.leave_constant_optics_unread = true;
  LoadedScene whole = loadScene(dir / "ball.vol.json"), lean = loadScene(dir / "ball.vol.json", lean_options);
  ASSERT_EQ(lean.objects.size(), 1u);
  EXPECT_FALSE(lean.objects[0].volume.has("ior_grad"));
  EXPECT_TRUE(lean.objects[0].volume.unread_fields.count("ior_grad"));
  EXPECT_FALSE(lean.objects[0].volume.has("ior"));
  EXPECT_TRUE(lean.objects[0].volume.unread_fields.count("ior"));
  EXPECT_TRUE(whole.objects[0].volume.has("ior_grad"));
  EXPECT_TRUE(whole.objects[0].volume.has("ior"));
  const Camera camera = lookAlong({0.3, 0.4, 2.0}, glm::normalize(glm::dvec3(-0.3, -0.4, -2.0)), 30.0);
  for (LoadedScene* s : {&whole, &lean}) {
    s->scene.lights.clear();
    s->scene.environment.uniform = glm::dvec3(1.0);
  }
  RenderSettings settings;
  const Image a = SceneRenderer(*shaders_, whole, settings).render(camera, {40, 40});
  const Image b = SceneRenderer(*shaders_, lean, settings).render(camera, {40, 40});
  EXPECT_EQ(a.pixels, b.pixels);
  // A graded material needs ∇n: read whatever the option.
  Volume graded = sharpVolume("procedural:sphere,r=0.5,ior=1.5", 24, box({-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}));
  nlohmann::json table = graded.metadata.at("interfaces");
  table["slots"][0]["graded"] = true;
  graded.metadata["interfaces"] = table;
  writeVolume(graded, dir / "graded.vol.json");  // without ∇n, which a graded material needs
  EXPECT_CONTAINS(test_support::inputErrorOf([&] { loadScene(dir / "graded.vol.json", lean_options); }), "ior_grad");
  graded.addField("ior_grad", 3);
  writeVolume(graded, dir / "graded.vol.json");
  EXPECT_TRUE(loadScene(dir / "graded.vol.json", lean_options).objects[0].volume.has("ior_grad"));
  EXPECT_TRUE(loadScene(dir / "graded.vol.json", lean_options).objects[0].volume.has("ior"));
  // As voxelize writes it now: no ∇n to leave unread, the same picture.
  writeVolume(sharpVolume("procedural:sphere,r=0.5,ior=1.5", 40, box({-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6})),
              dir / "lean.vol.json");
  LoadedScene now = loadScene(dir / "lean.vol.json", lean_options);
  EXPECT_FALSE(now.objects[0].volume.has("ior_grad") || now.objects[0].volume.unread_fields.count("ior_grad"));
  now.scene.lights.clear();
  now.scene.environment.uniform = glm::dvec3(1.0);
  EXPECT_EQ(SceneRenderer(*shaders_, now, settings).render(camera, {40, 40}).pixels, a.pixels);
}

// Between sharp surfaces of constant n the march steps as far as the distance field allows
// (object.glsl stepLength@, on with empty-space skipping). A rounded cube of three absorbing glasses
// (n 1.45, 1.55, 1.65; refraction, total internal reflection, Fresnel, Beer–Lambert) gives the same
// picture as the march at one voxel a step at most (--no-skip), radiance and exit directions, to
// within what a 10 % shorter step changes by itself: rays that reflect many times in the rounded
// edges take one side or the other of an edge on a hair's difference of their path.
TEST_F(SharpViewerTest, SteppingToTheNextSurfaceChangesNothing) {
  LoadedScene scene = oneObject(sharpVolume("procedural:layered_cube,size=0.8,radius=0.12", 48,
                                            box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5})));
  const Camera camera = lookAlong({1.2, 0.9, 1.6}, glm::normalize(glm::dvec3(-1.2, -0.9, -1.6)), 34.0);
  const glm::ivec2 size(48, 48);
  auto differing = [&](const Image& a, const Image& b) {
    int count = 0;
    for (int y = 0; y < size.y; ++y)
      for (int x = 0; x < size.x; ++x) {
        float diff = 0;
        for (int c = 0; c < 3; ++c) diff = std::max(diff, std::abs(a.at(x, y)[c] - b.at(x, y)[c]));
        count += diff > 0.01f;
      }
    return count;
  };
  auto sumGreen = [&](const Image& a) {
    double sum = 0;
    for (int y = 0; y < size.y; ++y)
      for (int x = 0; x < size.x; ++x) sum += a.at(x, y)[1];
    return sum;
  };
  for (RenderOutput output : {RenderOutput::Radiance, RenderOutput::ExitDirection}) {
    RenderSettings skip, whole;
    skip.output = whole.output = output;
    whole.skip_empty_space = false;
    RenderSettings shorter = whole;
    shorter.step_voxels = 0.45;
    const Image skipped = SceneRenderer(*shaders_, scene, skip).render(camera, size);
    const Image full = SceneRenderer(*shaders_, scene, whole).render(camera, size);
    const Image full_shorter = SceneRenderer(*shaders_, scene, shorter).render(camera, size);
    const int differ = differing(skipped, full), differ_shorter = differing(full_shorter, full);
    const char* what = output == RenderOutput::Radiance ? "radiance" : "exit direction";
    std::printf("viewer skip to surfaces: %s: %d of 2304 pixels differ by more than 0.01 (a 10 %% shorter step: %d)\n",
                what, differ, differ_shorter);
    EXPECT_GT(differ_shorter, 0) << what << ": the comparison must see the rays that reflect in the edges";
    EXPECT_LE(differ, differ_shorter) << what;
    if (output == RenderOutput::Radiance) {
      // The cube's light in all: the same within 0.3 % (what a few differing pixels can move).
      EXPECT_NEAR(sumGreen(skipped) / sumGreen(full), 1.0, 0.003) << what;
    }
  }
}

// A glass sphere over a floor, baked with a receiver map under a light straight down (1 W/m²).
Volume bakedSphereOverAFloor(int res = 32) {
  Volume volume = sharpVolume("procedural:sphere,r=0.3,center=0:0.5:0,ior=1.5", res, box({-0.4, 0.1, -0.4}, {0.4, 0.9, 0.4}));
  CpuSimulator sim(volume);
  LightSpec light;  // straight down, 1 W/m²
  SimulationOptions options;
  options.max_depth = 4;
  ReceiverSpec floor;
  floor.half_extent = 0.6;
  options.receiver = floor;
  const BakeResult bake = sim.run(light, options);
  applyBake(volume, bake, light);
  return volume;
}

// The map's planar irradiance at `point` (its volume space), filtered as the texture is: bilinear
// between texel centres, clamped at the edges. −1 where the map does not reach.
double mapIrradiance(const ReceiverMap& map, const glm::dvec3& point) {
  const glm::dvec2 uv = map.planeCoordinates(point) - map.origin;
  if (uv.x < 0 || uv.y < 0 || uv.x > map.texels.x * map.pitch || uv.y > map.texels.y * map.pitch) return -1.0;
  const glm::dvec2 st = uv / map.pitch - 0.5;
  const int i0 = static_cast<int>(std::floor(st.x)), j0 = static_cast<int>(std::floor(st.y));
  const double fx = st.x - i0, fy = st.y - j0;
  auto texel = [&](int i, int j) {
    i = std::clamp(i, 0, map.texels.x - 1);
    j = std::clamp(j, 0, map.texels.y - 1);
    return static_cast<double>(map.rgb(static_cast<std::size_t>(j) * map.texels.x + i).x);
  };
  return (1 - fx) * (1 - fy) * texel(i0, j0) + fx * (1 - fy) * texel(i0 + 1, j0) + (1 - fx) * fy * texel(i0, j0 + 1) +
         fx * fy * texel(i0 + 1, j0 + 1);
}

// The radiance of the ground at `point` (world, y = 0), seen from the side and low, so that the
// ray meets the ground before any object's box: a camera 0.3 away along a slant, a narrow field.
float groundPixel(SceneRenderer& renderer, const glm::dvec3& point) {
  const glm::dvec3 dir = glm::normalize(glm::dvec3(0.0, -0.05, -1.0));
  return renderer.render(lookAlong(point - 0.3 * dir, dir, 0.05), {3, 3}).at(1, 1)[0];
}

Scene floorScene(int objects) {
  Scene scene;
  SceneGroundSpec ground;
  ground.half_extent = 2.0;
  ground.albedo = glm::dvec3(0.5);
  scene.ground = ground;
  scene.lights.push_back(SceneLightSpec{});  // the light the objects were baked with
  scene.environment.uniform = glm::dvec3(0.0);
  for (int k = 0; k < objects; ++k) scene.objects.push_back({});
  return scene;
}

// The ground of a scene whose object was baked with a receiver map: in the sunlight beside the
// object and in its shadow and caustic alike, a pixel's radiance is ρ/π times the map's planar
// irradiance there (the environment black, so nothing else adds).
TEST_F(SharpViewerTest, TheGroundShowsTheReceiverMap) {
  const Volume volume = bakedSphereOverAFloor();
  const ReceiverMap& map = volume.receivers.at(0);
  LoadedScene loaded = sceneFromVolumes(floorScene(1), {volume});
  SceneRenderer renderer(*shaders_, loaded, RenderSettings{});
  EXPECT_FALSE(renderer.usesGroundMap());  // one map is read directly
  int checked = 0;
  for (const glm::dvec2 probe : {glm::dvec2(0.45, 0.0), glm::dvec2(0.2, 0.15), glm::dvec2(0.05, 0.0),
                                 glm::dvec2(-0.5, -0.5), glm::dvec2(0.0, 0.28)}) {
    const glm::dvec3 point(probe.x, 0.0, probe.y);
    const float pixel = groundPixel(renderer, point);
    const double E = mapIrradiance(map, point);
    const double expected = 0.5 * E / std::numbers::pi;
    std::printf("ground at (%.2f, %.2f): radiance %.5f, ρE/π from the map %.5f (E %.4f)\n", probe.x, probe.y, pixel,
                expected, E);
    // 1 %, the bound (float texture and interpolation agree far better); an absolute
    // floor for the shadow, where E is small.
    EXPECT_NEAR(pixel, expected, 0.01 * expected + 1e-5);
    ++checked;
  }
  EXPECT_EQ(checked, 5);
}

// The shadow's edge where the sun grazes the sphere (viewer/shadow_edge.h), not spread over the
// map's texels: under the light straight down the edge is the circle ρ = R = 0.3. A third of a
// texel of the map (a twelfth of a voxel) outside it the ground is lit, a third of a texel inside
// it dark, on eight azimuths, at 32³ and 48³. The map alone (its bilinear lookup) shows about half
// the light at both points: the edge spread over two texels.
TEST_F(SharpViewerTest, TheShadowsEdgeIsWhereTheSunGrazesTheObject) {
  for (int res : {32, 48}) {
    SCOPED_TRACE(res);
    const Volume volume = bakedSphereOverAFloor(res);
    const ReceiverMap& map = volume.receivers.at(0);
    LoadedScene loaded = sceneFromVolumes(floorScene(1), {volume});
    SceneRenderer renderer(*shaders_, loaded, RenderSettings{});
    const double lit = 0.5 * 1.0 / std::numbers::pi;  // ρE/π in the sun
    double darkest_lit = 1e30, brightest_dark = 0.0, map_lit = 1e30, map_dark = 0.0;
    for (int a = 0; a < 8; ++a) {
      const double phi = (a + 0.3) * std::numbers::pi / 4.0;
      const glm::dvec3 radial(std::cos(phi), 0.0, std::sin(phi));
      const glm::dvec3 outside = (0.3 + map.pitch / 3.0) * radial, inside = (0.3 - map.pitch / 3.0) * radial;
      darkest_lit = std::min(darkest_lit, static_cast<double>(groundPixel(renderer, outside)));
      brightest_dark = std::max(brightest_dark, static_cast<double>(groundPixel(renderer, inside)));
      map_lit = std::min(map_lit, 0.5 * mapIrradiance(map, outside) / std::numbers::pi);
      map_dark = std::max(map_dark, 0.5 * mapIrradiance(map, inside) / std::numbers::pi);
    }
    std::printf("%d³: a third of a texel outside the edge %.4f, inside %.4f (the map alone: %.4f, %.4f) of %.4f "
                "in the sun\n",
                res, darkest_lit, brightest_dark, map_lit, map_dark, lit);
    // Lit: the sun less nothing (the sphere reflects a few % back up; 0.9 leaves room for the
    // light the bake loses where patches tear at the silhouette, a tenth of a texel wide). Dark:
    // the light refracted at grazing incidence, about 4 % of the sun's (exact tracer), and the
    // same loss.
    EXPECT_GT(darkest_lit, 0.9 * lit);
    EXPECT_LT(brightest_dark, 0.15 * lit);
    EXPECT_LT(map_lit, 0.9 * lit);  // what the lookup of the map alone gave: the edge smeared
  }
}

// The ground's texels made before the renderer (SceneRenderer::prepare, as the headless viewer
// makes them while its driver loads) give the renderer it builds without them: the same image to
// the bit, shadow edge and caustic included, for a sphere moved off the origin.
TEST_F(SharpViewerTest, GroundTexelsPreparedBeforehandRenderTheSameImage) {
  const Volume volume = bakedSphereOverAFloor(32);
  Scene scene = floorScene(1);
  scene.objects[0].translate = glm::dvec3(0.13, 0.0, -0.07);
  LoadedScene loaded = sceneFromVolumes(scene, {volume});
  const SceneRenderer::Preparation prepared = SceneRenderer::prepare(loaded);
  ASSERT_EQ(prepared.ground_texels.size(), 1u);
  ASSERT_TRUE(prepared.ground_texels[0].has_value()) << "the baked map lies in the ground's plane";
  // A white light's map is grey: its texels R and A alone (receiverTexelsHalf).
  ASSERT_EQ(volume.receivers.at(0).components, 1);
  EXPECT_EQ(prepared.ground_texels[0]->size(), 2 * volume.receivers.at(0).texelCount());
  const Camera camera{glm::dvec3(0.6, 1.2, 1.6), glm::dvec3(0.1, 0.0, 0.0), glm::dvec3(0, 1, 0), 40.0};
  const Image without = SceneRenderer(*shaders_, loaded, RenderSettings{}).render(camera, {64, 64});
  const Image with = SceneRenderer(*shaders_, loaded, RenderSettings{}, &prepared).render(camera, {64, 64});
  ASSERT_EQ(with.pixels.size(), without.pixels.size());
  EXPECT_EQ(with.pixels, without.pixels);
  // The headless viewer then gives up the lone object's map irradiance (its texels hold it): the
  // renderer built after that renders the same image.
  LoadedScene released = loaded;
  SceneRenderer::releasePrepared(released, prepared);
  EXPECT_TRUE(released.objects[0].volume.receivers.at(0).irradiance.empty());
  const Image after = SceneRenderer(*shaders_, released, RenderSettings{}, &prepared).render(camera, {64, 64});
  EXPECT_EQ(after.pixels, without.pixels);
  // Two objects keep their maps: a ground map of both reads them.
  LoadedScene two = sceneFromVolumes(floorScene(2), {volume, volume});
  const SceneRenderer::Preparation prepared_two = SceneRenderer::prepare(two);
  SceneRenderer::releasePrepared(two, prepared_two);
  for (const LoadedObject& object : two.objects) EXPECT_FALSE(object.volume.receivers.at(0).irradiance.empty());
  // A scene without a ground has nothing to prepare.
  loaded.scene.ground.reset();
  EXPECT_FALSE(SceneRenderer::prepare(loaded).ground_texels.at(0).has_value());
}

// Two such spheres side by side (x = ±0.4, their maps overlapping in |x| < 0.2): the ground is
// shaded from one ground map, and shows at every point the direct light changed by each map that
// reaches it — its irradiance less the 1 W/m² it was baked with — in their overlap, in either
// shadow and caustic, and beyond both maps.
TEST_F(SharpViewerTest, TheGroundSumsWhatEveryReceiverMapChanges) {
  const Volume volume = bakedSphereOverAFloor();
  const ReceiverMap& map = volume.receivers.at(0);
  // Translations by whole texels: the ground map's lattice is then each map's own, and its
  // bilinear filter reproduces each exactly (ground_map.h), so the 1 % bound of one map holds.
  const double shift = std::round(0.4 / map.pitch) * map.pitch;
  Scene scene = floorScene(2);
  scene.objects[0].translate = glm::dvec3(-shift, 0.0, 0.0);
  scene.objects[1].translate = glm::dvec3(shift, 0.0, 0.0);
  LoadedScene loaded = sceneFromVolumes(scene, {volume, volume});
  SceneRenderer renderer(*shaders_, loaded, RenderSettings{});
  ASSERT_TRUE(renderer.usesGroundMap());
  int overlapped = 0;
  for (const glm::dvec2 probe : {glm::dvec2(0.0, 0.0), glm::dvec2(0.12, 0.05), glm::dvec2(-0.15, -0.2),
                                 glm::dvec2(0.4, 0.0), glm::dvec2(-0.65, 0.1), glm::dvec2(0.62, 0.2),
                                 glm::dvec2(1.3, 0.0)}) {
    const glm::dvec3 point(probe.x, 0.0, probe.y);
    double E = 1.0;  // the direct light
    int covering = 0;
    for (double x : {-shift, shift}) {
      const double mapped = mapIrradiance(map, point - glm::dvec3(x, 0.0, 0.0));
      if (mapped < 0) continue;
      E += mapped - 1.0;
      ++covering;
    }
    overlapped += covering == 2;
    const float pixel = groundPixel(renderer, point);
    const double expected = 0.5 * E / std::numbers::pi;
    std::printf("two maps: ground at (%.2f, %.2f), %d maps: radiance %.5f, ρE/π %.5f\n", probe.x, probe.y, covering,
                pixel, expected);
    EXPECT_NEAR(pixel, expected, 0.01 * expected + 1e-5) << probe.x << ", " << probe.y;
  }
  EXPECT_GE(overlapped, 3);
}

// Nine baked amber spheres in one shader (the thesis' Fig. 7.5a has nine objects): each binds its
// optics and interfaces textures and its bricks, and no more. σa is one constant in the glass, so
// the march takes it from the material (MEDIUM_SIGMA_A) and the field is not uploaded; the receiver
// maps are summed into the one ground map. Before, nine such objects asked for 9 × 5 + 1 = 46
// textures of the 32 one shader gets. Through a sphere's centre (no Fresnel, the environment 1)
// the pixel is exp(−σa·2r), as the fetched σa gave it.
TEST_F(SharpViewerTest, NineBakedAmberSpheresFitOneShader) {
  const glm::dvec3 sigma_a(0.4, 1.6, 4.5);
  Volume amber = sharpVolume("procedural:sphere,r=0.3,center=0:0.5:0,ior=1.5,sigma_a=0.4:1.6:4.5", 32,
                             box({-0.4, 0.1, -0.4}, {0.4, 0.9, 0.4}));
  ASSERT_TRUE(slotMedia(amber, interfaceTable(amber)).sigma_a_constant);
  const Volume baked = bakedSphereOverAFloor();
  amber.receivers = baked.receivers;
  amber.metadata["light"] = baked.metadata.at("light");
  Scene scene = floorScene(9);
  scene.environment.uniform = glm::dvec3(1.0);
  for (int k = 0; k < 9; ++k) scene.objects[k].translate = glm::dvec3(0.9 * (k % 3 - 1), 0.0, 0.9 * (k / 3 - 1));
  LoadedScene loaded = sceneFromVolumes(scene, std::vector<Volume>(9, amber));
  RenderSettings no_fresnel;
  no_fresnel.fresnel = false;
  SceneRenderer renderer(*shaders_, loaded, no_fresnel);
  EXPECT_TRUE(renderer.usesGroundMap());
  // The middle sphere (centre (0, 0.5, 0)) seen level along (1, 0, 2), a line that passes the
  // other eight at 0.4 from their centres or more (r = 0.3) and then sees the environment: 2r =
  // 0.6 of amber.
  const glm::dvec3 dir = glm::normalize(glm::dvec3(1.0, 0.0, 2.0));
  const Image image = renderer.render(lookAlong(glm::dvec3(0.0, 0.5, 0.0) - 3.0 * dir, dir, 2.0), {5, 5});
  for (int c = 0; c < 3; ++c) {
    const double expected = std::exp(-0.6 * sigma_a[c]);
    // The centre ray meets both surfaces head on; what is left is where the voxelized distance
    // puts them (far under a voxel) and float rounding: 1 %.
    EXPECT_NEAR(image.at(2, 2)[c], expected, 0.01 * expected + 1e-4) << c;
  }
}

// A glass block resting on a black ground, seen through its front face from above: every ray that
// enters the vertical face reaches the bottom at 62.7° from its normal, past the critical angle
// (41.8° for n = 1.5), so it reflects totally, leaves through the back face and sees the white
// environment. None may end on the ground: the bottom face is found a hair above or below the
// ground plane (float noise in the distance), and that must not decide the reflection (it did,
// and speckled the layered cube's bottom layer with ground pixels).
TEST_F(SharpViewerTest, TotalReflectionAtAFaceRestingOnTheGroundNeverShowsTheGround) {
  Scene scene;
  scene.objects.push_back({});
  SceneGroundSpec ground;
  ground.albedo = glm::dvec3(0.0);
  scene.ground = ground;
  scene.environment.uniform = glm::dvec3(1.0);
  LoadedScene loaded = sceneFromVolumes(
      scene, {sharpVolume("procedural:box,size=0.4,center=0:0.2:0,ior=1.5", 48, box({-0.3, -0.1, -0.3}, {0.3, 0.5, 0.3}))});
  loaded.scene.lights.clear();
  SceneRenderer renderer(*shaders_, loaded, RenderSettings{});
  // 43.5° below the horizontal onto (0, 0.08) of the face z = 0.2; inside, 27.3° below: the ray
  // meets the bottom 0.155 behind the face. A 2° field keeps the image within 0.04 of that point.
  const glm::dvec3 d = glm::normalize(glm::dvec3(0.0, -0.95, -1.0)), target(0.0, 0.08, 0.2);
  const Image image = renderer.render(lookAlong(target - 2.0 * d, d, 2.0), {16, 16});
  float darkest = 1e9f;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) darkest = std::min(darkest, image.at(x, y)[0]);
  // Through both faces at 27–44° the transmittance is about 0.92, and the reflections at each face
  // add the environment back (the viewer's other branch): ≈ 1. A ray ending on the black ground
  // gives 0 (times whatever it gathered before); 0.5 separates the two.
  std::printf("block on the ground: darkest pixel %.4f\n", darkest);
  EXPECT_GT(darkest, 0.5f);
}

// A reflection sees the ground (object.glsl branchRadiance): a block of black glass (n = 1.5,
// σa = 400: nothing comes through) stands in the sun (vertical, E = 1) over a white ground
// (ρ = 0.8) under a black sky; its vertical face z = 0.2, seen from above 30° below the horizontal,
// mirrors the ray down onto the ground in the open, which shines ρE/π. So the face shows
// R(30°)·ρE/π, R the exact Fresnel reflectance at the 30° incidence (0.0415) — with sharp interfaces
// (the crossing's other branch), with a smoothed n (the boundary layer's reflection, at the normal
// where |∇n| peaks) and with the glass touching the volume's box (the face the box cuts). A
// reflection that saw only the sky would be black.
TEST_F(SharpViewerTest, AReflectionSeesTheGround) {
  const double theta = glm::radians(30.0);  // incidence on the face, and the view's angle below the horizontal
  const double expected = reference::fresnelReflectance(1.0, 1.5, std::cos(theta)) * 0.8 / std::numbers::pi;
  const std::string glass = "procedural:box,size=0.4,center=0:0.5:0,ior=1.5,sigma_a=400:400:400";
  struct Case {
    const char* name;
    Volume volume;
    double tolerance;
  };
  std::vector<Case> cases;
  // Sharp faces: the crossing's Fresnel is exact; 2 % for the float march and the face found to a
  // fraction of a voxel.
  cases.push_back({"sharp", sharpVolume(glass, 48, box({-0.3, 0.2, -0.3}, {0.3, 0.8, 0.3})), 0.02});
  cases.push_back({"touching the box", sharpVolume(glass, 48, box({-0.3, 0.3, -0.3}, {0.3, 0.7, 0.2})), 0.02});
  // A smoothed n: the layer's normal from ∇n, whose direction the Gaussian keeps on a flat face
  // away from its edges; 5 % for the peak's placement in the layer.
  cases.push_back({"smoothed", test_scenes::proceduralVolume(glass, 48, box({-0.3, 0.2, -0.3}, {0.3, 0.8, 0.3})), 0.05});
  for (Case& c : cases) {
    Scene scene;
    scene.objects.push_back({});
    SceneGroundSpec ground;
    ground.albedo = glm::dvec3(0.8);
    ground.half_extent = 10.0;
    scene.ground = ground;
    scene.environment.uniform = glm::dvec3(0.0);
    SceneLightSpec sun;  // straight down, E = 1
    scene.lights = {sun};
    LoadedScene loaded = sceneFromVolumes(scene, {std::move(c.volume)});
    loaded.scene.lights = {sun};
    SceneRenderer renderer(*shaders_, loaded, RenderSettings{});
    // Onto (0, 0.55) of the face z = 0.2, 30° below the horizontal; mirrored, 30° down towards +z,
    // meeting the ground at z = 0.2 + 0.55·√3 = 1.15, far from the block's footprint.
    const glm::dvec3 d = glm::normalize(glm::dvec3(0.0, -std::sin(theta), -std::cos(theta))), target(0.0, 0.55, 0.2);
    const Image image = renderer.render(lookAlong(target - 1.0 * d, d, 1.0), {8, 8});
    double mean = 0.0;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) mean += image.at(x, y)[1] / 64.0;
    std::printf("%s: the face shows %.5f, R·ρE/π = %.5f\n", c.name, mean, expected);
    EXPECT_NEAR(mean, expected, c.tolerance * expected) << c.name;
  }
}

// A reflection sees the other objects (REFLECT_OBJECTS, one bounce): the black glass block above
// mirrors the view 30° down towards +z into a second object, a box of air that glows with emission
// e = 10 per unit length over z ∈ [0.7, 1.3] (below the view's own path, so that only the mirrored
// ray crosses it), under a black sky with no ground. The face shows R(30°) times what an eye at the
// mirror point sees along the mirrored ray: the glow over 0.6 / cos 30° = 0.693, e·0.693 = 6.93
// (within the 3 % EmissionIntegratesAlongTheRay allows the march's last step in a box). Seeing
// only the sky, as every reflection did before, the face would be black, which
// --no-reflect-objects still gives.
TEST_F(SharpViewerTest, AReflectionSeesTheOtherObjects) {
  const double theta = glm::radians(30.0);
  const double e = 10.0, path = 0.6 / std::cos(theta);
  const double R = reference::fresnelReflectance(1.0, 1.5, std::cos(theta));
  Volume glow;
  glow.grid.dims = glm::ivec3(16);
  glow.grid.bounds_min = glm::dvec3(-0.5, -0.1, 0.7);
  glow.grid.bounds_max = glm::dvec3(0.5, 0.5, 1.3);
  std::fill_n(glow.addField("ior", 1).data.begin(), glow.grid.count(), 1.0f);
  glow.addField("ior_grad", 3);
  std::fill_n(glow.addField("emission", 3).data.begin(), 3 * glow.grid.count(), static_cast<float>(e));
  Scene scene;
  scene.objects.resize(2);
  scene.environment.uniform = glm::dvec3(0.0);
  LoadedScene loaded = sceneFromVolumes(
      scene, {sharpVolume("procedural:box,size=0.4,center=0:0.5:0,ior=1.5,sigma_a=400:400:400", 48,
                          box({-0.3, 0.2, -0.3}, {0.3, 0.8, 0.3})),
              glow});
  loaded.scene.lights.clear();
  const glm::dvec3 d = glm::normalize(glm::dvec3(0.0, -std::sin(theta), -std::cos(theta))), target(0.0, 0.55, 0.2);
  const auto meanOf = [](const Image& image) {
    double mean = 0.0;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) mean += image.at(x, y)[1] / 64.0;
    return mean;
  };
  const auto faceShows = [&](const RenderSettings& settings) {
    return meanOf(SceneRenderer(*shaders_, loaded, settings).render(lookAlong(target - 1.0 * d, d, 1.0), {8, 8}));
  };
  const double seen = faceShows(RenderSettings{});
  RenderSettings sky_only;
  sky_only.reflect_objects = false;
  const double without = faceShows(sky_only);
  // The glow alone, seen from the mirror point along the mirrored ray.
  Scene alone;
  alone.objects.resize(1);
  alone.environment.uniform = glm::dvec3(0.0);
  LoadedScene glow_alone = sceneFromVolumes(alone, {glow});
  glow_alone.scene.lights.clear();
  const glm::dvec3 mirrored(0.0, -std::sin(theta), std::cos(theta));
  const double direct = meanOf(SceneRenderer(*shaders_, glow_alone, RenderSettings{}).render(lookAlong(target, mirrored, 1.0), {8, 8}));
  std::printf("the face mirrors the glow: %.5f, R·(the glow seen directly, %.4f; e·L = %.4f) = %.5f; reflecting the "
              "sky only: %.5f\n",
              seen, direct, e * path, R * direct, without);
  EXPECT_NEAR(direct, e * path, 0.03 * e * path);
  // As AReflectionSeesTheGround: 2 % for the float march and the face found to a fraction of a voxel.
  EXPECT_NEAR(seen, R * direct, 0.02 * R * direct);
  EXPECT_LT(without, 1e-4);
}

// Two absorbing, scattering glasses stacked along the view (A: z in [0, 0.5], n 1.5; B: z in
// [−0.5, 0], n 1.7; each its own slot, each σa and ω̂ one constant: slotMedia finds them, and the
// march reads them by the material it is in), under a uniform baked light E along l, black sky,
// seen along −z at normal incidence. Closed form (Eq. 5.10 with Eq. 3.4, 5.7; the Fresnel factors
// of both crossings): L = (1 − R_A)·[ω̂_A·p·E·(1 − e^(−σ_A·d))/σ_A
//                                   + e^(−σ_A·d)·(1 − R_AB)·ω̂_B·p·E·(1 − e^(−σ_B·d))/σ_B],
// d = 0.5, p the 3D-normalised Henyey–Greenstein of g = 0.6 at cos θ = l·ẑ.
TEST_F(SharpViewerTest, ConstantMediaScatterAndAbsorbAsTheClosedFormSays) {
  const glm::dvec3 sigma_a(0.5, 2.0, 4.0), sigma_b(3.0, 1.0, 0.25);
  const double albedo_a = 0.6, albedo_b = 0.3, g = 0.6, E = 2.0, n_a = 1.5, n_b = 1.7, d = 0.5;
  const glm::dvec3 l = glm::normalize(glm::dvec3(0.0, -0.6, 0.8));
  const double cos_theta = l.z;
  const double phase = (1 - g * g) / (4 * std::numbers::pi * std::pow(1 + g * g - 2 * g * cos_theta, 1.5));
  const double r_a = std::pow((n_a - 1) / (n_a + 1), 2), r_ab = std::pow((n_b - n_a) / (n_b + n_a), 2);
  glm::dvec3 expected;
  for (int c = 0; c < 3; ++c)
    expected[c] = (1 - r_a) * (albedo_a * phase * E * (1 - std::exp(-sigma_a[c] * d)) / sigma_a[c] +
                               std::exp(-sigma_a[c] * d) * (1 - r_ab) * albedo_b * phase * E *
                                   (1 - std::exp(-sigma_b[c] * d)) / sigma_b[c]);
  auto material = [](const glm::dvec3& s, double albedo) {
    char text[128];
    std::snprintf(text, sizeof text, "sigma_a=%g:%g:%g,scatter=%g,g=0.6", s.x, s.y, s.z, albedo);
    return std::string(text);
  };
  for (int res : {32, 48}) {
    Volume v = sharpVolume({"procedural:box,size=0.8:0.8:0.5,center=0:0:0.25,ior=1.5," + material(sigma_a, albedo_a),
                            "procedural:box,size=0.8:0.8:0.5,center=0:0:-0.25,ior=1.7," + material(sigma_b, albedo_b)},
                           res, box({-0.6, -0.6, -0.75}, {0.6, 0.6, 0.75}));
    const SlotMedia media = slotMedia(v, interfaceTable(v));
    ASSERT_TRUE(media.sigma_a_constant && media.scatter_constant) << "the march must read the constants";
    LoadedScene scene = underUniformLight(std::move(v), E, l);
    const Image image = SceneRenderer(*shaders_, scene, RenderSettings{}).render(lookAlong({0, 0, 4}, {0, 0, -1}, 4.0), {9, 9});
    for (int c = 0; c < 3; ++c) {
      std::printf("constant media %d^3: channel %d %.5f, closed form %.5f\n", res, c, image.at(4, 4)[c], expected[c]);
      // The step's own attenuation is integrated exactly, so what is left is float rounding and
      // where the faces lie (the distance field of a box is exact; its interpolation between
      // voxel centres moves a face by far less than 1e-3 of d): 0.2 %.
      EXPECT_NEAR(image.at(4, 4)[c], expected[c], 0.002 * expected[c]) << res << "^3, channel " << c;
    }
    RenderSettings no_scattering;
    no_scattering.scattering = false;
    EXPECT_EQ(SceneRenderer(*shaders_, scene, no_scattering).render(lookAlong({0, 0, 4}, {0, 0, -1}, 4.0), {9, 9}).at(4, 4)[1], 0.0f);
  }
}

// Smoke in a box around a glass ball (the amber bunny's setting: the smoke has n = 1, no surface of
// its own), under a uniform baked light E along l, black sky, seen along −z beside the ball. The
// march takes the smoke's σa and ω̂ as constants over the share of each step inside its box
// (core/interfaces.h airMediumBox). Closed form (Eq. 5.10 with Eq. 3.4, 5.7; no surface on the
// way): L = ω̂·p·E·(1 − e^(−σ·d))/σ, d = 0.77 the box's depth, its faces off the voxel lattice.
TEST_F(SharpViewerTest, SmokeInABoxScattersAndAbsorbsAsTheClosedFormSays) {
  const glm::dvec3 sigma(0.5, 2.0, 4.0);
  const double albedo = 0.6, g = 0.4, E = 2.0, d = 0.77;
  const glm::dvec3 l = glm::normalize(glm::dvec3(0.0, -0.6, 0.8));
  const double phase = (1 - g * g) / (4 * std::numbers::pi * std::pow(1 + g * g - 2 * g * l.z, 1.5));
  for (int res : {32, 48}) {
    Volume v = sharpVolume(std::vector<std::string>{"procedural:sphere,r=0.15,center=0:0:0,ior=1.5",
                            "procedural:box,size=0.7:0.62:0.77,center=0.03:-0.02:0.01,ior=1,sigma_a=0.5:2:4,scatter=0.6,g=0.4"},
                           res, box({-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}));
    ASSERT_TRUE(slotMedia(v, interfaceTable(v)).air_box.has_value()) << "the march must read the smoke's constants";
    LoadedScene scene = underUniformLight(std::move(v), E, l);
    // Rays at x = −0.2, the smoke's and the volume's faces crossed at right angles, the ball missed.
    const Image image = SceneRenderer(*shaders_, scene, RenderSettings{}).render(lookAlong({-0.2, 0, 4}, {0, 0, -1}, 0.5), {9, 9});
    for (int c = 0; c < 3; ++c) {
      const double expected = albedo * phase * E * (1 - std::exp(-sigma[c] * d)) / sigma[c];
      std::printf("smoke box %d^3: channel %d %.5f, closed form %.5f\n", res, c, image.at(4, 4)[c], expected);
      // The attenuation within a step is integrated exactly and the faces are exact (the share of
      // the step in the box), so what is left is float rounding: 0.2 %. (The fetched σa and ω̂,
      // blended over a voxel at each face, were 0.8–6.5 % low at 32³, 0.6–4.8 % at 48³.)
      EXPECT_NEAR(image.at(4, 4)[c], expected, 0.002 * expected) << res << "^3, channel " << c;
    }
  }
}

// Dispersion in sixteen spectral bands through a flint prism (n_d = 1.5, Abbe number 20: Cauchy
// B = 0.0131 µm²), Fresnel off (every band carries all its light), under an environment whose
// radiance is its azimuth, L = 0.5 + atan(x, −z)/2π: each channel of a pixel is then exactly
// Σ_b w_b,c·L(d_b), d_b the band's ray out of the exact prism (Snell at every face, total internal
// reflection where it happens), so the colour split measures each band's deviation. Two rays: at
// minimum deviation (one way for every band), and one that meets the second face at the critical
// angle in the middle of the spectrum (violet's half reflected totally, red's out), at 48³ and 64³.
// With interpolate_bands off the viewer traces every band: exact but for the float march (its
// flat faces' distances are linear, so their normals and crossings are exact). By default it
// traces the spectrum's ends and interpolates the bands between where both took one way
// (raymarch.frag spectralRun), finding where the way changes by bisection: the same as that
// interpolation done here with the exact ends' rays, and off the exact sum by the interpolation's
// own error (linear in the Cauchy term; largest near the critical angle, where the ray leaving is
// steep in n).
TEST_F(SharpViewerTest, SpectralBandsThroughAPrismLeaveAsSnellSaysForEachBand) {
  const double n_d = 1.5, apex = std::numbers::pi / 3.0, cauchy_b = 0.523655 * (n_d - 1.0) / 20.0;
  const std::vector<SpectralBand> bands = spectralBands(16);
  const int count = static_cast<int>(bands.size());
  const auto n_of = [&](int b) { return n_d + cauchy_b * cauchyTerm(bands[static_cast<std::size_t>(b)].lambda_um); };
  test_support::TempDir dir;
  Image sky;  // L = u, the map's horizontal coordinate: linear in the azimuth, so filtering keeps it
  sky.width = 512;
  sky.height = 64;
  sky.channels = 3;
  sky.pixels.resize(static_cast<std::size_t>(sky.width * sky.height * 3));
  for (int y = 0; y < sky.height; ++y)
    for (int x = 0; x < sky.width; ++x)
      for (int c = 0; c < 3; ++c) sky.at(x, y)[c] = (static_cast<float>(x) + 0.5f) / static_cast<float>(sky.width);
  writeImage(dir.path() / "azimuth.exr", sky);
  const auto radiance = [](const glm::dvec3& d) { return 0.5 + std::atan2(d.x, -d.z) / (2.0 * std::numbers::pi); };
  // The procedural prism's faces (sin a, 0, cos a) at the inradius, a = 0°, 120°, 240°, and caps.
  const double inradius = 0.6 / (2.0 * std::sqrt(3.0));
  std::vector<glm::dvec4> planes{{0, 1, 0, 0.5}, {0, -1, 0, 0.5}};
  for (int k = 0; k < 3; ++k) {
    const double a = k * 2.0 * std::numbers::pi / 3.0;
    planes.push_back({std::sin(a), 0.0, std::cos(a), inradius});
  }
  struct Exit {
    glm::dvec3 d;
    int reflections = 0;  // total internal reflections on the way: the way, for this prism
  };
  const auto exactExit = [&](double n, glm::dvec3 p, glm::dvec3 d) {
    const reference::Solid prism = reference::Solid::halfSpaces(planes, n);
    reference::Hit hit;
    Exit exit{d};
    if (!prism.intersect(p, d, 1e-9, hit)) return exit;
    p += hit.t * d;
    d = glm::refract(d, hit.normal, 1.0 / n);
    for (; exit.reflections < 16 && prism.intersect(p, d, 1e-9, hit); ++exit.reflections) {
      p += hit.t * d;
      const glm::dvec3 out = glm::refract(d, -hit.normal, n);
      if (glm::dot(out, out) > 0.0) {
        exit.d = out;
        return exit;
      }
      d = glm::reflect(d, hit.normal);
    }
    return exit;
  };
  // Entering the face of a = 120° at incidence θ (the first test's geometry): the direction.
  const auto along = [](double theta) {
    const double in = std::numbers::pi / 6.0 - theta;
    return glm::dvec3(std::cos(in), 0.0, std::sin(in));
  };
  const double deviation = 2.0 * std::asin(n_d * std::sin(apex / 2.0)) - apex;
  const double minimum = (apex + deviation) / 2.0;
  // The critical angle at the second face for n halfway between bands 7 and 8.
  const double n_change = 0.5 * (n_of(7) + n_of(8));
  const double critical = std::asin(n_change * std::sin(apex - std::asin(1.0 / n_change)));
  for (int res : {48, 64}) {
    LoadedScene scene = oneObject(sharpVolume("procedural:prism,side=0.6,height=1,ior=1.5,abbe=20", res,
                                              box({-0.5, -0.55, -0.5}, {0.5, 0.55, 0.5})));
    scene.scene.environment.uniform.reset();
    scene.scene.environment.file = (dir.path() / "azimuth.exr").string();
    RenderSettings interpolated, every;
    interpolated.fresnel = every.fresnel = false;
    interpolated.bands = every.bands = 16;
    every.interpolate_bands = false;
    SceneRenderer fast(*shaders_, scene, interpolated), slow(*shaders_, scene, every);
    for (const double theta : {minimum, critical}) {
      const glm::dvec3 d = along(theta), eye = -2.0 * d;
      std::vector<Exit> exits;
      for (int b = 0; b < count; ++b) exits.push_back(exactExit(n_of(b), eye, d));
      // Exact, and interpolated as the viewer does between the exact ends of each run of one way.
      glm::dvec3 exact(0.0), exact_interpolated(0.0);
      int ways = 1;
      for (int b0 = 0; b0 < count;) {
        int b1 = b0;
        while (b1 + 1 < count && exits[static_cast<std::size_t>(b1 + 1)].reflections == exits[static_cast<std::size_t>(b0)].reflections) ++b1;
        const double c0 = cauchyTerm(bands[static_cast<std::size_t>(b0)].lambda_um), c1 = cauchyTerm(bands[static_cast<std::size_t>(b1)].lambda_um);
        for (int b = b0; b <= b1; ++b) {
          const SpectralBand& band = bands[static_cast<std::size_t>(b)];
          const double t = b1 > b0 ? (cauchyTerm(band.lambda_um) - c0) / (c1 - c0) : 0.0;
          exact += band.rgb * radiance(exits[static_cast<std::size_t>(b)].d);
          exact_interpolated += band.rgb * radiance(glm::normalize(glm::mix(exits[static_cast<std::size_t>(b0)].d, exits[static_cast<std::size_t>(b1)].d, t)));
        }
        if (b1 + 1 < count) ++ways;
        b0 = b1 + 1;
      }
      const Camera camera = lookAlong(eye, d, 0.2);
      const Image fast_image = fast.render(camera, {5, 5}), slow_image = slow.render(camera, {5, 5});
      const float* a = fast_image.at(2, 2);
      const float* b = slow_image.at(2, 2);
      const glm::dvec3 fast_rgb(a[0], a[1], a[2]), slow_rgb(b[0], b[1], b[2]);
      std::printf("%d³, incidence %.3f° (%d way%s): exact (%.5f, %.5f, %.5f), every band traced (%.5f, %.5f, %.5f); "
                  "interpolated (%.5f, %.5f, %.5f), so between the exact ends (%.5f, %.5f, %.5f)\n",
                  res, glm::degrees(theta), ways, ways > 1 ? "s" : "", exact.x, exact.y, exact.z, slow_rgb.x,
                  slow_rgb.y, slow_rgb.z, fast_rgb.x, fast_rgb.y, fast_rgb.z, exact_interpolated.x,
                  exact_interpolated.y, exact_interpolated.z);
      EXPECT_EQ(ways, theta == minimum ? 1 : 2);
      for (int c = 0; c < 3; ++c) {
        // The float march (a direction off by 10⁻⁴ rad moves L by 1.6·10⁻⁵; measured ≤ 10⁻⁵).
        EXPECT_NEAR(slow_rgb[c], exact[c], 1e-4) << res << " every band, channel " << c;
        EXPECT_NEAR(fast_rgb[c], exact_interpolated[c], 1e-4) << res << " interpolated, channel " << c;
        // The interpolation's own error: measured 1.7·10⁻⁴ at minimum deviation, 1.2·10⁻³ near the
        // critical angle (against a colour split of 6.8·10⁻³ and 0.68).
        EXPECT_NEAR(fast_rgb[c], exact[c], 2e-3) << res << " interpolated against exact, channel " << c;
      }
      // The bands split: blue deviated most (at minimum deviation), violet's half reflected away.
      if (theta == minimum) EXPECT_GT(exact.z - exact.x, 0.005);
      else EXPECT_GT(exact.x - exact.z, 0.5);
    }
  }
}

}  // namespace
}  // namespace eik
