#include "viewer/render_settings.h"

#include "core/error.h"
#include "core/text.h"

namespace eik {

RayIntegrator parseRayIntegrator(const std::string& text, const std::string& source) {
  const std::string name = lower(text);
  if (name == "euler") return RayIntegrator::Euler;
  if (name == "rk4") return RayIntegrator::RK4;
  throw InputError(source, text, "expected euler or rk4");
}

const char* rayIntegratorName(RayIntegrator integrator) {
  return integrator == RayIntegrator::RK4 ? "rk4" : "euler";
}

}  // namespace eik
