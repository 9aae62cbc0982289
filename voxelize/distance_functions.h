// Signed distance primitives the procedural shapes are built from (procedural_shapes.cpp): exact,
// hence 1-Lipschitz, negative inside. Inline, because the implicit voxeliser evaluates them millions
// of times per shape (implicit_voxelizer.h).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace eik {

// Axis-aligned box centred at the origin with half side lengths `half`.
inline double sdBox(const glm::dvec3& p, const glm::dvec3& half) {
  const glm::dvec3 q = glm::abs(p) - half;
  return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

// The box with its edges and corners rounded by `radius` (the outer extent stays `half`).
inline double sdRoundBox(const glm::dvec3& p, const glm::dvec3& half, double radius) {
  return sdBox(p, half - radius) - radius;
}

// 2D rectangle centred at the origin with half side lengths `half`.
inline double sdBox2(const glm::dvec2& p, const glm::dvec2& half) {
  const glm::dvec2 q = glm::abs(p) - half;
  return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, q.y), 0.0);
}

// Combines a 2D distance d (in the plane) with a 1D distance e (along the third axis) into the
// exact distance of their intersection-like product (extrusion, capped cylinder).
inline double combine2(double d, double e) {
  return std::min(std::max(d, e), 0.0) + glm::length(glm::max(glm::dvec2(d, e), 0.0));
}

// Cylinder around the y axis, centre at y = 0, edges rounded by `rounding`.
inline double sdRoundCylinderY(const glm::dvec3& p, double radius, double half_height, double rounding) {
  const double rho = std::sqrt(p.x * p.x + p.z * p.z);
  return combine2(rho - radius + rounding, std::abs(p.y) - half_height + rounding) - rounding;
}

}  // namespace eik
