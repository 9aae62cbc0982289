// An orbit camera for the interactive viewer: the eye circles a target at a distance, turned by
// yaw (about the scene's up axis) and pitch (elevation above the plane perpendicular to up), the
// target moves in the view plane (pan), and the distance scales (zoom). Works for any `up`
// (Y-up and Z-up scenes alike); yaw 0 and the reference direction come from the starting camera,
// so fromCamera(c).camera() gives back c.
#pragma once

#include <glm/glm.hpp>

#include "viewer/camera.h"

namespace eik {

class OrbitCamera {
 public:
  // The pitch stays this far from ±90° so that the view never looks along `up`.
  static constexpr double kMaxPitchRad = 1.5533430342749532;  // 89°
  static constexpr double kMinDistance = 1e-4;
  static constexpr double kMaxDistance = 1e6;

  OrbitCamera() : OrbitCamera(Camera{}) {}
  explicit OrbitCamera(const Camera& start);

  Camera camera() const;

  // Turns the eye about the target: `yaw_rad` about `up` (positive: counter-clockwise seen from
  // above), `pitch_rad` up or down (clamped to ±kMaxPitchRad).
  void orbit(double yaw_rad, double pitch_rad);
  // Moves target and eye together in the view plane by (dx, dy) in units of the view's height at
  // the target's distance: pan(0, 0.25) moves the view up by a quarter of the screen, so the old
  // target then projects at NDC y = -0.5. dx is to the right, dy up.
  void pan(double dx, double dy);
  // Multiplies the distance by `factor` (> 0; < 1 moves closer), clamped to [kMinDistance, kMaxDistance].
  void zoom(double factor);

  // Mouse helpers for a viewport `height_px` pixels high: a drag across the whole height turns by
  // 180° (orbit) or moves the scene with the cursor (pan; `dy_px` grows downwards as in window
  // coordinates); each scroll step zooms by 10%.
  void orbitByPixels(double dx_px, double dy_px, double height_px);
  void panByPixels(double dx_px, double dy_px, double height_px);
  void zoomBySteps(double steps);

  glm::dvec3 target() const { return target_; }
  glm::dvec3 up() const { return up_; }
  double distance() const { return distance_; }
  double yaw() const { return yaw_; }
  double pitch() const { return pitch_; }
  double fovYDeg() const { return fov_y_deg_; }
  // Unit vectors of the current view: from the eye to the target, screen right, screen up.
  glm::dvec3 forward() const;
  glm::dvec3 right() const;
  glm::dvec3 screenUp() const;

 private:
  glm::dvec3 offsetDirection() const;  // unit vector from the target to the eye

  glm::dvec3 target_{0.0};
  glm::dvec3 up_{0.0, 1.0, 0.0};
  glm::dvec3 axis_a_{0.0, 0.0, 1.0};  // yaw 0 direction, ⟂ up
  glm::dvec3 axis_b_{1.0, 0.0, 0.0};  // yaw 90°: cross(up, axis_a)
  double distance_ = 3.0;
  double yaw_ = 0.0;
  double pitch_ = 0.0;
  double fov_y_deg_ = 40.0;
};

}  // namespace eik
