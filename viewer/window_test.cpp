// The interactive window against headless rendering: the same scene, camera and settings through
// runViewerWindow's scripted mode (a real GLFW window, under Xvfb in ctest: see
// viewer/CMakeLists.txt, viewer_tests.WindowUnderXvfb) and through SceneRenderer::render in an
// OSMesa context must give the same HDR image, and the pixels the window's display pass puts on
// the screen must be the PNG that headless output writes. Moving the light re-bakes: the window's
// frame after a scripted light move is the headless render of a fresh bake with that light. Plus
// the light-angle maths of the panel.
#include "viewer/window.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <memory>

#include "core/error.h"
#include "core/image_io.h"
#include "core/testing.h"
#include "gl/context.h"
#include "gl/shader_library.h"
#include "viewer/baked_ball_scene.h"
#include "viewer/environment.h"
#include "viewer/orbit_camera.h"
#include "viewer/scene_renderer.h"

namespace eik {
namespace {

// A 32³ glass ball of radius 0.35 in [-0.5, 0.5]³, n = 1.5 inside, smoothed over ~2 voxels, with
// σa = (0, 0.6, 1.2): curved rays, Fresnel at its boundary and colour from absorption.
Volume glassBall() {
  Volume v;
  const int n = 32;
  v.grid.dims = glm::ivec3(n);
  v.grid.bounds_min = glm::dvec3(-0.5);
  v.grid.bounds_max = glm::dvec3(0.5);
  Field& ior = v.addField("ior", 1);
  Field& grad = v.addField("ior_grad", 3);
  Field& sigma = v.addField("sigma_a", 3);
  const double width = 2.0 / n;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const glm::dvec3 p = v.grid.center(i, j, k);
        const double r = glm::length(p);
        const double s = 0.5 * (1.0 - std::tanh((r - 0.35) / width));  // 1 inside, 0 outside
        const double ds_dr = -0.5 / (width * std::cosh((r - 0.35) / width) * std::cosh((r - 0.35) / width));
        const std::size_t idx = v.grid.index(i, j, k);
        ior.data[idx] = static_cast<float>(1.0 + 0.5 * s);
        const glm::dvec3 g = r > 1e-9 ? 0.5 * ds_dr * p / r : glm::dvec3(0.0);
        for (int c = 0; c < 3; ++c) grad.data[3 * idx + c] = static_cast<float>(g[c]);
        sigma.data[3 * idx + 0] = 0.0f;
        sigma.data[3 * idx + 1] = static_cast<float>(0.6 * s);
        sigma.data[3 * idx + 2] = static_cast<float>(1.2 * s);
      }
  return v;
}

// The glass ball before a checker environment, and the camera the window tests look at it with.
LoadedScene checkerBallScene() {
  LoadedScene scene = sceneFromVolume(glassBall(), "ball");
  applyEnvironmentFlag("checker:1,0.9,0.8", scene.scene.environment);
  return scene;
}
const Camera kBallCamera{{0.3, 0.5, 2.2}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 40.0};

// RGB values of two equally sized HDR images more than one half-float step apart (both went through
// the EXR writer, so equal renders give equal files; the step absorbs a last-bit difference between
// the two GL back ends' float arithmetic).
int hdrMismatches(const Image& a, const Image& b) {
  int mismatches = 0;
  for (std::size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); ++i)
    if (i % 4 != 3 && std::abs(a.pixels[i] - b.pixels[i]) > 1e-3f * std::max(1.0f, std::abs(b.pixels[i]))) ++mismatches;
  return mismatches;
}

