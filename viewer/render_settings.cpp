#include "viewer/render_settings.h"

#include <algorithm>
#include <cctype>

#include "core/error.h"

namespace eik {

RayIntegrator parseRayIntegrator(const std::string& text, const std::string& source) {
  std::string lower = text;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  if (lower == "euler") return RayIntegrator::Euler;
  if (lower == "rk4") return RayIntegrator::RK4;
  throw InputError(source, text, "expected euler or rk4");
}

const char* rayIntegratorName(RayIntegrator integrator) {
  return integrator == RayIntegrator::RK4 ? "rk4" : "euler";
}

}  // namespace eik
