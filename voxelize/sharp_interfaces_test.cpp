// Sharp interfaces from the voxeliser (sharp_interfaces.h): the slots, the distances, n unblended,
// ∇n of graded materials only.
#include "voxelize/sharp_interfaces.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/interfaces.h"
#include "core/testing.h"
#include "voxelize/grid_builder.h"
#include "voxelize/pipeline.h"
#include "voxelize/procedural.h"

namespace eik {
namespace {

using test_support::inputErrorOf;

std::vector<Region> regionsOf(const std::vector<std::string>& specs, const GridSpec& grid) {
  ProceduralOptions options;
  options.distance_band = interfaceBand(grid);
  std::vector<Region> regions;
  for (const std::string& s : specs)
    for (Region& r : voxelizeProcedural(parseProceduralSpec(s), grid, options)) regions.push_back(std::move(r));
  return regions;
}

GridSpec cube(int res, double half) {
  GridSpec g;
  g.dims = glm::ivec3(res);
  g.bounds_min = glm::dvec3(-half);
  g.bounds_max = glm::dvec3(half);
  return g;
}

TEST(SharpInterfaces, SlotsAreMaterialsInnermostFirst) {
  const GridSpec g = cube(24, 0.6);
  // Wine inside glass; a second glass object merges with the first; smoke (n = 1) around all of it
  // needs no slot; two opaque grains share one.
  const auto regions = regionsOf({"procedural:sphere,r=0.5,ior=1.5", "procedural:sphere,r=0.2,ior=1.33,name=wine",
                                  "procedural:box,size=0.1,center=0.3:0.3:0.3,ior=1.5,name=chip",
                                  "procedural:sphere,r=0.05,center=-0.2:0:0,albedo=0.1:0.1:0.1,name=grain",
                                  "procedural:sphere,r=0.04,center=0.2:0:0,albedo=0.2:0.2:0.2,name=grain",
                                  "procedural:box,size=1.1,ior=1,scatter=0.3,name=smoke"},
                                 g);
  const SlotAssignment slots = assignInterfaceSlots(regions, interfaceBand(g));
  ASSERT_EQ(slots.table.slots.size(), 3u);
  EXPECT_TRUE(slots.table.slots[0].opaque);        // the grains, smallest
  // n = 1.5: the chip, smaller than the wine, comes first and names the slot it shares with the sphere.
  EXPECT_EQ(slots.table.slots[1].name, "chip");
  EXPECT_EQ(slots.table.slots[2].name, "wine");
  EXPECT_EQ(slots.slot_of_region[2], slots.slot_of_region[0]);  // chip and sphere: one glass
  EXPECT_EQ(slots.slot_of_region[5], -1);                        // the smoke
}

// Each slot records the σa its objects share (lightsim's σa per material), and none when they differ.
TEST(SharpInterfaces, ASlotRecordsTheAbsorptionItsObjectsShare) {
  const GridSpec g = cube(16, 0.6);
  const auto shared = assignInterfaceSlots(
      regionsOf({"procedural:sphere,r=0.2,center=-0.3:0:0,ior=1.33,sigma_a=1:2:3,name=a",
                 "procedural:sphere,r=0.2,center=0.3:0:0,ior=1.33,sigma_a=1:2:3,name=b",
                 "procedural:box,size=0.2,center=0:0.4:0,ior=1.5,name=glass",
                 "procedural:sphere,r=0.05,center=0:-0.4:0,albedo=0.1:0.1:0.1,sigma_a=4,name=grain"},
                g),
      interfaceBand(g));
  ASSERT_EQ(shared.table.slots.size(), 3u);
  const auto slotOf = [&](double ior, bool opaque) {
    for (const InterfaceSlot& s : shared.table.slots)
      if (s.ior == ior && s.opaque == opaque) return s;
    ADD_FAILURE() << "no slot of n = " << ior;
    return InterfaceSlot{};
  };
  EXPECT_EQ(slotOf(1.5, false).sigma_a, glm::dvec3(0.0));
  EXPECT_EQ(slotOf(1.0, true).sigma_a, std::nullopt);  // stops light: no σa
  const InterfaceSlot liquid = slotOf(static_cast<double>(1.33f), false);
  ASSERT_TRUE(liquid.sigma_a.has_value());
  EXPECT_EQ(*liquid.sigma_a, glm::dvec3(1.0, 2.0, 3.0));
  const auto differ = assignInterfaceSlots(
      regionsOf({"procedural:sphere,r=0.2,center=-0.3:0:0,ior=1.33,sigma_a=1:2:3,name=a",
                 "procedural:sphere,r=0.2,center=0.3:0:0,ior=1.33,sigma_a=1,name=b"},
                g),
      interfaceBand(g));
  ASSERT_EQ(differ.table.slots.size(), 1u);
  EXPECT_FALSE(differ.table.slots[0].sigma_a.has_value());
}

TEST(SharpInterfaces, MoreThanFourMaterialsIsAnErrorNamingThem) {
  const GridSpec g = cube(12, 1.0);
  std::vector<std::string> specs;
  for (int i = 0; i < 5; ++i)
    specs.push_back("procedural:sphere,r=0.1,center=" + std::to_string(-0.8 + 0.4 * i) + ":0:0,ior=" +
                    std::to_string(1.3 + 0.1 * i) + ",name=m" + std::to_string(i));
  const auto regions = regionsOf(specs, g);
  EXPECT_CONTAINS(inputErrorOf([&] { assignInterfaceSlots(regions, 0.1); }), "5 distinct materials");
}

TEST(SharpInterfaces, FieldsAreSharpDistancesAndUnblendedN) {
  const GridSpec g = cube(32, 0.6);
  const Volume v = buildSharpVolume(regionsOf({"procedural:sphere,r=0.5,ior=1.5"}, g), g, interfaceBand(g));
  const Field& d = v.fields.at("interfaces");
  const Field& n = v.fields.at("ior");
  // One distance per slot; no ∇n, which is 0 throughout without a graded material (constantSlots).
  ASSERT_EQ(d.components, 1);
  EXPECT_FALSE(v.has("ior_grad"));
  EXPECT_EQ(iorGradient(v, interfaceTable(v)), nullptr);
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 32; ++i) {
        const std::size_t at = g.index(i, j, k);
        const double r = glm::length(g.center(i, j, k));
        const double band = interfaceBand(g);
        // The exact distance of a sphere, within the band; +band beyond.
        ASSERT_NEAR(d.voxel(at)[0], std::clamp(r - 0.5, -band, band), 1e-6);
        ASSERT_FLOAT_EQ(n.data[at], r < 0.5 ? 1.5f : 1.0f);  // no blending at the surface
      }
  EXPECT_EQ(v.metadata.at("interfaces").at("slots").size(), 1u);
  EXPECT_EQ(v.metadata.at("ior_smoothing_sigma_voxels"), 0.0);
}

// Objects that need no interface (n = 1, nothing opaque): the volume has no interfaces field and
// no table, which readers would refuse as "0 slots" (voxelize wrote such a volume that lightsim and
// the viewer could not open).
// Handed over (an rvalue), the regions give up their coverage and distances once read, and the
// volume is the one the const form builds, every field to the bit: several materials sharing slots,
// an absorbing one, smoke and a graded lens (whose n, kept, still says it is graded).
TEST(SharpInterfaces, HandedOverRegionsReleaseTheirArraysAndBuildTheSameVolume) {
  const GridSpec g = cube(24, 0.6);
  const std::vector<std::string> specs = {"procedural:sphere,r=0.45,ior=1.5,sigma_a=0.5:0.2:0.1",
                                          "procedural:sphere,r=0.15,center=0.2:0:0,ior=1.33,name=wine",
                                          "procedural:gradient_slab,size=0.2:0.2:0.2,center=-0.2:0:0,n0=1.3,n1=1.7",
                                          "procedural:box,size=1.1,ior=1,scatter=0.3,name=smoke"};
  const std::vector<Region> kept = regionsOf(specs, g);
  const Volume expected = buildSharpVolume(kept, g, interfaceBand(g));
  std::vector<Region> handed = regionsOf(specs, g);
  const Volume got = buildSharpVolume(std::move(handed), g, interfaceBand(g));
  ASSERT_EQ(handed.size(), kept.size());
  for (std::size_t i = 0; i < handed.size(); ++i) {
    EXPECT_TRUE(handed[i].coverage.empty()) << handed[i].name;
    EXPECT_TRUE(handed[i].distance.empty()) << handed[i].name;
    EXPECT_EQ(handed[i].ior.empty(), kept[i].ior.empty()) << handed[i].name;
  }
  ASSERT_EQ(got.fields.size(), expected.fields.size());
  for (const auto& [name, field] : expected.fields) {
    ASSERT_TRUE(got.has(name)) << name;
    EXPECT_EQ(got.fields.at(name).components, field.components) << name;
    EXPECT_TRUE(got.fields.at(name).data == field.data) << name;
  }
  EXPECT_EQ(got.metadata, expected.metadata);
}

TEST(SharpInterfaces, ObjectsOfAirMakeAVolumeWithoutInterfaces) {
  const GridSpec g = cube(16, 0.6);
  const Volume v = buildSharpVolume(regionsOf({"procedural:box,size=0.5:0.5:0.5,ior=1.0"}, g), g, interfaceBand(g));
  EXPECT_FALSE(v.has("interfaces"));
  EXPECT_FALSE(v.metadata.contains("interfaces"));
  EXPECT_TRUE(interfaceTable(v).empty());  // the reader's view: a volume without sharp interfaces
  for (float n : v.fields.at("ior").data) ASSERT_EQ(n, 1.0f);
  ASSERT_TRUE(v.has("ior_grad"));  // no table to say ∇n is 0: readers need the field
  for (float g : v.fields.at("ior_grad").data) ASSERT_EQ(g, 0.0f);
}

TEST(SharpInterfaces, AGradedLensKeepsItsOwnNAndGradientAcrossTheSurface) {
  const GridSpec g = cube(32, 0.6);
  const Volume v = buildSharpVolume(regionsOf({"procedural:gradient_slab,size=0.8:0.8:0.8,n0=1.3,n1=1.7"}, g), g,
                                    interfaceBand(g));
  ASSERT_TRUE(interfaceTable(v).slots.at(0).graded);
  EXPECT_EQ(v.fields.at("interfaces").components, 1);
  // n rises by 0.4 over 0.8 along x: ∇n = (0.5, 0, 0) inside and just outside (continued), no jump.
  const Field& grad = v.fields.at("ior_grad");
  for (int i = 2; i < 30; ++i) {
    const std::size_t at = g.index(i, 16, 16);
    if (std::abs(g.center(i, 16, 16).x) > 0.4 + 2 * g.voxelSize().x) continue;
    EXPECT_NEAR(grad.voxel(at)[0], 0.5, 1e-4) << i;
    EXPECT_NEAR(grad.voxel(at)[1], 0.0, 1e-6) << i;
  }
  EXPECT_NEAR(v.fields.at("ior").data[g.index(16, 16, 16)], 1.5 + 0.5 * g.center(16, 16, 16).x, 1e-5);
}

}  // namespace
}  // namespace eik
