// The viewer window's re-bake (background_bake.h), without a window: the re-bake of an object is
// the bake `lightsim` would make of it with the new light (bit for bit); the caustic it puts on the
// ground moves to where the exact tracer (tests/reference/exact_optics.h) puts it for each light;
// the coarse bake is close to the full one with fewer patch-steps; BackgroundBake lands the newest
// request's bake and cancels what a new request makes stale; the bake options round-trip through
// the manifest and malformed ones are refused by name.
#include "viewer/background_bake.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "core/error.h"
#include "lightsim/bake.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/test_scenes.h"
#include "tests/reference/exact_optics.h"
#include "tests/reference/map_binning.h"
#include "viewer/baked_ball_scene.h"
#include "viewer/window.h"

namespace eik {
namespace {

using test_scenes::bakedScene;
using test_scenes::directional;
using test_scenes::kBallRes;
using test_scenes::lightsimOptions;
using test_scenes::sunAt;


// The scene every test starts from: the ball baked with the sun at azimuth 0 (made once).
const LoadedScene& sceneBakedAtAzimuth0() {
  static const LoadedScene scene = bakedScene(directional(sunAt(0.0)));
  return scene;
}


// The caustic on a map of planar irradiance: the centroid (x, z) of the texels brighter than twice
// the floor's direct irradiance (the focused light under the ball), weighted by irradiance.
glm::dvec2 causticCentroid(const ReceiverMap& map, double direct) {
  glm::dvec2 sum(0.0);
  double weight = 0.0;
  for (int j = 0; j < map.texels.y; ++j)
    for (int i = 0; i < map.texels.x; ++i) {
      const double e = map.rgb(static_cast<std::size_t>(j) * map.texels.x + i).x;
      if (e <= 2.0 * direct) continue;
      const glm::dvec3 c = map.texelCenter(i, j);
      sum += e * glm::dvec2(c.x, c.z);
      weight += e;
    }
  return weight > 0.0 ? sum / weight : glm::dvec2(1e30);
}

// The exact tracer's caustic centroid for the ball lit along `direction`, binned into `map`'s texels.
glm::dvec2 exactCausticCentroid(const ReceiverMap& map, glm::dvec3 direction) {
  reference::DirectionalBeam beam;
  beam.direction = glm::normalize(direction);
  beam.beam_center = {0.0, 1.5, 0.0};
  beam.beam_radius = 1.2;  // the ball and a margin of direct light
  reference::Receiver receiver;
  receiver.point = receiver.center = map.point;
  reference::binLikeMap(map, receiver);
  reference::TraceOptions options;
  options.rays = 1'000'000;
  const reference::ReceiverTally tally = reference::trace({reference::Solid::sphere({0.0, 1.5, 0.0}, 1.0, 1.5)},
                                                          beam, receiver, options);
  return causticCentroid(reference::irradianceLikeMap(map, tally), -beam.direction.y);
}

TEST(BackgroundBake, ARebakeIsTheBakeLightsimMakesWithTheNewLight) {
  const LoadedScene& scene = sceneBakedAtAzimuth0();
  const std::vector<RebakeSource> sources = rebakeSources(scene);
  ASSERT_EQ(sources.size(), 1u);
  EXPECT_FALSE(sources[0].material->has("irradiance"));
  EXPECT_TRUE(sources[0].material->receivers.empty());

  const glm::dvec3 moved = sunAt(90.0);
  const LoadedObject rebaked = rebake(sources[0], moved, BakeQuality::Full);

  // A fresh bake of the unbaked ball with the new light and lightsim's options.
  const Volume ball = test_scenes::sharpVolume("procedural:sphere,r=1,center=0:1.5:0,ior=1.5", kBallRes, std::nullopt, 2.0);
  CpuSimulator simulator(ball);
  const BakeResult fresh = simulator.run(directional(moved), lightsimOptions(ball.grid));
  EXPECT_EQ(rebaked.volume.fields.at("irradiance").data, fresh.irradiance.data);
  EXPECT_EQ(rebaked.volume.fields.at("light_dir").data, fresh.light_dir.data);
  ASSERT_EQ(rebaked.volume.receivers.size(), 1u);
  ReceiverMap fresh_map = fresh.receivers.at(0);
  fresh_map.makeGrey();  // as applyBake keeps a white light's map
  EXPECT_EQ(rebaked.volume.receivers[0].components, fresh_map.components);
  EXPECT_EQ(rebaked.volume.receivers[0].irradiance, fresh_map.irradiance);
  const glm::dvec3 baked_dir(rebaked.volume.metadata.at("light").at("direction").at(0).get<double>(),
                             rebaked.volume.metadata.at("light").at("direction").at(1).get<double>(),
                             rebaked.volume.metadata.at("light").at("direction").at(2).get<double>());
  EXPECT_NEAR(glm::length(baked_dir - glm::normalize(moved)), 0.0, 1e-12);
  EXPECT_NE(rebaked.volume.fields.at("irradiance").data, scene.objects[0].volume.fields.at("irradiance").data);
}

// A scaled object is re-baked as `lightsim SCENE.json` bakes it: at world scale, its σa per world
// unit. An absorbing glass slab 0.3 thick (wider than its volume), placed with scale 2, under the sun
// straight down: the floor under it gets E·(1 − R)²·exp(−σa·0.6), R = 0.04 at each face (the light
// reflected twice inside, R²·e^(−2τ) ≈ 10⁻³ of it, is not followed at one bounce); baked in the
// volume's own unit it would get exp(−σa·0.3), 35 % more.
TEST(BackgroundBake, AScaledObjectIsRebakedAtWorldScale) {
  const auto b = test_scenes::box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  Volume slab = test_scenes::sharpVolume("procedural:box,size=4:0.3:4,center=0:0:0,ior=1.5,sigma_a=1:1:1", 32, b);
  slab.metadata["light"] = directional({0.0, -1.0, 0.0}).toJson();
  slab.receivers.push_back(ReceiverMap{});  // as a baked volume has: the window re-bakes it
  Scene scene;
  SceneObjectSpec placed;
  placed.scale = glm::dvec3(2.0);
  placed.translate = {0.3, 0.0, -0.2};
  scene.objects.push_back(placed);
  SceneGroundSpec ground;
  ground.point = {0.0, -1.2, 0.0};  // the volume's y = −0.6, below its box
  ground.half_extent = 1.5;
  scene.ground = ground;
  const LoadedScene loaded = sceneFromVolumes(scene, {slab});
  const std::vector<RebakeSource> sources = rebakeSources(loaded);
  ASSERT_EQ(sources.size(), 1u);
  EXPECT_EQ(sources[0].frame.scale, 2.0);
  const LoadedObject rebaked = rebake(sources[0], {0.0, -1.0, 0.0}, BakeQuality::Full);
  ASSERT_EQ(rebaked.volume.receivers.size(), 1u);
  const ReceiverMap& map = rebaked.volume.receivers[0];
  // The map in the volume's coordinates: its plane at y = −0.6, the world's −1.2 over the scale.
  EXPECT_NEAR(glm::dot(map.point, map.normal), -0.6, 1e-9);
  // The texel under the slab's middle (the volume's origin, well inside its 4-wide faces).
  const glm::dvec2 uv = map.planeCoordinates(glm::dvec3(0.0, -0.6, 0.0)) - map.origin;
  const int i = static_cast<int>(uv.x / map.pitch), j = static_cast<int>(uv.y / map.pitch);
  const double got = map.rgb(static_cast<std::size_t>(j) * map.texels.x + i).x;
  const double want = (1.0 - 0.04) * (1.0 - 0.04) * std::exp(-1.0 * 0.6);
  std::printf("scaled slab: the floor under it %.5f, exact %.5f (in the volume's unit %.5f)\n", got, want,
              want * std::exp(0.3));
  // 1 %: the followed reflection's share, 10⁻³, and the map's texel at the slab's middle, where the
  // light comes straight through; the volume's unit is off by 35 %.
  EXPECT_NEAR(got / want, 1.0, 0.01);
}

// At two resolutions (32³ and 48³), each against the exact tracer.
TEST(BackgroundBake, TheCausticMovesToWhereExactOpticsPutsIt) {
  for (int res : {kBallRes, 48}) {
    const LoadedScene scene =
        res == kBallRes ? sceneBakedAtAzimuth0() : bakedScene(directional(sunAt(0.0)), res);
    const RebakeSource source = rebakeSources(scene).at(0);
    const double direct = std::sin(glm::radians(60.0));  // the floor's planar irradiance in the open
    glm::dvec2 centroids[2];
    int k = 0;
    for (double azimuth : {0.0, 90.0}) {
      const LoadedObject object = rebake(source, sunAt(azimuth), BakeQuality::Full);
      const ReceiverMap& map = object.volume.receivers.at(0);
      const glm::dvec2 ours = causticCentroid(map, direct);
      const glm::dvec2 exact = exactCausticCentroid(map, sunAt(azimuth));
      std::printf("%d³, azimuth %3.0f: caustic centroid (%.4f, %.4f), exact (%.4f, %.4f), off by %.4f (voxel %.4f)\n",
                  res, azimuth, ours.x, ours.y, exact.x, exact.y, glm::length(ours - exact),
                  source.material->grid.voxelSize().x);
      // Within a quarter of a voxel of the exact centroid (measured 0.001, a sixtieth of a voxel):
      // the ball's voxel surface moves its focus by a fraction of a voxel, the centroid of a spot some
      // 10 voxels across averages that, and the tracer's 10⁶ rays put some 10⁴ in the spot (±1 %).
      EXPECT_LT(glm::length(ours - exact), 0.25 * source.material->grid.voxelSize().x);
      centroids[k++] = ours;
    }
    // The sun turned by 90° about the vertical through the ball: the spot turns with it, from about
    // (0.87, 0) to (0, -0.87) (the ball's axis along the light meets the floor 1.5/tan 60° away).
    EXPECT_GT(glm::length(centroids[1] - centroids[0]), 1.0);
  }
}

TEST(BackgroundBake, ACoarseBakeIsCloseToTheFullOneInFewerPatchSteps) {
  const LoadedScene& scene = sceneBakedAtAzimuth0();
  const RebakeSource source = rebakeSources(scene).at(0);
  CpuSimulator simulator(*source.material);
  SimulationOptions full = source.options;
  SimulationOptions coarse = coarseOptions(full);
  const LightSpec light = directional(sunAt(30.0));
  const BakeResult a = simulator.run(light, full);
  const BakeResult b = simulator.run(light, coarse);
  const double direct = std::sin(glm::radians(60.0));
  const glm::dvec2 ca = causticCentroid(a.receivers.at(0), direct), cb = causticCentroid(b.receivers.at(0), direct);
  std::printf("full %llu patch-steps, coarse %llu; received %.5f of %.5f W / %.5f of %.5f W; caustic centroids "
              "%.4f apart\n",
              static_cast<unsigned long long>(a.stats.total_patches),
              static_cast<unsigned long long>(b.stats.total_patches), a.stats.flux_received.x, a.stats.flux_in.x,
              b.stats.flux_received.x, b.stats.flux_in.x, glm::length(ca - cb));
  EXPECT_LT(b.stats.total_patches, a.stats.total_patches / 2);
  // The same share of the light reaches the floor (the coarse patches tile a slightly larger square
  // of the light and of the coarser map, so more flux enters; what they lose at the ball, Fresnel
  // and kills at its silhouette where they are larger, differs by a fraction of a percent of it):
  // within 1 %.
  EXPECT_NEAR(b.stats.flux_received.x / b.stats.flux_in.x, a.stats.flux_received.x / a.stats.flux_in.x, 0.01);
  // The spot where the full bake has it, within a quarter of a voxel (measured 0.0011, a
  // fiftieth, with texels twice as large): a preview that puts the caustic where it will land.
  EXPECT_LT(glm::length(ca - cb), 0.25 * source.material->grid.voxelSize().x);
}

// Waits until `bake` is idle (a minute at most: a 32³ bake takes about a second).
void waitIdle(const BackgroundBake& bake) {
  const auto start = std::chrono::steady_clock::now();
  while (bake.busy() && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_FALSE(bake.busy()) << "the background bake did not finish";
}

TEST(BackgroundBake, TheNewestRequestLandsAndAStaleBakeIsCancelled) {
  const LoadedScene& scene = sceneBakedAtAzimuth0();
  BackgroundBake bake(scene);
  ASSERT_TRUE(bake.enabled());
  EXPECT_FALSE(bake.busy());
  EXPECT_TRUE(bake.take().empty());

  // Two full requests at once: the first is cancelled (or, if it finished first, lands before the
  // second); the last thing to land is the second light's bake.
  bake.request(sunAt(45.0), BakeQuality::Full);
  bake.request(sunAt(135.0), BakeQuality::Full);
  waitIdle(bake);
  EXPECT_TRUE(bake.lastError().empty()) << bake.lastError();
  std::vector<BackgroundBake::Landed> landed = bake.take();
  ASSERT_FALSE(landed.empty());
  ASSERT_LE(landed.size(), 2u);
  const BackgroundBake::Landed last = landed.back();  // a copy: `landed` is reassigned below
  EXPECT_EQ(last.index, 0);
  EXPECT_EQ(last.quality, BakeQuality::Full);
  const LoadedObject expected = rebake(rebakeSources(scene).at(0), sunAt(135.0), BakeQuality::Full);
  EXPECT_EQ(last.object.volume.fields.at("irradiance").data, expected.volume.fields.at("irradiance").data);
  EXPECT_EQ(last.object.volume.receivers.at(0).irradiance, expected.volume.receivers.at(0).irradiance);
  EXPECT_DOUBLE_EQ(bake.progress(), 1.0);
  EXPECT_TRUE(bake.take().empty()) << "take() hands each bake over once";

  // A coarse request lands a coarse bake.
  bake.request(sunAt(-60.0), BakeQuality::Coarse);
  waitIdle(bake);
  landed = bake.take();
  ASSERT_EQ(landed.size(), 1u);
  EXPECT_EQ(landed[0].quality, BakeQuality::Coarse);
  EXPECT_LT(landed[0].stats.total_patches, last.stats.total_patches / 2);
}

TEST(BackgroundBake, ACancelledRunThrowsAndASetFlagStopsItAtOnce) {
  const Volume ball = test_scenes::sharpVolume("procedural:sphere,r=1,center=0:1.5:0,ior=1.5", 16, std::nullopt, 2.0);
  CpuSimulator simulator(ball);
  SimulationOptions options = lightsimOptions(ball.grid);
  std::atomic<bool> cancel{true};
  options.cancel = &cancel;
  EXPECT_THROW(simulator.run(directional({0, -1, 0}), options), BakeCancelled);
  cancel = false;
  EXPECT_NO_THROW(simulator.run(directional({0, -1, 0}), options));
}

TEST(BackgroundBake, ObjectsNotBakedByADirectionalLightAreLeftAsTheyAre) {
  LoadedScene scene = sceneBakedAtAzimuth0();
  scene.objects.push_back(scene.objects[0]);
  scene.objects.push_back(scene.objects[0]);
  scene.objects[1].volume.metadata["light"] = {{"type", "point"}, {"position", {0, 3, 0}}, {"intensity", {1, 1, 1}}};
  scene.objects[2].volume.fields.erase("irradiance");
  scene.objects[2].volume.metadata.erase("light");
  const std::vector<RebakeSource> sources = rebakeSources(scene);
  ASSERT_EQ(sources.size(), 1u);
  EXPECT_EQ(sources[0].object, 0);
}

TEST(BackgroundBake, BakeOptionsRoundTripAndMalformedOnesAreRefusedByName) {
  SimulationOptions o;
  o.deposit = DepositMode::Max;
  o.deposit_kernel = DepositKernel::Point;
  o.bounces = 3;
  o.integrator = Integrator::RK2;
  o.step_voxels = 0.25;
  o.patch_voxels = 2.0;
  o.split_voxels = 1.5;
  o.split_rule = SplitRule::Quad;
  o.max_depth = 5;
  o.at_max_depth = DepthLimit::Kill;
  o.flux_threshold = 1e-3;
  o.max_steps = 321;
  o.free_flight = true;
  o.volume_deposits = false;
  ReceiverSpec r;
  r.name = "floor";
  r.point = {0.5, -1, 0};
  r.normal = {0, 1, 0};
  r.half_extent = 2.5;
  r.pitch_voxels = 0.5;
  o.receiver = r;
  const SimulationOptions back = bakeOptionsFromJson(bakeOptionsToJson(o), "m.vol.json");
  EXPECT_EQ(bakeOptionsToJson(back), bakeOptionsToJson(o));
  EXPECT_EQ(back.max_steps, 321);
  EXPECT_FALSE(back.volume_deposits);
  ASSERT_TRUE(back.receiver.has_value());
  EXPECT_EQ(back.receiver->name, "floor");
  EXPECT_EQ(back.receiver->point, r.point);

  // Absent keys keep the defaults given.
  SimulationOptions defaults;
  defaults.max_depth = 4;
  EXPECT_EQ(bakeOptionsFromJson(nlohmann::json::object(), "m", defaults).max_depth, 4);

  auto message = [](const nlohmann::json& j) {
    try {
      bakeOptionsFromJson(j, "m.vol.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({{"split_rule", "hex"}}).find("bake_options.split_rule"), std::string::npos);
  EXPECT_NE(message({{"step_voxels", "big"}}).find("bake_options.step_voxels"), std::string::npos);
  EXPECT_NE(message({{"max_steps", 1.5}}).find("bake_options.max_steps"), std::string::npos);
  EXPECT_NE(message({{"receiver", {{"point", {0, 0}}, {"normal", {0, 1, 0}}}}}).find("bake_options.receiver.point"),
            std::string::npos);
  EXPECT_NE(message({{"receiver", {{"point", {0, 0, 0}}, {"normal", {0, 0, 0}}}}}).find("receiver.normal"),
            std::string::npos);
  EXPECT_NE(message({{"step_voxels", -1.0}}).find("m.vol.json"), std::string::npos);  // validateOptions
  EXPECT_NE(message(nlohmann::json::array()).find("bake_options"), std::string::npos);
}

}  // namespace
}  // namespace eik