TEST(ViewerWindow, LightAnglesRoundTrip) {
  for (const glm::dvec3 up : {glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1), glm::normalize(glm::dvec3(1, 2, 3))}) {
    for (double az : {-170.0, -30.0, 0.0, 45.0, 120.0})
      for (double el : {-60.0, 0.0, 30.0, 85.0}) {
        const glm::dvec3 d = lightDirectionFromAngles(az, el, up);
        EXPECT_NEAR(glm::length(d), 1.0, 1e-12);
        // The elevation is that of the direction the light comes from: travel points down for el > 0.
        EXPECT_NEAR(glm::dot(-d, up), std::sin(glm::radians(el)), 1e-12);
        const glm::dvec2 back = lightAnglesFromDirection(d, up);
        EXPECT_NEAR(back.x, az, 1e-9);
        EXPECT_NEAR(back.y, el, 1e-9);
      }
  }
  // Straight down from above in a Y-up scene: elevation 90°.
  EXPECT_NEAR(lightAnglesFromDirection(glm::dvec3(0, -1, 0), glm::dvec3(0, 1, 0)).y, 90.0, 1e-9);
}

// Skips the test without a display, unless EIKONAL_REQUIRE_DISPLAY is set (ctest runs the window
// tests under xvfb-run as viewer_tests.WindowUnderXvfb), where that is a failure. A macro, because
// GTEST_SKIP and FAIL return from the function they are in.
#define SKIP_WITHOUT_DISPLAY()                                                                       \
  do {                                                                                               \
    if (!gl::displayAvailable()) {                                                                   \
      if (std::getenv("EIKONAL_REQUIRE_DISPLAY") != nullptr)                                         \
        FAIL() << "EIKONAL_REQUIRE_DISPLAY is set but there is no DISPLAY";                          \
      GTEST_SKIP() << "no DISPLAY (ctest runs this under xvfb-run as viewer_tests.WindowUnderXvfb)"; \
    }                                                                                                \
  } while (false)

// Runs the scripted window; a window that cannot open skips the test (fails under
// EIKONAL_REQUIRE_DISPLAY), and so does any RuntimeError of the run there.
#define RUN_WINDOW_OR_SKIP(scene, settings, camera, options)                   \
  do {                                                                         \
    try {                                                                      \
      ASSERT_EQ(runViewerWindow(scene, settings, camera, options), 0);         \
    } catch (const RuntimeError& e) {                                          \
      if (std::getenv("EIKONAL_REQUIRE_DISPLAY") != nullptr) FAIL() << e.what(); \
      GTEST_SKIP() << e.what();                                                \
    }                                                                          \
  } while (false)

