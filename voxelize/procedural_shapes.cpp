#include "voxelize/procedural_shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <utility>

#include "core/error.h"
#include "core/scene.h"
#include "voxelize/distance_functions.h"

namespace eik {
namespace {

using glm::dvec2;
using glm::dvec3;

std::vector<std::string> allMaterialKeys() { return materialKeys(); }
std::vector<std::string> materialKeysExcept(std::initializer_list<const char*> excluded) {
  std::vector<std::string> keys;
  for (const auto& k : materialKeys())
    if (std::none_of(excluded.begin(), excluded.end(), [&](const char* e) { return k == e; })) keys.push_back(k);
  return keys;
}

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
std::string regionName(const ShapeParams& p, const std::string& fallback, const Material& m) {
  return p.given("name") ? m.name : fallback;
}

// The keys every shape but the floor takes after its own: a scale (one number, or X:Y:Z along the
// shape's axes) and a turn about the shape's centre, as a scene places a volume
// (docs/scene-format.md: X, then Y, then Z).
std::vector<ParamDef> placed(std::vector<ParamDef> params) {
  params.push_back(tripleParam("scale", "1", 0.0, true,
                               "scale about the centre, one number or X:Y:Z along the shape's axes (σa stays per "
                               "world unit, as a scene's scale)"));
  params.push_back(tripleParam("euler_deg", "0:0:0", -1e300, false,
                               "turn about the centre: degrees about X, then Y, then Z (a scene's rotate_deg)"));
  return params;
}

// The solids scaled by S = diag(s) and turned by R about c: x = c + R·S·(x_shape − c). A signed
// distance keeps under a turn and scales by s under a uniform scale; under an uneven one it is no
// distance any more, and × min(s) keeps its zero set (the surface) exact and every value a lower
// bound of the distance (as lightsim/scene_bake.h volumeAtWorldScale does to a volume's). The
// bounds are those of the turned box's corners.
void place(std::vector<ImplicitSolid>& solids, const dvec3& c, const dvec3& scale, const dvec3& euler_deg) {
  if (scale == dvec3(1.0) && euler_deg == dvec3(0.0)) return;
  const double s = std::min(scale.x, std::min(scale.y, scale.z));
  SceneObjectSpec placement;
  placement.rotate_deg = euler_deg;
  placement.scale = scale;
  const glm::dmat3 to_world(objectToWorld(placement));
  const glm::dmat3 to_shape = glm::inverse(to_world);
  for (ImplicitSolid& solid : solids) {
    const auto back = [=](const dvec3& x) { return c + to_shape * (x - c); };
    solid.sdf = [sdf = std::move(solid.sdf), back, s](const dvec3& x) { return s * sdf(back(x)); };
    if (solid.ior) solid.ior = [ior = std::move(solid.ior), back](const dvec3& x) { return ior(back(x)); };
    Bounds turned;
    for (int k = 0; k < 8; ++k) {
      const dvec3 corner((k & 1) ? solid.bounds.max.x : solid.bounds.min.x, (k & 2) ? solid.bounds.max.y : solid.bounds.min.y,
                         (k & 4) ? solid.bounds.max.z : solid.bounds.min.z);
      turned.extend(c + to_world * (corner - c));
    }
    solid.bounds = turned;
  }
}

std::vector<ImplicitSolid> buildSphere(const ShapeParams& p, double) {
  const double r = p.number("r");
  const dvec3 c = p.vec("center");
  Material m = p.material(Material{});
  return {solid(regionName(p, "sphere", m), m, [=](const dvec3& x) { return glm::length(x - c) - r; }, c - r, c + r)};
}

// An upright prism over an equilateral triangle of side `side` in the xz plane (one corner towards
// −z, turned by `rotate_deg` about +y), `height` tall along y. The distance is the largest of the
// three faces' and the caps' plane distances: exact inside and on the faces, a bound outside.
std::vector<ImplicitSolid> buildPrism(const ShapeParams& p, double) {
  const double side = p.number("side"), height = p.number("height");
  const double turn = glm::radians(p.number("rotate_deg"));
  const dvec3 c = p.vec("center");
  const double inradius = side / (2.0 * std::sqrt(3.0));
  // Outward normals of the three side faces in the xz plane: the corner towards −z means the face
  // opposite it faces +z.
  std::array<dvec2, 3> normals;
  for (int k = 0; k < 3; ++k) {
    const double a = turn + k * 2.0 * 3.14159265358979323846 / 3.0;
    normals[static_cast<std::size_t>(k)] = dvec2(std::sin(a), std::cos(a));
  }
  Material m = p.material(Material{});
  const double r = 2.0 * inradius;  // circumradius
  return {solid(regionName(p, "prism", m), m,
                [=](const dvec3& x) {
                  const dvec2 q(x.x - c.x, x.z - c.z);
                  double d = std::abs(x.y - c.y) - 0.5 * height;
                  for (const dvec2& n : normals) d = std::max(d, glm::dot(q, n) - inradius);
                  return d;
                },
                c - dvec3(r, 0.5 * height, r), c + dvec3(r, 0.5 * height, r))};
}

std::vector<ImplicitSolid> buildBox(const ShapeParams& p, double) {
  const dvec3 half = 0.5 * p.vec("size");
  const dvec3 c = p.vec("center");
  Material m = p.material(Material{});
  return {solid(regionName(p, "box", m), m, [=](const dvec3& x) { return sdBox(x - c, half); }, c - half, c + half)};
}

std::vector<ImplicitSolid> buildRoundedCube(const ShapeParams& p, double) {
  const double size = p.number("size");
  const double radius = p.number("radius");
  if (radius > 0.5 * size) p.fail("radius", formatValue(radius) + " exceeds half the size " + formatValue(0.5 * size));
  const dvec3 half(0.5 * size);
  const dvec3 c = p.vec("center");
  Material m = p.material(Material{});
  return {solid(regionName(p, "rounded_cube", m), m, [=](const dvec3& x) { return sdRoundBox(x - c, half, radius); },
                c - half, c + half)};
}

std::vector<ImplicitSolid> buildLayeredCube(const ShapeParams& p, double) {
  const double size = p.number("size");
  const double radius = p.number("radius");
  if (radius > 0.5 * size) p.fail("radius", formatValue(radius) + " exceeds half the size " + formatValue(0.5 * size));
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

std::vector<ImplicitSolid> buildWineGlass(const ShapeParams& p, double) {
  const double height = p.number("height");
  // Profile in units of the height, y from −0.5 (foot) to +0.5 (rim).
  const double rb = p.number("bowl_radius");     // outer radius of the spherical bowl
  const double wall = p.number("wall");
  const double rs = p.number("stem_radius");
  const double rf = p.number("foot_radius");
  const double tf = p.number("foot_thickness");
  const double fill = p.number("fill");
  if (2.0 * wall >= rb) p.fail("wall", formatValue(wall) + " must be less than half the bowl radius " + formatValue(rb));
  if (rs >= rb - wall) p.fail("stem_radius", formatValue(rs) + " must be less than the inner bowl radius " + formatValue(rb - wall));
  const double rim_y = 0.5;
  const double yc = rim_y - 0.55 * rb;  // bowl centre: the rim sits 0.55·R above it (a tulip-like bowl)
  const double bowl_bottom = yc - rb;
  const double foot_top = -0.5 + tf;
  if (bowl_bottom <= foot_top + 0.02)
    p.fail("bowl_radius", formatValue(rb) + " leaves no room for the stem (bowl_radius < " + formatValue((rim_y - foot_top - 0.02) / 1.55) + ")");
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

std::vector<ImplicitSolid> buildLogoBlock(const ShapeParams& p, double) {
  const dvec3 size = p.vec("size");
  const double radius = p.number("radius");
  const double depth = p.number("logo_depth");
  const double min_half = 0.5 * std::min(size.x, std::min(size.y, size.z));
  if (radius > min_half) p.fail("radius", formatValue(radius) + " exceeds half the smallest side " + formatValue(min_half));
  if (depth >= size.z) p.fail("logo_depth", formatValue(depth) + " must be less than the block's depth " + formatValue(size.z));
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

std::vector<ImplicitSolid> buildLuneburg(const ShapeParams& p, double) {
  const double R = p.number("r");
  const dvec3 c = p.vec("center");
  Material m = p.material(Material{});
  m.ior = static_cast<float>(std::sqrt(2.0));  // the centre value; the region carries n per voxel
  m.dispersion_b = p.dispersionFor(m.ior, m.dispersion_b);
  ImplicitSolid s = solid(regionName(p, "luneburg", m), m, [=](const dvec3& x) { return glm::length(x - c) - R; },
                          c - R, c + R);
  // Luneburg lens: n(r) = sqrt(2 − (r/R)²) (docs/testing.md).
  s.ior = [=](const dvec3& x) {
    const double t = glm::dot(x - c, x - c) / (R * R);
    return std::sqrt(2.0 - std::min(t, 1.0));
  };
  return {s};
}

std::vector<ImplicitSolid> buildGradientSlab(const ShapeParams& p, double) {
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
    // Not clamped: with sharp interfaces n is continued over the band around the slab.
    const double t = (x[a] - c[a] + half[a]) / (2.0 * half[a]);
    return n0 + (n1 - n0) * t;
  };
  return {s};
}

std::vector<ImplicitSolid> buildFloor(const ShapeParams& p, double voxel_height) {
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

}  // namespace

const std::vector<ShapeDef>& shapeDefs() {
  static const std::vector<ShapeDef> defs = [] {
    std::vector<ShapeDef> d;
    d.push_back({"sphere", "glass sphere (thesis Fig. 5.1, 7.4a)",
                 {positiveParam("r", "0.5", "radius"), centerParam()}, allMaterialKeys(), {"sphere"}, buildSphere});
    d.push_back({"box", "rectangular glass box",
                 {tripleParam("size", "1:1:1", 0.0, true, "side lengths X:Y:Z (one value: a cube)"), centerParam()},
                 allMaterialKeys(), {"box"}, buildBox});
    d.push_back({"prism", "upright prism over an equilateral triangle (thesis Fig. 3.5b)",
                 {positiveParam("side", "0.7", "side of the triangle"), positiveParam("height", "1", "height along y"),
                  numberParam("rotate_deg", "0", -360.0, 360.0, false, "turn about +y (0: a corner towards -z)"),
                  centerParam()},
                 allMaterialKeys(), {"prism"}, buildPrism});
    d.push_back({"rounded_cube", "cube with rounded edges and corners",
                 {positiveParam("size", "1", "side length"), numberParam("radius", "0.1", 0.0, 1e300, false, "edge radius (<= size/2)"),
                  centerParam()},
                 allMaterialKeys(), {"rounded_cube"}, buildRoundedCube});
    d.push_back({"layered_cube",
                 "rounded cube of three glasses with different n and colours (thesis Fig. 1.2, 7.3a)",
                 {positiveParam("size", "1", "side length"), numberParam("radius", "0.15", 0.0, 1e300, false, "edge radius (<= size/2)"),
                  choiceParam("axis", "y", {"x", "y", "z", "radial"},
                         "layers stacked along x, y or z (layer1 at the negative end), or radial: nested shells "
                         "(layer1 the core)"),
                  iorParam("n1", "1.45", "refractive index of layer1"), iorParam("n2", "1.55", "refractive index of layer2"),
                  iorParam("n3", "1.65", "refractive index of layer3"),
                  tripleParam("sigma_a1", "3:1.2:0.15", 0.0, false, "σa of layer1 (blue glass; default ÷ size)"),
                  tripleParam("sigma_a2", "0.6:0.05:0.6", 0.0, false, "σa of layer2 (green tint; default ÷ size)"),
                  tripleParam("sigma_a3", "0.1:0.9:3", 0.0, false, "σa of layer3 (amber; default ÷ size)"),
                  centerParam()},
                 materialKeysExcept({"ior", "n", "sigma_a", "albedo", "name"}), {"layer1", "layer2", "layer3"}, buildLayeredCube});
    d.push_back({"wine_glass",
                 "lathe-profile wine glass (foot, stem, spherical bowl) with red wine in the lower bowl "
                 "(thesis Fig. 3.1, 3.3b, 7.4b); lengths other than height are fractions of height",
                 {positiveParam("height", "1", "total height (foot at -height/2, rim at +height/2)"),
                  positiveParam("bowl_radius", "0.26", "outer radius of the spherical bowl (x height)"),
                  positiveParam("wall", "0.025", "bowl wall thickness (x height)"),
                  positiveParam("stem_radius", "0.022", "stem radius (x height)"),
                  positiveParam("foot_radius", "0.22", "foot radius (x height)"),
                  positiveParam("foot_thickness", "0.025", "foot thickness (x height)"),
                  numberParam("fill", "0.45", 0.0, 1.0, false, "wine level: fraction of the bowl's inner depth"),
                  iorParam("wine_n", "1.34", "refractive index of the wine"),
                  tripleParam("wine_sigma_a", "0.5:8:6", 0.0, false,
                         "σa of the wine: passes red (default ÷ height; an explicit value is per world unit)"),
                  centerParam()},
                 materialKeysExcept({"albedo"}), {"glass", "wine"}, buildWineGlass});
    d.push_back({"logo_block",
                 "glass block with an embedded logo (a ring around the letter E, extruded along z) "
                 "(thesis Fig. 1.1, 7.2a)",
                 {tripleParam("size", "1:1:0.5", 0.0, true, "block side lengths X:Y:Z"),
                  numberParam("radius", "0.03", 0.0, 1e300, false, "edge radius"),
                  positiveParam("logo_depth", "0.2", "extrusion depth of the logo along z"),
                  iorParam("logo_n", "1.6", "refractive index of the logo glass"),
                  tripleParam("logo_sigma_a", "8:8:2", 0.0, false, "σa of the logo glass (dark blue)"),
                  tripleParam("logo_albedo", "", 0.0, false, "if given, the logo is opaque with this albedo instead"),
                  centerParam()},
                 materialKeysExcept({"albedo"}), {"block", "logo"}, buildLogoBlock});
    d.push_back({"luneburg", "Luneburg lens, n(r) = sqrt(2 - (r/R)^2) inside radius R; per-voxel n",
                 {positiveParam("r", "0.5", "radius R"), centerParam()}, materialKeysExcept({"ior", "n", "albedo"}), {"luneburg"},
                 buildLuneburg});
    d.push_back({"gradient_slab", "slab whose n varies linearly along an axis from n0 to n1; per-voxel n",
                 {tripleParam("size", "1:1:0.25", 0.0, true, "side lengths X:Y:Z"),
                  choiceParam("axis", "x", {"x", "y", "z"}, "axis along which n varies"),
                  iorParam("n0", "1.3", "n at the slab's -axis face"), iorParam("n1", "1.7", "n at the slab's +axis face"),
                  centerParam()},
                 materialKeysExcept({"ior", "n", "albedo"}), {"gradient_slab"}, buildGradientSlab});
    d.push_back({"floor", "thin opaque receiver plane (x-z square) whose top face is at height y",
                 {numberParam("y", "-0.5", -1e300, 1e300, false, "height of the top face"),
                  positiveParam("size", "2", "side length of the square"),
                  numberParam("thickness", "0", 0.0, 1e300, false, "thickness below y (0: one voxel of the grid)")},
                 {"albedo", "name"}, {"floor"}, buildFloor});
    for (ShapeDef& def : d)
      if (def.name != "floor") def.params = placed(std::move(def.params));
    return d;
  }();
  return defs;
}

const ShapeDef& findShape(const std::string& name, const std::string& source) {
  for (const auto& def : shapeDefs())
    if (def.name == name) return def;
  throw InputError(source, "", "unknown shape '" + name + "' (valid shapes: " + shapeNames() + ")");
}

std::string shapeNames() {
  std::vector<std::string> names;
  for (const auto& def : shapeDefs()) names.push_back(def.name);
  return joinedList(names);
}

std::vector<ImplicitSolid> buildShapeSolids(const ProceduralSpec& spec, double voxel_height) {
  const ShapeDef& shape = findShape(spec.name, kProceduralPrefix + spec.name);
  const ShapeParams params(shape.name, shape.params, shape.material_keys, spec);
  std::vector<ImplicitSolid> solids = shape.build(params, voxel_height);
  if (params.has("scale")) place(solids, params.vec("center"), params.vec("scale"), params.vec("euler_deg"));
  return solids;
}

}  // namespace eik
