#include "voxelize/procedural.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>

#include "core/error.h"
#include "core/parallel.h"
#include "voxelize/material_spec.h"

namespace eik {
namespace {

using glm::dvec2;
using glm::dvec3;

// ---------------------------------------------------------------------------------------------
// Signed distance primitives (exact, hence 1-Lipschitz; negative inside).

double sdBox(const dvec3& p, const dvec3& half) {
  const dvec3 q = glm::abs(p) - half;
  return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

double sdRoundBox(const dvec3& p, const dvec3& half, double radius) { return sdBox(p, half - radius) - radius; }

double sdBox2(const dvec2& p, const dvec2& half) {
  const dvec2 q = glm::abs(p) - half;
  return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, q.y), 0.0);
}

// Combines a 2D distance d (in the plane) with a 1D distance e (along the third axis) into the
// exact distance of their intersection-like product (extrusion, capped cylinder).
double combine2(double d, double e) {
  return std::min(std::max(d, e), 0.0) + glm::length(glm::max(dvec2(d, e), 0.0));
}

// Cylinder around the y axis, centre at y = 0, edges rounded by `rounding`.
double sdRoundCylinderY(const dvec3& p, double radius, double half_height, double rounding) {
  const double rho = std::sqrt(p.x * p.x + p.z * p.z);
  return combine2(rho - radius + rounding, std::abs(p.y) - half_height + rounding) - rounding;
}

// ---------------------------------------------------------------------------------------------
// Parameters.

enum class Kind { Number, Triple, Choice };

struct ParamDef {
  std::string key;
  Kind kind = Kind::Number;
  std::string default_value;  // empty: optional, unset by default
  double lo = -1e300, hi = 1e300;
  bool lo_open = false, hi_open = false;
  std::vector<std::string> choices;
  std::string meaning;
};

ParamDef num(std::string key, std::string def, double lo, double hi, bool lo_open, std::string meaning) {
  ParamDef p;
  p.key = std::move(key);
  p.default_value = std::move(def);
  p.lo = lo;
  p.hi = hi;
  p.lo_open = lo_open;
  p.meaning = std::move(meaning);
  return p;
}
ParamDef positive(std::string key, std::string def, std::string meaning) {
  return num(std::move(key), std::move(def), 0.0, 1e300, true, std::move(meaning));
}
ParamDef ior(std::string key, std::string def, std::string meaning) {
  return num(std::move(key), std::move(def), 1.0, 1e300, false, std::move(meaning));
}
ParamDef triple(std::string key, std::string def, double lo, bool lo_open, std::string meaning) {
  ParamDef p = num(std::move(key), std::move(def), lo, 1e300, lo_open, std::move(meaning));
  p.kind = Kind::Triple;
  return p;
}
ParamDef choice(std::string key, std::string def, std::vector<std::string> choices, std::string meaning) {
  ParamDef p;
  p.key = std::move(key);
  p.kind = Kind::Choice;
  p.default_value = std::move(def);
  p.choices = std::move(choices);
  p.meaning = std::move(meaning);
  return p;
}
ParamDef centerParam() { return triple("center", "0:0:0", -1e300, false, "centre of the object (X:Y:Z)"); }

std::string fmt(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

struct ShapeDef;

// A shape's validated parameters.
class Params {
 public:
  Params(const ShapeDef& shape, const ProceduralSpec& spec);

  double number(const std::string& key) const;
  dvec3 vec(const std::string& key) const;
  std::string text(const std::string& key) const { return values_.at(key); }
  bool given(const std::string& key) const {
    return given_.count(key) != 0 || std::any_of(material_pairs_.begin(), material_pairs_.end(),
                                                 [&](const KeyValue& kv) { return kv.first == key; });
  }
  // The Cauchy B for index n if the user gave `abbe`, else `fallback` (for shapes whose n is not the
  // material key's).
  float dispersionFor(double n, float fallback) const {
    for (const auto& [key, value] : material_pairs_)
      if (key == "abbe") return cauchyBFromAbbe(static_cast<float>(n), static_cast<float>(parseNumber(value, source_, key)));
    return fallback;
  }
  // `base` with the material keys the user gave applied.
  Material material(Material base) const { return applyMaterialOverrides(material_pairs_, std::move(base), source_); }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const { throw InputError(source_, key, what); }

 private:
  std::string source_;
  std::map<std::string, std::string> values_;  // shape keys, defaults filled in
  std::map<std::string, std::string> given_;
  std::vector<KeyValue> material_pairs_;
  std::map<std::string, const ParamDef*> defs_;
};

// Voxel height of the grid being voxelised (0 when only bounds are wanted).
using Builder = std::function<std::vector<ImplicitSolid>(const Params&, double voxel_height)>;

struct ShapeDef {
  std::string name;
  std::string description;
  std::vector<ParamDef> params;
  std::vector<std::string> material_keys;
  std::vector<std::string> regions;
  Builder build;
};

std::vector<std::string> allMaterialKeys() { return materialKeys(); }
std::vector<std::string> materialKeysExcept(std::initializer_list<const char*> excluded) {
  std::vector<std::string> keys;
  for (const auto& k : materialKeys())
    if (std::none_of(excluded.begin(), excluded.end(), [&](const char* e) { return k == e; })) keys.push_back(k);
  return keys;
}

double Params::number(const std::string& key) const {
  return parseNumber(values_.at(key), source_, key);
}
dvec3 Params::vec(const std::string& key) const { return parseTriple(values_.at(key), source_, key); }

Params::Params(const ShapeDef& shape, const ProceduralSpec& spec) : source_(kProceduralPrefix + spec.name) {
  for (const auto& def : shape.params) {
    defs_[def.key] = &def;
    if (!def.default_value.empty()) values_[def.key] = def.default_value;
  }
  for (const auto& [key, value] : spec.params) {
    const bool material_key =
        std::find(shape.material_keys.begin(), shape.material_keys.end(), key) != shape.material_keys.end();
    if (material_key) {
      material_pairs_.emplace_back(key, value);
      continue;
    }
    auto it = defs_.find(key);
    if (it == defs_.end()) {
      std::vector<std::string> valid;
      for (const auto& def : shape.params) valid.push_back(def.key);
      for (const auto& k : shape.material_keys) valid.push_back(k);
      const std::string what = isMaterialKey(key) ? "material key not accepted by shape '" + shape.name + "'"
                                                  : "unknown key for shape '" + shape.name + "'";
      fail(key, what + " (valid keys: " + joined(valid) + ")");
    }
    const ParamDef& def = *it->second;
    if (def.kind == Kind::Choice) {
      if (std::find(def.choices.begin(), def.choices.end(), value) == def.choices.end())
        fail(key, "'" + value + "' is not one of " + joined(def.choices));
    } else {
      auto check = [&](double v) {
        const bool below = def.lo_open ? !(v > def.lo) : !(v >= def.lo);
        const bool above = def.hi_open ? !(v < def.hi) : !(v <= def.hi);
        if (below || above) {
          std::string range;
          if (def.hi >= 1e300)
            range = std::string("must be ") + (def.lo_open ? "> " : ">= ") + fmt(def.lo);
          else
            range = std::string("must lie in ") + (def.lo_open ? "(" : "[") + fmt(def.lo) + ", " + fmt(def.hi) +
                    (def.hi_open ? ")" : "]");
          fail(key, fmt(v) + " is out of range: " + range);
        }
      };
      if (def.kind == Kind::Number) {
        check(parseNumber(value, source_, key));
      } else {
        const dvec3 v = parseTriple(value, source_, key);
        check(v.x);
        check(v.y);
        check(v.z);
      }
    }
    values_[key] = value;
    given_[key] = value;
  }
  // Validate the material keys now, so errors surface at parse time.
  (void)material(Material{});
}

// ---------------------------------------------------------------------------------------------
// The shapes.

ImplicitSolid solid(std::string name, Material m, std::function<double(const dvec3&)> sdf, const dvec3& lo,
                    const dvec3& hi) {
  ImplicitSolid s;
  s.name = std::move(name);
  s.material = std::move(m);
  s.sdf = std::move(sdf);
  s.bounds.min = lo;
  s.bounds.max = hi;
  return s;
}

// Region name: the material's name if the user gave one, else the shape's default.
std::string regionName(const Params& p, const std::string& fallback, const Material& m) {
  return p.given("name") ? m.name : fallback;
}

std::vector<ImplicitSolid> buildSphere(const Params& p, double) {
  const double r = p.number("r");
  const dvec3 c = p.vec("center");
  Material m = p.material(Material{});
  return {solid(regionName(p, "sphere", m), m, [=](const dvec3& x) { return glm::length(x - c) - r; }, c - r, c + r)};
}

std::vector<ImplicitSolid> buildBox(const Params& p, double) {
  const dvec3 half = 0.5 * p.vec("size");
  const dvec3 c = p.vec("center");
  Material m = p.material(Material{});
  return {solid(regionName(p, "box", m), m, [=](const dvec3& x) { return sdBox(x - c, half); }, c - half, c + half)};
}

std::vector<ImplicitSolid> buildRoundedCube(const Params& p, double) {
  const double size = p.number("size");
  const double radius = p.number("radius");
  if (radius > 0.5 * size) p.fail("radius", fmt(radius) + " exceeds half the size " + fmt(0.5 * size));
  const dvec3 half(0.5 * size);
  const dvec3 c = p.vec("center");
  Material m = p.material(Material{});
  return {solid(regionName(p, "rounded_cube", m), m, [=](const dvec3& x) { return sdRoundBox(x - c, half, radius); },
                c - half, c + half)};
}

std::vector<ImplicitSolid> buildLayeredCube(const Params& p, double) {
  const double size = p.number("size");
  const double radius = p.number("radius");
  if (radius > 0.5 * size) p.fail("radius", fmt(radius) + " exceeds half the size " + fmt(0.5 * size));
  const std::string axis_name = p.text("axis");
  const dvec3 c = p.vec("center");
  const dvec3 half(0.5 * size);
  const Material common = p.material(Material{});
  std::vector<ImplicitSolid> out;
  for (int layer = 0; layer < 3; ++layer) {
    const std::string id = std::to_string(layer + 1);
    Material m = common;
    m.name = "layer" + id;
    m.ior = static_cast<float>(p.number("n" + id));
    // Default colours are per unit of a size-1 cube; they scale with the cube (explicit values are
    // per world unit).
    m.sigma_a = glm::vec3(p.vec("sigma_a" + id) / (p.given("sigma_a" + id) ? 1.0 : size));
    m.dispersion_b = p.dispersionFor(m.ior, m.dispersion_b);
    std::function<double(const dvec3&)> sdf;
    if (axis_name == "radial") {
      // Concentric rounded cubes: layer1 the core (size/3), layer2 the middle shell, layer3 the outside.
      const double outer = size * (layer + 1) / 3.0, inner = size * layer / 3.0;
      const double r_out = radius * (layer + 1) / 3.0, r_in = radius * layer / 3.0;
      sdf = [=](const dvec3& x) {
        const double d_out = sdRoundBox(x - c, dvec3(0.5 * outer), r_out);
        if (layer == 0) return d_out;
        return std::max(d_out, -sdRoundBox(x - c, dvec3(0.5 * inner), r_in));
      };
    } else {
      // Three slabs of equal thickness along the axis, layer1 at the negative end.
      const int a = axis_name == "x" ? 0 : (axis_name == "y" ? 1 : 2);
      const double lo = -0.5 * size + size * layer / 3.0, hi = lo + size / 3.0;
      sdf = [=](const dvec3& x) {
        const dvec3 q = x - c;
        double d = sdRoundBox(q, half, radius);
        if (layer > 0) d = std::max(d, lo - q[a]);
        if (layer < 2) d = std::max(d, q[a] - hi);
        return d;
      };
    }
    out.push_back(solid(m.name, m, sdf, c - half, c + half));
  }
  return out;
}

std::vector<ImplicitSolid> buildWineGlass(const Params& p, double) {
  const double height = p.number("height");
  // Profile in units of the height, y from −0.5 (foot) to +0.5 (rim).
  const double rb = p.number("bowl_radius");     // outer radius of the spherical bowl
  const double wall = p.number("wall");
  const double rs = p.number("stem_radius");
  const double rf = p.number("foot_radius");
  const double tf = p.number("foot_thickness");
  const double fill = p.number("fill");
  if (2.0 * wall >= rb) p.fail("wall", fmt(wall) + " must be less than half the bowl radius " + fmt(rb));
  if (rs >= rb - wall) p.fail("stem_radius", fmt(rs) + " must be less than the inner bowl radius " + fmt(rb - wall));
  const double rim_y = 0.5;
  const double yc = rim_y - 0.55 * rb;  // bowl centre: the rim sits 0.55·R above it (a tulip-like bowl)
  const double bowl_bottom = yc - rb;
  const double foot_top = -0.5 + tf;
  if (bowl_bottom <= foot_top + 0.02)
    p.fail("bowl_radius", fmt(rb) + " leaves no room for the stem (bowl_radius < " + fmt((rim_y - foot_top - 0.02) / 1.55) + ")");
  const double cavity_bottom = yc - (rb - wall);
  const double wine_y = cavity_bottom + fill * (rim_y - cavity_bottom);
  const dvec3 c = p.vec("center");
  const double H = height;

  // Cavity (inside of the bowl sphere); the glass never enters it, the wine never leaves it.
  auto cavity = [=](const dvec3& q) { return glm::length(q - dvec3(0.0, yc, 0.0)) - (rb - wall); };
  auto glass = [=](const dvec3& x) {
    const dvec3 q = (x - c) / H;
    const double r = glm::length(q - dvec3(0.0, yc, 0.0));
    const double shell = std::max(std::abs(r - (rb - 0.5 * wall)) - 0.5 * wall, q.y - rim_y);
    const double stem_half = 0.5 * (bowl_bottom + wall - (foot_top - 0.5 * tf));
    const double stem_mid = 0.5 * (bowl_bottom + wall + (foot_top - 0.5 * tf));
    const double stem = sdRoundCylinderY(q - dvec3(0.0, stem_mid, 0.0), rs, stem_half, 0.0);
    const double foot = sdRoundCylinderY(q - dvec3(0.0, -0.5 + 0.5 * tf, 0.0), rf, 0.5 * tf, 0.45 * tf);
    const double body = std::min(shell, std::min(stem, foot));
    return H * std::max(body, -cavity(q));
  };
  auto wine = [=](const dvec3& x) {
    const dvec3 q = (x - c) / H;
    return H * std::max(cavity(q), q.y - wine_y);
  };

  Material glass_m = p.material(Material{});
  Material wine_m;
  wine_m.name = "wine";
  wine_m.ior = static_cast<float>(p.number("wine_n"));
  // Red wine passes red and absorbs green and blue (thesis Fig. 3.3b); the default is per unit of
  // a glass of height 1 and scales with the glass.
  wine_m.sigma_a = glm::vec3(p.vec("wine_sigma_a") / (p.given("wine_sigma_a") ? 1.0 : H));

  const double rmax = std::max(rb, rf) * H;
  std::vector<ImplicitSolid> out;
  out.push_back(solid(regionName(p, "glass", glass_m), glass_m, glass, c + dvec3(-rmax, -0.5 * H, -rmax),
                      c + dvec3(rmax, 0.5 * H, rmax)));
  const double rw = (rb - wall) * H;
  out.push_back(solid("wine", wine_m, wine, c + dvec3(-rw, cavity_bottom * H, -rw), c + dvec3(rw, std::max(wine_y, cavity_bottom) * H, rw)));
  return out;
}

// 2D logo in the unit square [−0.5, 0.5]²: a ring around the letter "E".
double sdLogo2(const dvec2& q) {
  const double ring = std::abs(glm::length(q) - 0.36) - 0.035;
  const double stroke = 0.035;
  double e = sdBox2(q - dvec2(-0.09, 0.0), dvec2(stroke, 0.17));      // spine
  e = std::min(e, sdBox2(q - dvec2(0.0, 0.135), dvec2(0.125, stroke)));     // top bar
  e = std::min(e, sdBox2(q - dvec2(-0.015, 0.0), dvec2(0.105, stroke)));    // middle bar
  e = std::min(e, sdBox2(q - dvec2(0.0, -0.135), dvec2(0.125, stroke)));    // bottom bar
  return std::min(ring, e);
}

std::vector<ImplicitSolid> buildLogoBlock(const Params& p, double) {
  const dvec3 size = p.vec("size");
  const double radius = p.number("radius");
  const double depth = p.number("logo_depth");
  const double min_half = 0.5 * std::min(size.x, std::min(size.y, size.z));
  if (radius > min_half) p.fail("radius", fmt(radius) + " exceeds half the smallest side " + fmt(min_half));
  if (depth >= size.z) p.fail("logo_depth", fmt(depth) + " must be less than the block's depth " + fmt(size.z));
  const double s = std::min(size.x, size.y);  // the logo fills the smaller face dimension
  const dvec3 c = p.vec("center");
  const dvec3 half = 0.5 * size;

  auto logo = [=](const dvec3& x) {
    const dvec3 q = x - c;
    return combine2(s * sdLogo2(dvec2(q.x, q.y) / s), std::abs(q.z) - 0.5 * depth);  // extruded along z
  };
  auto block = [=](const dvec3& x) { return std::max(sdRoundBox(x - c, half, radius), -logo(x)); };

  Material block_m = p.material(Material{});
  Material logo_m;
  logo_m.name = "logo";
  logo_m.ior = static_cast<float>(p.number("logo_n"));
  logo_m.sigma_a = glm::vec3(p.vec("logo_sigma_a"));
  if (p.given("logo_albedo")) {
    const dvec3 a = p.vec("logo_albedo");
    if (a.x > 1.0 || a.y > 1.0 || a.z > 1.0) p.fail("logo_albedo", "'" + p.text("logo_albedo") + "' must lie in [0, 1]");
    logo_m.albedo = glm::vec3(a);
    logo_m.opaque = true;
    logo_m.ior = block_m.ior;  // an opaque embedding does not refract: no index step around it
    logo_m.sigma_a = glm::vec3(0.0f);
  }
  const double lr = 0.395 * s;
  std::vector<ImplicitSolid> out;
  out.push_back(solid(regionName(p, "block", block_m), block_m, block, c - half, c + half));
  out.push_back(solid("logo", logo_m, logo, c - dvec3(lr, lr, 0.5 * depth), c + dvec3(lr, lr, 0.5 * depth)));
  return out;
}

std::vector<ImplicitSolid> buildLuneburg(const Params& p, double) {
  const double R = p.number("r");
  const dvec3 c = p.vec("center");
  Material m = p.material(Material{});
  m.ior = static_cast<float>(std::sqrt(2.0));  // the centre value; the region carries n per voxel
  m.dispersion_b = p.dispersionFor(m.ior, m.dispersion_b);
  ImplicitSolid s = solid(regionName(p, "luneburg", m), m, [=](const dvec3& x) { return glm::length(x - c) - R; },
                          c - R, c + R);
  // Luneburg lens: n(r) = sqrt(2 − (r/R)²) (DESIGN §6).
  s.ior = [=](const dvec3& x) {
    const double t = glm::dot(x - c, x - c) / (R * R);
    return std::sqrt(2.0 - std::min(t, 1.0));
  };
  return {s};
}

std::vector<ImplicitSolid> buildGradientSlab(const Params& p, double) {
  const dvec3 half = 0.5 * p.vec("size");
  const dvec3 c = p.vec("center");
  const std::string axis_name = p.text("axis");
  const int a = axis_name == "x" ? 0 : (axis_name == "y" ? 1 : 2);
  const double n0 = p.number("n0"), n1 = p.number("n1");
  Material m = p.material(Material{});
  m.ior = static_cast<float>(0.5 * (n0 + n1));  // the mean; the region carries n per voxel
  m.dispersion_b = p.dispersionFor(m.ior, m.dispersion_b);
  ImplicitSolid s = solid(regionName(p, "gradient_slab", m), m, [=](const dvec3& x) { return sdBox(x - c, half); },
                          c - half, c + half);
  // n rises linearly from n0 at the slab's −axis face to n1 at its +axis face.
  s.ior = [=](const dvec3& x) {
    const double t = std::clamp((x[a] - c[a] + half[a]) / (2.0 * half[a]), 0.0, 1.0);
    return n0 + (n1 - n0) * t;
  };
  return {s};
}

std::vector<ImplicitSolid> buildFloor(const Params& p, double voxel_height) {
  const double y = p.number("y");
  const double size = p.number("size");
  double thickness = p.number("thickness");
  if (thickness == 0.0) thickness = voxel_height;  // one voxel of the grid
  Material m;
  m.name = "floor";
  m.ior = 1.0f;  // an opaque receiver does not refract
  m.opaque = true;
  m.albedo = glm::vec3(0.8f);
  m = p.material(m);
  m.opaque = true;
  const double hs = 0.5 * size;
  const dvec3 centre(0.0, y - 0.5 * thickness, 0.0);
  const dvec3 half(hs, 0.5 * thickness, hs);
  ImplicitSolid s = solid(regionName(p, "floor", m), m, [=](const dvec3& x) { return sdBox(x - centre, half); },
                          dvec3(-hs, y - thickness, -hs), dvec3(hs, y, hs));
  s.open_surface = true;
  return {s};
}

const std::vector<ShapeDef>& shapeDefs() {
  static const std::vector<ShapeDef> defs = [] {
    std::vector<ShapeDef> d;
    d.push_back({"sphere", "glass sphere (thesis Fig. 5.1, 7.4a)",
                 {positive("r", "0.5", "radius"), centerParam()}, allMaterialKeys(), {"sphere"}, buildSphere});
    d.push_back({"box", "rectangular glass box",
                 {triple("size", "1:1:1", 0.0, true, "side lengths X:Y:Z (one value: a cube)"), centerParam()},
                 allMaterialKeys(), {"box"}, buildBox});
    d.push_back({"rounded_cube", "cube with rounded edges and corners",
                 {positive("size", "1", "side length"), num("radius", "0.1", 0.0, 1e300, false, "edge radius (<= size/2)"),
                  centerParam()},
                 allMaterialKeys(), {"rounded_cube"}, buildRoundedCube});
    d.push_back({"layered_cube",
                 "rounded cube of three glasses with different n and colours (thesis Fig. 1.2, 7.3a)",
                 {positive("size", "1", "side length"), num("radius", "0.15", 0.0, 1e300, false, "edge radius (<= size/2)"),
                  choice("axis", "y", {"x", "y", "z", "radial"},
                         "layers stacked along x, y or z (layer1 at the negative end), or radial: nested shells "
                         "(layer1 the core)"),
                  ior("n1", "1.45", "refractive index of layer1"), ior("n2", "1.55", "refractive index of layer2"),
                  ior("n3", "1.65", "refractive index of layer3"),
                  triple("sigma_a1", "3:1.2:0.15", 0.0, false, "σa of layer1 (blue glass; default ÷ size)"),
                  triple("sigma_a2", "0.6:0.05:0.6", 0.0, false, "σa of layer2 (green tint; default ÷ size)"),
                  triple("sigma_a3", "0.1:0.9:3", 0.0, false, "σa of layer3 (amber; default ÷ size)"),
                  centerParam()},
                 materialKeysExcept({"ior", "n", "sigma_a", "albedo", "name"}), {"layer1", "layer2", "layer3"}, buildLayeredCube});
    d.push_back({"wine_glass",
                 "lathe-profile wine glass (foot, stem, spherical bowl) with red wine in the lower bowl "
                 "(thesis Fig. 3.1, 3.3b, 7.4b); lengths other than height are fractions of height",
                 {positive("height", "1", "total height (foot at -height/2, rim at +height/2)"),
                  positive("bowl_radius", "0.26", "outer radius of the spherical bowl (x height)"),
                  positive("wall", "0.025", "bowl wall thickness (x height)"),
                  positive("stem_radius", "0.022", "stem radius (x height)"),
                  positive("foot_radius", "0.22", "foot radius (x height)"),
                  positive("foot_thickness", "0.025", "foot thickness (x height)"),
                  num("fill", "0.45", 0.0, 1.0, false, "wine level: fraction of the bowl's inner depth"),
                  ior("wine_n", "1.34", "refractive index of the wine"),
                  triple("wine_sigma_a", "0.5:8:6", 0.0, false,
                         "σa of the wine: passes red (default ÷ height; an explicit value is per world unit)"),
                  centerParam()},
                 materialKeysExcept({"albedo"}), {"glass", "wine"}, buildWineGlass});
    d.push_back({"logo_block",
                 "glass block with an embedded logo (a ring around the letter E, extruded along z) "
                 "(thesis Fig. 1.1, 7.2a)",
                 {triple("size", "1:1:0.5", 0.0, true, "block side lengths X:Y:Z"),
                  num("radius", "0.03", 0.0, 1e300, false, "edge radius"),
                  positive("logo_depth", "0.2", "extrusion depth of the logo along z"),
                  ior("logo_n", "1.6", "refractive index of the logo glass"),
                  triple("logo_sigma_a", "8:8:2", 0.0, false, "σa of the logo glass (dark blue)"),
                  triple("logo_albedo", "", 0.0, false, "if given, the logo is opaque with this albedo instead"),
                  centerParam()},
                 materialKeysExcept({"albedo"}), {"block", "logo"}, buildLogoBlock});
    d.push_back({"luneburg", "Luneburg lens, n(r) = sqrt(2 - (r/R)^2) inside radius R; per-voxel n",
                 {positive("r", "0.5", "radius R"), centerParam()}, materialKeysExcept({"ior", "n", "albedo"}), {"luneburg"},
                 buildLuneburg});
    d.push_back({"gradient_slab", "slab whose n varies linearly along an axis from n0 to n1; per-voxel n",
                 {triple("size", "1:1:0.25", 0.0, true, "side lengths X:Y:Z"),
                  choice("axis", "x", {"x", "y", "z"}, "axis along which n varies"),
                  ior("n0", "1.3", "n at the slab's -axis face"), ior("n1", "1.7", "n at the slab's +axis face"),
                  centerParam()},
                 materialKeysExcept({"ior", "n", "albedo"}), {"gradient_slab"}, buildGradientSlab});
    d.push_back({"floor", "thin opaque receiver plane (x-z square) whose top face is at height y",
                 {num("y", "-0.5", -1e300, 1e300, false, "height of the top face"),
                  positive("size", "2", "side length of the square"),
                  num("thickness", "0", 0.0, 1e300, false, "thickness below y (0: one voxel of the grid)")},
                 {"albedo", "name"}, {"floor"}, buildFloor});
    return d;
  }();
  return defs;
}

const ShapeDef& findShape(const std::string& name, const std::string& source) {
  for (const auto& def : shapeDefs())
    if (def.name == name) return def;
  std::vector<std::string> names;
  for (const auto& def : shapeDefs()) names.push_back(def.name);
  throw InputError(source, "", "unknown shape '" + name + "' (valid shapes: " + joined(names) + ")");
}

std::vector<ImplicitSolid> buildSolids(const ProceduralSpec& spec, double voxel_height) {
  const ShapeDef& shape = findShape(spec.name, kProceduralPrefix + spec.name);
  const Params params(shape, spec);
  return shape.build(params, voxel_height);
}

}  // namespace

std::string ProceduralSpec::text() const {
  std::string out = kProceduralPrefix + name;
  for (const auto& [key, value] : params) out += "," + key + "=" + value;
  return out;
}

const std::vector<ProceduralShapeInfo>& proceduralShapes() {
  static const std::vector<ProceduralShapeInfo> infos = [] {
    std::vector<ProceduralShapeInfo> out;
    for (const auto& def : shapeDefs()) {
      ProceduralShapeInfo info;
      info.name = def.name;
      info.description = def.description;
      for (const auto& p : def.params)
        info.params.push_back({p.key, p.default_value.empty() ? "(unset)" : p.default_value,
                               p.meaning + (p.kind == Kind::Choice ? " [" + joined(p.choices) + "]" : "")});
      info.material_keys = def.material_keys;
      info.regions = def.regions;
      out.push_back(std::move(info));
    }
    return out;
  }();
  return infos;
}

bool isProceduralSpec(const std::string& input) { return input.rfind(kProceduralPrefix, 0) == 0; }

ProceduralSpec parseProceduralSpec(const std::string& text) {
  std::string body = isProceduralSpec(text) ? text.substr(std::string(kProceduralPrefix).size()) : text;
  ProceduralSpec spec;
  const std::size_t comma = body.find(',');
  spec.name = body.substr(0, comma);
  while (!spec.name.empty() && spec.name.back() == ' ') spec.name.pop_back();
  if (spec.name.empty()) {
    std::vector<std::string> names;
    for (const auto& def : shapeDefs()) names.push_back(def.name);
    throw InputError(text.empty() ? std::string(kProceduralPrefix) : text, "",
                     "missing shape name (valid shapes: " + joined(names) + ")");
  }
  const ShapeDef& shape = findShape(spec.name, kProceduralPrefix + spec.name);
  if (comma != std::string::npos)
    for (auto& [key, value] : splitKeyValues(body.substr(comma + 1), kProceduralPrefix + spec.name))
      spec.params[key] = value;
  const Params validate(shape, spec);  // throws on unknown keys and bad values
  (void)shape.build(validate, 0.0);    // and on inconsistent combinations (e.g. radius > size/2)
  return spec;
}

Bounds proceduralBounds(const ProceduralSpec& spec) {
  Bounds b;
  for (const auto& s : buildSolids(spec, 0.0)) b.extend(s.bounds);
  return b;
}

std::vector<ImplicitSolid> proceduralSolids(const ProceduralSpec& spec, const GridSpec& grid) {
  return buildSolids(spec, grid.voxelSize().y);
}

std::vector<Region> voxelizeProcedural(const ProceduralSpec& spec, const GridSpec& grid,
                                       const ProceduralOptions& options, const ProgressFn& progress) {
  const auto solids = proceduralSolids(spec, grid);
  std::vector<Region> regions;
  regions.reserve(solids.size());
  const double n = static_cast<double>(solids.size());
  for (std::size_t i = 0; i < solids.size(); ++i) {
    ProgressFn part;
    if (progress) part = [&progress, i, n](double f) { progress((static_cast<double>(i) + f) / n); };
    regions.push_back(voxelizeImplicit(solids[i], grid, options, part));
  }
  return regions;
}

Region voxelizeImplicit(const ImplicitSolid& solid, const GridSpec& grid, const ProceduralOptions& options,
                        const ProgressFn& progress) {
  const int supersample = options.supersample;
  if (supersample < 1 || supersample > 16)
    throw std::invalid_argument("voxelizeImplicit: supersample must lie in [1, 16], got " + std::to_string(supersample));
  if (!solid.sdf) throw std::invalid_argument("voxelizeImplicit: solid '" + solid.name + "' has no distance function");
  Region region;
  region.name = solid.name;
  region.material = solid.material;
  region.coverage.assign(grid.count(), 0.0f);
  if (solid.ior) region.ior.assign(grid.count(), solid.material.ior);
  if (grid.count() == 0 || solid.bounds.empty()) {
    if (progress) progress(1.0);
    return region;
  }

  const dvec3 h = grid.voxelSize();
  const double half_diagonal = 0.5 * glm::length(h);
  // Voxels that can touch the solid's bounds (one voxel of margin against rounding).
  glm::ivec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::clamp(static_cast<int>(std::floor((solid.bounds.min[a] - grid.bounds_min[a]) / h[a])) - 1, 0, grid.dims[a]);
    hi[a] = std::clamp(static_cast<int>(std::ceil((solid.bounds.max[a] - grid.bounds_min[a]) / h[a])) + 1, 0, grid.dims[a]);
  }
  const int S = supersample;
  std::vector<double> offset_x(S), offset_y(S), offset_z(S);
  for (int s = 0; s < S; ++s) {
    const double t = (s + 0.5) / S - 0.5;
    offset_x[s] = t * h.x;
    offset_y[s] = t * h.y;
    offset_z[s] = t * h.z;
  }
  const float inv_samples = 1.0f / static_cast<float>(S * S * S);
  const bool antialias = options.antialias;
  const double sub_width = std::min(h.x, std::min(h.y, h.z)) / S;
  const auto& sdf = solid.sdf;
  const auto& ior = solid.ior;
  std::atomic<std::int64_t> slices_done{0};
  const double slices = std::max(1, hi.z - lo.z);