TEST(ViewerWindow, WindowImageEqualsHeadlessImageUnderADisplay) {
  SKIP_WITHOUT_DISPLAY();
  test_support::TempDir dir("eikonal-window-test");
  const LoadedScene scene = checkerBallScene();
  RenderSettings settings;
  const Camera camera = kBallCamera;
  const glm::ivec2 size(96, 64);
  const float exposure = 0.5f;
  const ToneMapper tonemap = ToneMapper::Reinhard;

  // Headless, as `viewer --render` does it.
  Image headless;
  {
    gl::ContextOptions options;
    options.backend = gl::GlBackend::Auto;
    gl::GlContext context(options);
    gl::ShaderLibrary shaders;
    SceneRenderer renderer(shaders, scene, settings);
    headless = renderer.render(camera, size);
  }
  writeImage(dir / "headless.exr", headless);
  ImageWriteOptions png;
  png.exposure_ev = exposure;
  png.tonemap = tonemap;
  writeImage(dir / "headless.png", headless, png);

  // In the window, scripted: three frames, then save.
  WindowOptions options;
  options.size = size;
  options.exposure_ev = exposure;
  options.tonemap = tonemap;
  options.scripted_frames = 3;
  options.save = {dir / "window.exr", dir / "window.png"};
  options.quiet = true;
  options.shot_prefix = dir / "shot";
  options.scripted_shot = true;
  RUN_WINDOW_OR_SKIP(scene, settings, camera, options);

  // HDR: both went through the EXR writer (half floats), so equal renders give equal files; the
  // tolerance, one half-float step (2^-10 relative), absorbs a last-bit difference between the two
  // GL back ends' float arithmetic.
  const Image a = readImage(dir / "window.exr");
  const Image b = readImage(dir / "headless.exr");
  ASSERT_EQ(a.width, size.x) << "the window's framebuffer is not the size asked for";
  ASSERT_EQ(a.height, size.y);
  ASSERT_EQ(b.width, size.x);
  int hdr_mismatches = 0, exact = 0;
  double max_diff = 0.0, sum = 0.0, min_v = 1e30, max_v = -1e30;
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x)
      for (int c = 0; c < 3; ++c) {
        const float va = a.at(x, y)[c], vb = b.at(x, y)[c];
        const double diff = std::abs(va - vb);
        max_diff = std::max(max_diff, diff);
        if (diff > 1e-3 * std::max(1.0f, std::abs(vb))) ++hdr_mismatches;
        if (va == vb) ++exact;
        sum += vb;
        min_v = std::min<double>(min_v, vb);
        max_v = std::max<double>(max_v, vb);
      }
  EXPECT_EQ(hdr_mismatches, 0) << "max |window - headless| = " << max_diff;
  std::printf("HDR: %d of %d values identical, max |diff| %.3g\n", exact, size.x * size.y * 3, max_diff);
  EXPECT_GT(max_v - min_v, 0.3) << "the test image should not be flat";

  // Display: the window's screen pixels against the headless PNG, at most one 8-bit step apart.
  const Image sa = readImage(dir / "window.png");
  const Image sb = readImage(dir / "headless.png");
  ASSERT_EQ(sa.width, size.x);
  ASSERT_EQ(sa.height, size.y);
  int png_off_by_more = 0, png_off_by_one = 0;
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x)
      for (int c = 0; c < 3; ++c) {
        const int qa = static_cast<int>(std::lround(sa.at(x, y)[c] * 255.0f));
        const int qb = static_cast<int>(std::lround(sb.at(x, y)[c] * 255.0f));
        if (std::abs(qa - qb) > 1) ++png_off_by_more;
        if (std::abs(qa - qb) == 1) ++png_off_by_one;
      }
  EXPECT_EQ(png_off_by_more, 0);
  EXPECT_LT(png_off_by_one, size.x * size.y * 3 / 100) << "more than 1% of the values off by one step";
  std::printf("PNG: %d of %d values one 8-bit step apart, none more\n", png_off_by_one, size.x * size.y * 3);

  // The S key's files: EXR and PNG rendered and written as `--render` does, so the same bytes' worth
  // of pixels as the headless ones (the EXR to a half-float step as above, the PNG exactly).
  const Image shot_exr = readImage(dir / "shot-001.exr");
  const Image shot_png = readImage(dir / "shot-001.png");
  ASSERT_EQ(shot_exr.width, size.x);
  ASSERT_EQ(shot_png.height, size.y);
  int shot_mismatches = 0;
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x)
      for (int c = 0; c < 3; ++c) {
        const float vb = b.at(x, y)[c];
        if (std::abs(shot_exr.at(x, y)[c] - vb) > 1e-3 * std::max(1.0f, std::abs(vb))) ++shot_mismatches;
        if (shot_png.at(x, y)[c] != sb.at(x, y)[c]) ++shot_mismatches;
      }
  EXPECT_EQ(shot_mismatches, 0);
}

