#include "viewer/orbit_camera.h"

#include <algorithm>
#include <cmath>

namespace eik {

namespace {
constexpr double kPi = 3.14159265358979323846;

// A unit vector perpendicular to `n` (unit).
glm::dvec3 anyPerpendicular(const glm::dvec3& n) {
  glm::dvec3 other = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(n, other));
}
}  // namespace

OrbitCamera::OrbitCamera(const Camera& start) : target_(start.target), fov_y_deg_(start.fov_y_deg) {
  up_ = glm::length(start.up) > 1e-12 ? glm::normalize(start.up) : glm::dvec3(0, 1, 0);
  glm::dvec3 offset = start.eye - start.target;
  distance_ = std::clamp(glm::length(offset), kMinDistance, kMaxDistance);
  const glm::dvec3 dir = glm::length(offset) > 1e-12 ? glm::normalize(offset) : up_;
  const glm::dvec3 horizontal = dir - glm::dot(dir, up_) * up_;
  axis_a_ = glm::length(horizontal) > 1e-9 ? glm::normalize(horizontal) : anyPerpendicular(up_);
  axis_b_ = glm::cross(up_, axis_a_);
  yaw_ = 0.0;
  pitch_ = std::clamp(std::asin(std::clamp(glm::dot(dir, up_), -1.0, 1.0)), -kMaxPitchRad, kMaxPitchRad);
}

glm::dvec3 OrbitCamera::offsetDirection() const {
  const glm::dvec3 horizontal = std::cos(yaw_) * axis_a_ + std::sin(yaw_) * axis_b_;
  return std::cos(pitch_) * horizontal + std::sin(pitch_) * up_;
}

glm::dvec3 OrbitCamera::forward() const { return -offsetDirection(); }
glm::dvec3 OrbitCamera::right() const { return glm::normalize(glm::cross(forward(), up_)); }
glm::dvec3 OrbitCamera::screenUp() const { return glm::cross(right(), forward()); }

Camera OrbitCamera::camera() const {
  Camera c;
  c.target = target_;
  c.eye = target_ + distance_ * offsetDirection();
  c.up = up_;
  c.fov_y_deg = fov_y_deg_;
  return c;
}

void OrbitCamera::orbit(double yaw_rad, double pitch_rad) {
  yaw_ = std::remainder(yaw_ + yaw_rad, 2.0 * kPi);
  pitch_ = std::clamp(pitch_ + pitch_rad, -kMaxPitchRad, kMaxPitchRad);
}

void OrbitCamera::pan(double dx, double dy) {
  const double view_height = 2.0 * distance_ * std::tan(glm::radians(fov_y_deg_) / 2.0);
  target_ += view_height * (dx * right() + dy * screenUp());
}

void OrbitCamera::zoom(double factor) {
  if (!(factor > 0.0) || !std::isfinite(factor)) return;
  distance_ = std::clamp(distance_ * factor, kMinDistance, kMaxDistance);
}

void OrbitCamera::orbitByPixels(double dx_px, double dy_px, double height_px) {
  const double per_pixel = kPi / std::max(height_px, 1.0);
  // Dragging right turns the scene right, i.e. the eye goes left (clockwise seen from above);
  // dragging down (dy > 0 in window coordinates) raises the eye.
  orbit(-dx_px * per_pixel, dy_px * per_pixel);
}

void OrbitCamera::panByPixels(double dx_px, double dy_px, double height_px) {
  // The scene follows the cursor: the target moves against the drag.
  const double h = std::max(height_px, 1.0);
  pan(-dx_px / h, dy_px / h);
}

void OrbitCamera::zoomBySteps(double steps) { zoom(std::pow(0.9, steps)); }

}  // namespace eik