  parallelFor(lo.z, hi.z, [&](std::int64_t zz) {
    const int k = static_cast<int>(zz);
    for (int j = lo.y; j < hi.y; ++j) {
      for (int i = lo.x; i < hi.x; ++i) {
        const dvec3 c = grid.center(i, j, k);
        const double d = sdf(c);
        if (d >= half_diagonal) {
          // Wholly outside; by the Lipschitz bound so are the next voxels along x while
          // d − m·h.x ≥ half_diagonal.
          i += static_cast<int>(std::min((d - half_diagonal) / h.x, static_cast<double>(hi.x)));
          continue;
        }
        const std::size_t at = grid.index(i, j, k);
        if (d <= -half_diagonal) {
          // Wholly inside, and so are the next voxels along x while −d − m·h.x ≥ half_diagonal.
          const int run = std::min(static_cast<int>((-d - half_diagonal) / h.x), hi.x - 1 - i);
          for (int m = 0; m <= run; ++m) {
            region.coverage[at + static_cast<std::size_t>(m)] = 1.0f;
            if (ior) region.ior[at + static_cast<std::size_t>(m)] = static_cast<float>(ior(grid.center(i + m, j, k)));
          }
          i += run;
          continue;
        }
        double inside = 0.0;
        double n_sum = 0.0;
        for (int sz = 0; sz < S; ++sz)
          for (int sy = 0; sy < S; ++sy)
            for (int sx = 0; sx < S; ++sx) {
              const dvec3 p = c + dvec3(offset_x[sx], offset_y[sy], offset_z[sz]);
              const double ds = sdf(p);
              const double weight = antialias ? std::clamp(0.5 - ds / sub_width, 0.0, 1.0) : (ds < 0.0 ? 1.0 : 0.0);
              if (weight > 0.0) {
                inside += weight;
                if (ior) n_sum += weight * ior(p);
              }
            }
        region.coverage[at] = static_cast<float>(inside) * inv_samples;
        if (ior && inside > 0.0) region.ior[at] = static_cast<float>(n_sum / inside);
      }
    }
    if (progress) progress(static_cast<double>(++slices_done) / slices);
  });

  if (!solid.open_surface) {
    double sum = 0.0;  // serial, so the result does not depend on the thread count
    for (float c : region.coverage) sum += c;
    region.enclosed_volume = sum * grid.voxelVolume();
  }
  return region;
}

}  // namespace eik