// While the camera is dragged the resolution follows the render budget: down when a frame takes
// longer, up when it is quicker, never past the bounds, and small changes are ignored.
TEST(ViewerWindow, DragScaleFollowsTheRenderBudget) {
  // Four times over budget: half the resolution per axis (a quarter of the pixels).
  EXPECT_NEAR(nextDragScale(0.25f, 4.0 * kDragRenderBudgetMs, 0.25f), 0.125f, 1e-6f);
  // A quarter of the budget: twice the resolution, but not past the bound.
  EXPECT_NEAR(nextDragScale(0.1f, 0.25 * kDragRenderBudgetMs, 0.25f), 0.2f, 1e-6f);
  EXPECT_EQ(nextDragScale(0.2f, 0.25 * kDragRenderBudgetMs, 0.25f), 0.25f);
  EXPECT_EQ(nextDragScale(0.1f, 1e4, 0.25f), kMinDragScale);
  EXPECT_EQ(nextDragScale(0.2f, 1.1 * kDragRenderBudgetMs, 0.25f), 0.2f);  // under 10 %: kept
  EXPECT_EQ(nextDragScale(0.2f, 0.0, 0.25f), 0.2f);                      // nothing measured
  EXPECT_EQ(nextDragScale(0.2f, 1.0, 0.125f), 0.125f);                   // the slider lowered
  EXPECT_EQ(nextDragScale(0.2f, 0.0, 0.01f), kMinDragScale);              // a bound under the minimum
}

// A scripted orbit (`viewer --window-orbit`): the drag frames render at a quarter of the window's
// resolution per axis at most and report their times; the last frame, released, is the headless
// render at the orbited camera (the same drags applied to the same OrbitCamera).
TEST(ViewerWindow, AnOrbitRendersFewerPixelsWhileDraggingThenTheFullView) {
  SKIP_WITHOUT_DISPLAY();
  test_support::TempDir dir("eikonal-window-test");
  const LoadedScene scene = checkerBallScene();
  RenderSettings settings;
  const Camera camera = kBallCamera;
  const glm::ivec2 size(96, 64);
  WindowOptions options;
  options.size = size;
  options.scripted_frames = 5;
  options.scripted_orbit_px = 12.0;
  options.save = {dir / "window.exr"};
  options.quiet = true;
  WindowOptions::Report report;
  options.report = &report;
  RUN_WINDOW_OR_SKIP(scene, settings, camera, options);
  ASSERT_EQ(report.orbit_frame_ms.size(), 3u);  // frames 2 to 4 of 5
  EXPECT_EQ(report.orbit_render_ms.size(), 3u);
  EXPECT_GT(report.orbit_render_size.x, 0);
  EXPECT_LE(report.orbit_render_size.x, size.x / 4);
  EXPECT_LE(report.orbit_render_size.y, size.y / 4);
  OrbitCamera orbit(camera);
  for (int i = 0; i < 3; ++i) orbit.orbitByPixels(12.0, 0.0, size.y);
  Image headless;
  {
    gl::GlContext context;
    gl::ShaderLibrary shaders;
    SceneRenderer renderer(shaders, scene, settings);
    headless = renderer.render(orbit.camera(), size);
    // The orbit moved the view: the camera as loaded sees another picture.
    const Image unmoved = renderer.render(camera, size);
    double moved = 0.0;
    for (std::size_t i = 0; i < unmoved.pixels.size(); ++i) moved += std::abs(unmoved.pixels[i] - headless.pixels[i]);
    EXPECT_GT(moved, 0.01 * static_cast<double>(unmoved.pixels.size()));
  }
  writeImage(dir / "headless.exr", headless);
  const Image a = readImage(dir / "window.exr");
  const Image b = readImage(dir / "headless.exr");
  ASSERT_EQ(a.width, size.x);
  ASSERT_EQ(a.height, size.y);
  EXPECT_EQ(hdrMismatches(a, b), 0);
}

