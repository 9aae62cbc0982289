// The public entry of the procedural shapes: parsing and validating specs, bounds, the regions of
// a spec. The shapes themselves are tested in procedural_shapes_test.cpp, the voxeliser in
// implicit_voxelizer_test.cpp.
#include "voxelize/procedural.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "core/testing.h"
#include "voxelize/test_meshes.h"

namespace eik {
namespace {

// The InputError message of parsing `spec` ("" and a test failure if it parses).
std::string specErrorOf(const std::string& spec) {
  return test_support::inputErrorOf([&] { parseProceduralSpec(spec); });
}

// n³ voxels on [−half, half]³.
GridSpec centredGrid(int n, double half) { return cubeGrid(glm::dvec3(0.0), 2.0 * half, n); }

TEST(ProceduralSpec, Parses) {
  const ProceduralSpec s = parseProceduralSpec("procedural:sphere,r=0.25,sigma_a=1:2:3");
  EXPECT_EQ(s.name, "sphere");
  EXPECT_EQ(s.params.at("r"), "0.25");
  EXPECT_EQ(s.params.at("sigma_a"), "1:2:3");
  EXPECT_EQ(parseProceduralSpec("wine_glass").name, "wine_glass");  // the prefix is optional
  EXPECT_TRUE(isProceduralSpec("procedural:box"));
  EXPECT_FALSE(isProceduralSpec("box.obj"));
  EXPECT_EQ(s.text(), "procedural:sphere,r=0.25,sigma_a=1:2:3");
}

TEST(ProceduralSpec, Errors) {
  std::string e = specErrorOf("procedural:teapot");
  EXPECT_NE(e.find("procedural:teapot: unknown shape 'teapot'"), std::string::npos) << e;
  EXPECT_NE(e.find("wine_glass"), std::string::npos) << "lists the shapes: " << e;

  e = specErrorOf("procedural:sphere,radius=1");
  EXPECT_NE(e.find("procedural:sphere: radius: unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("valid keys: r, center, scale, euler_deg, ior"), std::string::npos) << e;

  e = specErrorOf("procedural:sphere,r=big");
  EXPECT_NE(e.find("r: 'big' is not a number"), std::string::npos) << e;
  e = specErrorOf("procedural:sphere,r=-1");
  EXPECT_NE(e.find("r: -1 is out of range: must be > 0"), std::string::npos) << e;
  e = specErrorOf("procedural:wine_glass,fill=1.5");
  EXPECT_NE(e.find("fill: 1.5 is out of range: must lie in [0, 1]"), std::string::npos) << e;
  e = specErrorOf("procedural:gradient_slab,axis=w");
  EXPECT_NE(e.find("axis: 'w' is not one of x, y, z"), std::string::npos) << e;
  e = specErrorOf("procedural:luneburg,n=1.5");
  EXPECT_NE(e.find("procedural:luneburg: n: material key not accepted"), std::string::npos) << e;
  e = specErrorOf("procedural:sphere,g=2");
  EXPECT_NE(e.find("g: 2 is outside (-1, 1)"), std::string::npos) << "material keys are validated too: " << e;
  e = specErrorOf("procedural:rounded_cube,size=1,radius=0.7");
  EXPECT_NE(e.find("radius: 0.7 exceeds half the size"), std::string::npos) << e;
  e = specErrorOf("procedural:box,size=1:2");
  EXPECT_NE(e.find("size:"), std::string::npos) << e;
  e = specErrorOf("procedural:sphere,r");
  EXPECT_NE(e.find("KEY=VALUE"), std::string::npos) << e;
  e = specErrorOf("procedural:");
  EXPECT_NE(e.find("missing shape name"), std::string::npos) << e;
  EXPECT_THROW(proceduralBounds(ProceduralSpec{"sphere", {{"r", "0"}}}), InputError);
}

TEST(ProceduralSpec, EveryShapeIsDocumented) {
  ASSERT_GE(proceduralShapes().size(), 9u);
  for (const auto& shape : proceduralShapes()) {
    EXPECT_FALSE(shape.description.empty()) << shape.name;
    EXPECT_FALSE(shape.regions.empty()) << shape.name;
    for (const auto& p : shape.params) EXPECT_FALSE(p.meaning.empty()) << shape.name << " " << p.key;
  }
}

TEST(ProceduralSpec, BoundsFollowParameters) {
  const Bounds b = proceduralBounds(parseProceduralSpec("procedural:sphere,r=0.3,center=1:2:3"));
  EXPECT_NEAR(b.min.x, 0.7, 1e-12);
  EXPECT_NEAR(b.max.z, 3.3, 1e-12);
  const Bounds w = proceduralBounds(parseProceduralSpec("procedural:wine_glass,height=2"));
  EXPECT_NEAR(w.min.y, -1.0, 1e-12);
  EXPECT_NEAR(w.max.y, 1.0, 1e-12);
}

// Every shape voxelises on its own bounds: the documented regions, coverage in [0, 1], nothing
// outside the bounds, enclosed_volume = Σ coverage·V (0 for the open floor).
TEST(Procedural, DeterministicWhateverTheThreadCount) {
  const GridSpec grid = centredGrid(40, 0.6);
  const ProceduralSpec spec = parseProceduralSpec("procedural:wine_glass");
  ::setenv("EIKONAL_THREADS", "1", 1);
  const auto one = voxelizeProcedural(spec, grid);
  ::setenv("EIKONAL_THREADS", "3", 1);
  const auto three = voxelizeProcedural(spec, grid);
  ::unsetenv("EIKONAL_THREADS");
  ASSERT_EQ(one.size(), three.size());
  for (std::size_t r = 0; r < one.size(); ++r) {
    EXPECT_EQ(one[r].coverage, three[r].coverage);
    EXPECT_EQ(one[r].enclosed_volume, three[r].enclosed_volume);
  }
}

TEST(Procedural, RejectsSupersampleOutsideOneToSixteen) {
  const GridSpec grid = centredGrid(8, 0.55);
  for (int s : {0, 17}) {
    ProceduralOptions bad;
    bad.supersample = s;
    EXPECT_THROW(voxelizeProcedural(parseProceduralSpec("procedural:sphere"), grid, bad), std::invalid_argument) << s;
  }
}

TEST(Procedural, ProgressCoversEveryRegion) {
  const GridSpec grid = centredGrid(16, 0.6);
  double last = 0.0;
  bool monotone = true;
  voxelizeProcedural(parseProceduralSpec("procedural:wine_glass"), grid, {}, [&](double f) {
    if (f < last) monotone = false;
    last = f;
  });
  EXPECT_DOUBLE_EQ(last, 1.0);
  EXPECT_TRUE(monotone);
}

}  // namespace
}  // namespace eik
