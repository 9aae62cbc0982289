#include "lightsim/interface_crossing.h"

#include <algorithm>
#include <array>
#include <utility>
#include <cmath>

namespace eik {

namespace {

// One step of the ray equation in time (Eq. 4.12/4.13) inside material `medium`, without crossing.
void rayStep(glm::dvec3& x, glm::dvec3& w, const glm::dvec4& sample, double dt, Integrator integrator, int medium,
             const VolumeSampler& sampler) {
  auto rhs = [](const glm::dvec4& s, const glm::dvec3& w_) {
    return std::pair<glm::dvec3, glm::dvec3>(w_ / (s.x * s.x), glm::dvec3(s.y, s.z, s.w) / s.x);
  };
  auto at = [&](const glm::dvec3& p) { return sampler.materialOptics(medium, p); };
  switch (integrator) {
    case Integrator::Euler: {  // Eq. 6.1 / 6.2
      const auto [dx, dw] = rhs(sample, w);
      x += dt * dx;
      w += dt * dw;
      break;
    }
    case Integrator::RK2: {
      const auto [dx1, dw1] = rhs(sample, w);
      const auto [dx2, dw2] = rhs(at(x + 0.5 * dt * dx1), w + 0.5 * dt * dw1);
      x += dt * dx2;
      w += dt * dw2;
      break;
    }
    case Integrator::RK4: {
      const auto [dx1, dw1] = rhs(sample, w);
      const auto [dx2, dw2] = rhs(at(x + 0.5 * dt * dx1), w + 0.5 * dt * dw1);
      const auto [dx3, dw3] = rhs(at(x + 0.5 * dt * dx2), w + 0.5 * dt * dw2);
      const auto [dx4, dw4] = rhs(at(x + dt * dx3), w + dt * dw3);
      x += (dt / 6.0) * (dx1 + 2.0 * dx2 + 2.0 * dx3 + dx4);
      w += (dt / 6.0) * (dw1 + 2.0 * dw2 + 2.0 * dw3 + dw4);
      break;
    }
  }
}

// The material just past the surface of slot k at p, entering it (inside) or leaving it, going
// along `dir`: the distances a tenth of a voxel on, with slot k's on the far side of its surface.
// Looking past p matters where two slots share a surface (layers of glass touching): both change
// sign there, and at p itself the other's sign is noise.
int materialBeyond(const VolumeSampler& sampler, const glm::dvec3& p, const glm::dvec3& dir, int k, bool inside) {
  glm::dvec4 d = sampler.distances(p + (0.1 * sampler.h()) * dir);
  d[k] = inside ? -1.0 : 1.0;
  return materialSlot(d, sampler.slotCount());
}

}  // namespace

bool findInterface(const VolumeSampler& sampler, const glm::dvec3& a, const glm::dvec3& b, int from, InterfaceHit& hit) {
  // The end first: a chord that ends in the material it starts in crosses nothing (the common
  // case, one lookup of a byte).
  if (sampler.materialAt(b) == from) return false;
  const glm::dvec4 db = sampler.distances(b), da = sampler.distances(a);
  // The slot surfaces the chord crosses, in order along it: the first that changes the material
  // is the interface (crossing an outer slot's surface inside an inner slot changes nothing).
  std::array<std::pair<double, int>, kMaxInterfaceSlots> crossings{};
  int count = 0;
  for (int k = 0; k < sampler.slotCount(); ++k) {
    const bool in_a = da[k] < 0.0, in_b = db[k] < 0.0;
    if (in_a == in_b) continue;
    // Regula falsi on the distance along the chord, two refinements (the distance is nearly linear
    // within a voxel of the surface).
    double f0 = 0.0, f1 = 1.0, g0 = da[k], g1 = db[k];
    double f = g0 / (g0 - g1);
    for (int it = 0; it < 2; ++it) {
      const double g = sampler.distances(a + f * (b - a))[k];
      if ((g < 0.0) == (g0 < 0.0)) {
        f0 = f;
        g0 = g;
      } else {
        f1 = f;
        g1 = g;
      }
      f = g0 == g1 ? 0.5 * (f0 + f1) : f0 + (f1 - f0) * g0 / (g0 - g1);
    }
    crossings[static_cast<std::size_t>(count++)] = {f, k};
  }
  // Insertion sort of at most kMaxInterfaceSlots entries (std::sort on a partly used std::array
  // trips GCC 12's -Warray-bounds).
  for (int i = 1; i < count; ++i)
    for (int j = i; j > 0 && crossings[static_cast<std::size_t>(j)] < crossings[static_cast<std::size_t>(j - 1)]; --j)
      std::swap(crossings[static_cast<std::size_t>(j)], crossings[static_cast<std::size_t>(j - 1)]);
  int current = from;
  for (int i = 0; i < count; ++i) {
    const auto [f, k] = crossings[static_cast<std::size_t>(i)];
    const int beyond = materialBeyond(sampler, a + f * (b - a), glm::normalize(b - a), k, !(da[k] < 0.0));
    if (beyond == current) continue;
    hit.fraction = f;
    hit.slot = k;
    hit.entered = beyond;
    return true;
  }
  // No surface along the chord changes the corner's material, yet the end is in another one: the
  // corner sits on a surface it just crossed (its own material disagrees with the distances at a).
  // The crossing is here, on the surface of its material or of the one ahead.
  hit.fraction = 0.0;
  hit.slot = from >= 0 ? from : materialSlot(db, sampler.slotCount());
  hit.entered = materialSlot(db, sampler.slotCount());
  return hit.slot >= 0;
}

bool findInterfaceOnChord(const VolumeSampler& sampler, const glm::dvec3& a, const glm::dvec3& b, int from,
                          InterfaceHit& hit) {
  const int pieces = chordPieces(glm::length(b - a), sampler.h());
  if (pieces == 1) return findInterface(sampler, a, b, from, hit);
  const glm::dvec3 piece = (b - a) / static_cast<double>(pieces);
  for (int j = 0; j < pieces; ++j) {
    const glm::dvec3 start = a + static_cast<double>(j) * piece;
    const glm::dvec3 end = j + 1 == pieces ? b : a + static_cast<double>(j + 1) * piece;
    if (findInterface(sampler, start, end, from, hit)) {
      hit.fraction = (static_cast<double>(j) + hit.fraction) / static_cast<double>(pieces);
      return true;
    }
  }
  return false;
}

Refraction refract(const glm::dvec3& d, const glm::dvec3& normal, double n1, double n2) {
  Refraction r;
  const glm::dvec3 nf = glm::dot(d, normal) < 0.0 ? normal : -normal;  // against the ray
  const double cos_i = std::min(1.0, -glm::dot(d, nf));
  const double eta = n1 / n2;
  const double sin2_t = eta * eta * std::max(0.0, 1.0 - cos_i * cos_i);
  if (sin2_t >= 1.0) {
    r.total = true;
    r.reflectance = 1.0;
    r.direction = glm::normalize(d + 2.0 * cos_i * nf);
    return r;
  }
  const double cos_t = std::sqrt(1.0 - sin2_t);
  r.direction = glm::normalize(eta * d + (eta * cos_i - cos_t) * nf);
  r.reflectance = fresnelReflectance(n1, n2, cos_i);
  return r;
}

CornerCrossings advanceCornerSharp(glm::dvec3& x, glm::dvec3& w, int& medium, glm::dvec4& sample, double dt,
                                   Integrator integrator, const VolumeSampler& sampler) {
  CornerCrossings result;
  const bool absorbing = sampler.absorptionPerMaterial();
  // Beer–Lambert along one straight piece in `medium`.
  auto absorb = [&](const glm::dvec3& from, const glm::dvec3& to) {
    if (absorbing) result.optical_depth += sampler.pieceOpticalDepth(medium, from, to, glm::length(to - from));
  };
  double remaining = dt;
  for (int crossing = 0; crossing <= kMaxCrossingsPerStep && remaining > 0.0; ++crossing) {
    glm::dvec3 x1 = x, w1 = w;
    rayStep(x1, w1, sample, remaining, integrator, medium, sampler);
    InterfaceHit hit;
    if (crossing == kMaxCrossingsPerStep || !findInterfaceOnChord(sampler, x, x1, medium, hit) || hit.entered == medium) {
      absorb(x, x1);
      x = x1;
      sample = sampler.materialOptics(medium, x);
      w = renormalised(w1, sample.x);  // |w| = n (ALGORITHM.md step 1)
      return result;
    }
    // Up to the interface (time ∝ distance on the chord in a homogeneous material).
    const glm::dvec3 p = x + hit.fraction * (x1 - x);
    remaining *= 1.0 - hit.fraction;
    absorb(x, p);
    x = p;
    const glm::dvec3 normal = sampler.interfaceNormal(hit.slot, p);
    result.last_slot = hit.slot;
    if (sampler.opaque(hit.entered)) {
      result.blocked = true;
      sample = sampler.materialOptics(medium, x);
      return result;
    }
    const double n1 = sampler.materialOptics(medium, p).x;
    const glm::dvec4 after = sampler.materialOptics(hit.entered, p);
    const glm::dvec3 d = glm::normalize(w1);
    if (glm::dot(normal, normal) == 0.0) {
      // No usable normal (a flat distance): carry on into the new material unbent.
      medium = hit.entered;
      sample = after;
      w = d * after.x;
      continue;
    }
    const Refraction r = refract(d, normal, n1, after.x);
    if (r.total) {
      ++result.reflected;
      w = r.direction * n1;
      sample = sampler.materialOptics(medium, x);
    } else {
      ++result.transmitted;
      result.transmittance *= 1.0 - r.reflectance;
      medium = hit.entered;
      sample = after;
      w = r.direction * after.x;
    }
  }
  return result;
}

bool reflectedPatch(const Patch& transmitted, const VolumeSampler& sampler, double reach, Patch& reflected) {
  reflected = transmitted;
  for (int c = 0; c < 4; ++c) {
    const glm::dvec3 x = transmitted.x[c];
    const glm::dvec3 d = glm::normalize(transmitted.w[c]);
    const int medium = transmitted.medium[c];
    // Back along the ray in pieces of at most two voxels, nearest first: a chord is asked for the
    // material at its end, so one long chord through a thin part of the object (near a sphere's
    // rim) ends in the corner's own material and finds nothing.
    InterfaceHit hit;
    double back_by = -1.0;  // distance from x back to the interface
    const double piece = 2.0 * sampler.h();
    for (double done = 0.0; done < reach && back_by < 0.0; done += piece) {
      const double length = std::min(piece, reach - done);
      if (findInterface(sampler, x - done * d, x - (done + length) * d, medium, hit)) back_by = done + hit.fraction * length;
    }
    if (back_by < 0.0 || hit.entered == medium) return false;
    const glm::dvec3 p = x - back_by * d;
    const glm::dvec3 normal = sampler.interfaceNormal(hit.slot, p);
    if (glm::dot(normal, normal) == 0.0 || sampler.opaque(hit.entered)) return false;
    const double n2 = sampler.materialOptics(medium, p).x, n1 = sampler.materialOptics(hit.entered, p).x;
    // Reversibility: the incident ray is the reverse of the transmitted ray refracted back.
    const Refraction back = refract(-d, normal, n2, n1);
    if (back.total) return false;
    const glm::dvec3 incident = -back.direction;
    const glm::dvec3 r = mirror(incident, normal);
    // Time since the crossing: distance·n2 in the transmitted material; as far along r at speed 1/n1.
    const double travelled = back_by * n2 / n1;
    reflected.x[c] = p + travelled * r;
    reflected.w[c] = n1 * r;
    reflected.medium[c] = hit.entered;
  }
  // A mirror turns the corners' order around: swap x₁ and x₃ so that N points along the
  // propagation again (ALGORITHM.md "Patch state").
  std::swap(reflected.x[1], reflected.x[3]);
  std::swap(reflected.w[1], reflected.w[3]);
  std::swap(reflected.medium[1], reflected.medium[3]);
  return true;
}

}  // namespace eik