TEST(ViewerWindow, ResizedWindowRendersAtItsNewSize) {
  SKIP_WITHOUT_DISPLAY();
  test_support::TempDir dir("eikonal-window-test");
  LoadedScene scene = sceneFromVolume(glassBall(), "ball");
  applyEnvironmentFlag("checker:1,1,1", scene.scene.environment);
  RenderSettings settings;
  const Camera camera{{0.0, 0.4, 2.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 40.0};
  const glm::ivec2 first(48, 32), resized(80, 60);
  WindowOptions options;
  options.size = first;
  options.scripted_frames = 2;
  options.scripted_resize = resized;
  options.save = {dir / "window.exr"};
  options.quiet = true;
  RUN_WINDOW_OR_SKIP(scene, settings, camera, options);
  Image headless;
  {
    gl::GlContext context;
    gl::ShaderLibrary shaders;
    SceneRenderer renderer(shaders, scene, settings);
    headless = renderer.render(camera, resized);  // the new aspect ratio, too
  }
  writeImage(dir / "headless.exr", headless);
  const Image a = readImage(dir / "window.exr");
  const Image b = readImage(dir / "headless.exr");
  ASSERT_EQ(a.width, resized.x);
  ASSERT_EQ(a.height, resized.y);
  EXPECT_EQ(hdrMismatches(a, b), 0);
}


// The check: a scripted light move in the window (as the sliders move it) re-bakes in the
// background, and the saved frame shows the caustic where a fresh headless bake with that light
// puts it: the window's HDR image equals the headless render of the scene baked anew with the
// moved light, and differs from the scene as loaded.
TEST(ViewerWindow, ALightMoveRebakesAndTheCausticFollows) {
  SKIP_WITHOUT_DISPLAY();
  test_support::TempDir dir("eikonal-window-test");
  const LoadedScene loaded = test_scenes::bakedScene(test_scenes::directional(test_scenes::sunAt(0.0)));
  LoadedScene scene = loaded;
  applyEnvironmentFlag("uniform:0.2,0.2,0.2", scene.scene.environment);
  RenderSettings settings;
  const Camera camera{{0.0, 7.0, 2.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 40.0};  // the floor around the ball
  const glm::ivec2 size(128, 96);
  WindowOptions options;
  options.size = size;
  options.scripted_frames = 2;
  options.scripted_light = glm::dvec2(90.0, 60.0);
  options.save = {dir / "window.exr", dir / "window.png"};
  options.quiet = true;
  RUN_WINDOW_OR_SKIP(scene, settings, camera, options);

  // Headless: the scene as loaded, and the scene baked afresh with the sun at azimuth 90°.
  LoadedScene fresh = test_scenes::bakedScene(test_scenes::directional(test_scenes::sunAt(90.0)));
  fresh.scene.environment = scene.scene.environment;
  Image before, after;
  {
    gl::GlContext context;
    gl::ShaderLibrary shaders;
    before = SceneRenderer(shaders, scene, settings).render(camera, size);
    after = SceneRenderer(shaders, fresh, settings).render(camera, size);
  }
  writeImage(dir / "before.exr", before);
  writeImage(dir / "after.exr", after);
  ImageWriteOptions png;
  writeImage(dir / "before.png", before, png);
  writeImage(dir / "after.png", after, png);
  const Image window = readImage(dir / "window.exr");
  const Image expected = readImage(dir / "after.exr");
  const Image old = readImage(dir / "before.exr");
  ASSERT_EQ(window.width, size.x);
  ASSERT_EQ(window.height, size.y);
  // Against the fresh bake: one half-float step (both went through the EXR writer; the window's
  // GL and OSMesa may differ in the last bit). Against the old bake: the caustic and the shadow
  // have moved, so many pixels differ by far more.
  int mismatches = 0, moved = 0;
  for (std::size_t i = 0; i < window.pixels.size(); ++i) {
    if (i % 4 == 3) continue;
    if (std::abs(window.pixels[i] - expected.pixels[i]) > 1e-3f * std::max(1.0f, std::abs(expected.pixels[i])))
      ++mismatches;
    if (std::abs(window.pixels[i] - old.pixels[i]) > 0.1f * std::max(0.1f, std::abs(old.pixels[i]))) ++moved;
  }
  EXPECT_EQ(mismatches, 0) << "the window's frame is not the fresh bake's (" << dir.path() << ")";
  const int values = size.x * size.y * 3;
  std::printf("light move: %d of %d values changed by more than 10 %%, %d differ from the fresh bake\n", moved,
              values, mismatches);
  EXPECT_GT(moved, values / 20) << "the frame hardly changed: the caustic did not move";
}

}  // namespace
}  // namespace eik
