// The orbit camera's maths: round trip from a Camera, orbit keeps target and distance, the pitch
// clamp, pan moves the view by the stated fraction of the screen, zoom scales the distance, and
// all of it with a Z-up scene as well as a Y-up one.
#include "viewer/orbit_camera.h"

#include <gtest/gtest.h>

#include <cmath>

namespace eik {
namespace {

constexpr double kPi = 3.14159265358979323846;

void expectNear(const glm::dvec3& a, const glm::dvec3& b, double tol, const char* what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

// Where world point p lands in normalised device coordinates of camera c (aspect 1).
glm::dvec2 projectNdc(const Camera& c, const glm::dvec3& p) {
  glm::dvec4 clip = c.projection(1.0) * c.view() * glm::dvec4(p, 1.0);
  return glm::dvec2(clip) / clip.w;
}

Camera yUp() { return Camera{{1.0, 2.0, 5.0}, {0.5, 0.25, -0.5}, {0, 1, 0}, 35.0}; }
Camera zUp() { return Camera{{4.0, -3.0, 2.0}, {0.0, 0.0, 0.5}, {0, 0, 1}, 50.0}; }

TEST(OrbitCamera, RoundTripsTheStartingCamera) {
  for (const Camera& start : {yUp(), zUp()}) {
    Camera c = OrbitCamera(start).camera();
    expectNear(c.eye, start.eye, 1e-12, "eye");
    expectNear(c.target, start.target, 0, "target");
    expectNear(c.up, start.up, 0, "up");
    EXPECT_EQ(c.fov_y_deg, start.fov_y_deg);
  }
}

TEST(OrbitCamera, OrbitKeepsTargetAndDistanceAndAFullTurnReturns) {
  for (const Camera& start : {yUp(), zUp()}) {
    OrbitCamera orbit(start);
    const double d = glm::length(start.eye - start.target);
    orbit.orbit(0.7, 0.3);
    Camera c = orbit.camera();
    EXPECT_NEAR(glm::length(c.eye - c.target), d, 1e-12);
    expectNear(c.target, start.target, 0, "target");
    EXPECT_GT(glm::length(c.eye - start.eye), 0.1);  // it did move
    // Yaw turns about `up`: the height along up changes only with pitch.
    OrbitCamera yaw_only(start);
    yaw_only.orbit(1.1, 0.0);
    EXPECT_NEAR(glm::dot(yaw_only.camera().eye - start.target, start.up), glm::dot(start.eye - start.target, start.up),
                1e-12);
    // A full turn of yaw and pitch back to where it was.
    orbit.orbit(2 * kPi - 0.7, -0.3);
    expectNear(orbit.camera().eye, start.eye, 1e-12, "eye after a full turn");
  }
}

TEST(OrbitCamera, PitchIsClampedShortOfTheUpAxis) {
  OrbitCamera orbit(yUp());
  orbit.orbit(0.0, 10.0);
  EXPECT_DOUBLE_EQ(orbit.pitch(), OrbitCamera::kMaxPitchRad);
  Camera c = orbit.camera();
  const double cos_angle = glm::dot(glm::normalize(c.eye - c.target), c.up);
  EXPECT_NEAR(cos_angle, std::sin(OrbitCamera::kMaxPitchRad), 1e-12);
  EXPECT_LT(cos_angle, 1.0 - 1e-5);  // never along up: lookAt stays defined
  orbit.orbit(0.0, -20.0);
  EXPECT_DOUBLE_EQ(orbit.pitch(), -OrbitCamera::kMaxPitchRad);
  // The basis stays orthonormal and right-handed.
  EXPECT_NEAR(glm::dot(orbit.right(), orbit.forward()), 0.0, 1e-12);
  EXPECT_NEAR(glm::dot(orbit.screenUp(), orbit.forward()), 0.0, 1e-12);
  expectNear(glm::cross(orbit.right(), orbit.screenUp()), -orbit.forward(), 1e-12, "right x up = backwards");
}

TEST(OrbitCamera, PanMovesTheViewByTheStatedFractionOfTheScreen) {
  for (const Camera& start : {yUp(), zUp()}) {
    OrbitCamera orbit(start);
    orbit.pan(0.1, 0.25);
    Camera c = orbit.camera();
    // Eye and target moved together, perpendicular to the view direction.
    expectNear(c.eye - start.eye, c.target - start.target, 1e-12, "eye and target move together");
    EXPECT_NEAR(glm::dot(c.target - start.target, glm::normalize(start.target - start.eye)), 0.0, 1e-12);
    // The old target is now left of and below the centre: x = -2·0.1 (aspect 1), y = -2·0.25.
    glm::dvec2 ndc = projectNdc(c, start.target);
    EXPECT_NEAR(ndc.x, -0.2, 1e-9);
    EXPECT_NEAR(ndc.y, -0.5, 1e-9);
  }
}

TEST(OrbitCamera, DraggingMovesTheSceneWithTheCursor) {
  OrbitCamera orbit(yUp());
  const glm::dvec3 old_target = orbit.target();
  // Drag 50 px right and 100 px down in a 400 px high window: the old target follows the cursor,
  // 2·50/400 right and 2·100/400 down in NDC.
  orbit.panByPixels(50, 100, 400);
  glm::dvec2 ndc = projectNdc(orbit.camera(), old_target);
  EXPECT_NEAR(ndc.x, 0.25, 1e-9);
  EXPECT_NEAR(ndc.y, -0.5, 1e-9);
  // A drag across the whole height orbits by half a turn.
  OrbitCamera o2(yUp());
  o2.orbitByPixels(400, 0, 400);
  EXPECT_NEAR(std::abs(o2.yaw()), kPi, 1e-12);
}

TEST(OrbitCamera, ZoomScalesTheDistanceAlongTheSameLine) {
  OrbitCamera orbit(zUp());
  const Camera start = zUp();
  const double d = orbit.distance();
  orbit.zoom(0.5);
  Camera c = orbit.camera();
  EXPECT_NEAR(glm::length(c.eye - c.target), 0.5 * d, 1e-12);
  expectNear(glm::normalize(c.eye - c.target), glm::normalize(start.eye - start.target), 1e-12, "direction");
  orbit.zoomBySteps(2);
  EXPECT_NEAR(orbit.distance(), 0.5 * d * 0.81, 1e-12);
  orbit.zoom(0.0);  // ignored
  orbit.zoom(-1.0);
  EXPECT_NEAR(orbit.distance(), 0.5 * d * 0.81, 1e-12);
  orbit.zoom(1e-30);
  EXPECT_EQ(orbit.distance(), OrbitCamera::kMinDistance);
}

}  // namespace
}  // namespace eik
