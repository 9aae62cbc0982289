// The interfaces table of a volume (interfaces.h): read strictly, and the material a point is in.
#include "core/interfaces.h"

#include <gtest/gtest.h>

#include "core/testing.h"

namespace eik {
namespace {

using test_support::inputErrorOf;

Volume withTable(const nlohmann::json& table) {
  Volume v;
  v.grid.dims = {2, 2, 2};
  v.grid.bounds_max = glm::dvec3(1.0);
  v.addField("interfaces", 4);
  v.metadata["interfaces"] = table;
  return v;
}

TEST(Interfaces, ReadsTheSlotsInnermostFirst) {
  const InterfaceTable t = interfaceTable(withTable(
      {{"band", 0.1},
       {"slots", {{{"name", "wine"}, {"ior", 1.34}}, {{"name", "glass"}, {"ior", 1.5}, {"dispersion_b", 0.004}},
                  {{"name", "lens"}, {"ior", 1.0}, {"graded", true}}, {{"name", "opaque"}, {"opaque", true}}}}}));
  ASSERT_EQ(t.slots.size(), 4u);
  EXPECT_EQ(t.slots[0].name, "wine");
  EXPECT_DOUBLE_EQ(t.slots[1].dispersion_b, 0.004);
  EXPECT_TRUE(t.slots[2].graded);
  EXPECT_TRUE(t.slots[3].opaque);
  EXPECT_DOUBLE_EQ(t.band, 0.1);
  // It survives a round trip.
  EXPECT_EQ(interfaceTable(withTable(t.toJson())).slots[1].ior, 1.5);
}

TEST(Interfaces, ASlotsAbsorptionIsOptionalAndSurvivesARoundTrip) {
  const InterfaceTable t = interfaceTable(withTable(
      {{"band", 0.1},
       {"slots", {{{"name", "wine"}, {"ior", 1.34}, {"sigma_a", {0.5, 8.0, 6.0}}}, {{"name", "glass"}, {"ior", 1.5}}}}}));
  ASSERT_TRUE(t.slots[0].sigma_a.has_value());
  EXPECT_EQ(*t.slots[0].sigma_a, glm::dvec3(0.5, 8.0, 6.0));
  EXPECT_FALSE(t.slots[1].sigma_a.has_value());  // older volumes: the field alone
  const InterfaceTable back = interfaceTable(withTable(t.toJson()));
  EXPECT_EQ(back.slots[0].sigma_a, t.slots[0].sigma_a);
  EXPECT_FALSE(back.slots[1].sigma_a.has_value());
  for (const nlohmann::json& bad : {nlohmann::json{1.0, 2.0}, nlohmann::json{1.0, -2.0, 0.0}, nlohmann::json("red")})
    EXPECT_CONTAINS(inputErrorOf([&] {
                      interfaceTable(withTable({{"band", 0.1}, {"slots", {{{"ior", 1.5}, {"sigma_a", bad}}}}}));
                    }),
                    "interfaces.slots[0].sigma_a");
}

TEST(Interfaces, AVolumeWithoutThemHasAnEmptyTable) {
  Volume v;
  v.grid.dims = {2, 2, 2};
  EXPECT_TRUE(interfaceTable(v).empty());
}

TEST(Interfaces, MalformedTablesNameTheKey) {
  EXPECT_CONTAINS(inputErrorOf([] { interfaceTable(withTable({{"slots", {{{"ior", 1.5}}}}})); }), "interfaces.band");
  EXPECT_CONTAINS(inputErrorOf([] { interfaceTable(withTable({{"band", 0.1}, {"slots", nlohmann::json::array()}})); }),
                  "1 to 4 slots");
  EXPECT_CONTAINS(inputErrorOf([] {
                    interfaceTable(withTable({{"band", 0.1}, {"slots", {{{"ior", 0.5}}}}}));
                  }),
                  "interfaces.slots[0].ior");
  EXPECT_CONTAINS(inputErrorOf([] {
                    interfaceTable(withTable({{"band", 0.1}, {"slots", {{{"colour", 1}}}}}));
                  }),
                  "interfaces.slots[0].colour: unknown key");
  Volume no_table;
  no_table.grid.dims = {2, 2, 2};
  no_table.addField("interfaces", 4);
  EXPECT_CONTAINS(inputErrorOf([&] { interfaceTable(no_table); }), "no interfaces table");
}

TEST(Interfaces, TheUnusedSlotsDistanceIsOneConstantOrNone) {
  Field d;
  d.components = 4;
  const std::size_t voxels = 200000;  // several of the check's chunks
  d.data.resize(voxels * 4);
  const double kBand = 0.07;  // the table's; a field of four holds its own (0.05 here), which wins
  for (std::size_t i = 0; i < voxels; ++i) {
    d.data[i * 4] = static_cast<float>(i % 7) - 3.0f;  // slot 0 used
    d.data[i * 4 + 1] = d.data[i * 4 + 2] = d.data[i * 4 + 3] = 0.05f;  // +band
  }
  ASSERT_TRUE(unusedSlotDistance(d, 1, kBand).has_value());
  EXPECT_EQ(*unusedSlotDistance(d, 1, kBand), 0.05f);
  EXPECT_FALSE(unusedSlotDistance(d, 0, kBand).has_value());  // slot 0 is not one constant
  EXPECT_FALSE(unusedSlotDistance(d, 4, kBand).has_value());  // nothing unused
  d.data[(voxels - 1) * 4 + 3] = 0.06f;               // one voxel off, in the last chunk
  EXPECT_FALSE(unusedSlotDistance(d, 1, kBand).has_value());
  EXPECT_FALSE(unusedSlotDistance(d, 3, kBand).has_value());
  d.data[(voxels - 1) * 4 + 3] = 0.05f;
  d.data[(voxels - 1) * 4 + 2] = 0.06f;
  EXPECT_TRUE(unusedSlotDistance(d, 3, kBand).has_value());  // slot 2 is used here
  // One distance per slot (as voxelize writes them): nothing unused is stored, the rest is +band.
  Field lean;
  lean.components = 2;
  lean.data.assign(voxels * 2, -1.0f);
  ASSERT_TRUE(unusedSlotDistance(lean, 2, kBand).has_value());
  EXPECT_EQ(*unusedSlotDistance(lean, 2, kBand), static_cast<float>(kBand));
  lean.components = 4;  // four slots, all used
  lean.data.assign(voxels * 4, -1.0f);
  EXPECT_FALSE(unusedSlotDistance(lean, 4, kBand).has_value());
}

TEST(Interfaces, TheFieldHoldsOneDistancePerSlotOrFour) {
  Volume v;
  v.grid.dims = {2, 2, 2};
  v.metadata["interfaces"] = {{"band", 0.05}, {"slots", {{{"name", "glass"}, {"ior", 1.5}}, {{"name", "wine"}, {"ior", 1.34}}}}};
  for (const int components : {2, 4}) {
    v.addField("interfaces", components);
    EXPECT_EQ(interfaceTable(v).slots.size(), 2u) << components;
  }
  for (const int components : {1, 3}) {
    v.addField("interfaces", components);
    EXPECT_CONTAINS(inputErrorOf([&] { interfaceTable(v, "two.vol.json"); }),
                    "two.vol.json: fields.interfaces: " + std::to_string(components) + " components for 2 slots");
  }
}

TEST(Interfaces, GradientIsLeftOutOnlyWhereEveryMaterialHasAConstantN) {
  Volume v;
  v.grid.dims = {2, 2, 2};
  v.addField("interfaces", 1);
  v.metadata["interfaces"] = {{"band", 0.05}, {"slots", {{{"name", "glass"}, {"ior", 1.5}}}}};
  const InterfaceTable constant = interfaceTable(v);
  EXPECT_TRUE(constantSlots(constant));
  EXPECT_EQ(iorGradient(v, constant), nullptr);  // left out: 0 throughout
  v.addField("ior_grad", 3);
  EXPECT_EQ(iorGradient(v, constant), &v.fields.at("ior_grad"));
  v.fields.erase("ior_grad");
  v.metadata["interfaces"]["slots"][0]["graded"] = true;
  const InterfaceTable graded = interfaceTable(v);
  EXPECT_FALSE(constantSlots(graded));
  EXPECT_CONTAINS(inputErrorOf([&] { iorGradient(v, graded, "lens.vol.json"); }), "ior_grad");
  EXPECT_CONTAINS(inputErrorOf([&] { iorGradient(Volume{}, InterfaceTable{}, "smoothed.vol.json"); }), "ior_grad");
  EXPECT_FALSE(constantSlots(InterfaceTable{}));  // no table: a smoothed n, whose ∇n is read
  v.unread_fields["ior_grad"] = 3;                // left in its file
  EXPECT_EQ(iorGradient(v, graded), nullptr);
  v.unread_fields["ior_grad"] = 4;
  EXPECT_CONTAINS(inputErrorOf([&] { iorGradient(v, graded, "lens.vol.json"); }), "4 components, expected 3");
}

TEST(Interfaces, TheMaterialIsTheFirstSlotWithANegativeDistance) {
  EXPECT_EQ(materialSlot({0.1, -0.2, -0.3, 0.4}, 4), 1);
  EXPECT_EQ(materialSlot({0.1, 0.2, -0.3, 0.4}, 2), -1);  // slot 2 is not in use
  EXPECT_EQ(materialSlot({-0.1, -0.2, 0.3, 0.4}, 4), 0);
}

// The share of a segment inside a box: the slabs' overlap of the segment's parameter range.
TEST(BoxShare, IsThePartOfTheSegmentInsideTheBox) {
  const glm::dvec3 lo(0.0), hi(1.0, 2.0, 3.0);
  EXPECT_DOUBLE_EQ(boxShare({0.2, 0.5, 1.0}, {0.8, 1.5, 2.0}, lo, hi), 1.0);    // inside
  EXPECT_DOUBLE_EQ(boxShare({2.0, 0.5, 1.0}, {3.0, 1.5, 2.0}, lo, hi), 0.0);    // beside it
  EXPECT_DOUBLE_EQ(boxShare({-1.0, 1.0, 1.0}, {1.0, 1.0, 1.0}, lo, hi), 0.5);   // in through a face
  EXPECT_DOUBLE_EQ(boxShare({-1.0, 1.0, 1.0}, {2.0, 1.0, 1.0}, lo, hi), 1.0 / 3.0);  // through it
  EXPECT_NEAR(boxShare({-0.5, -1.0, 1.5}, {1.5, 3.0, 1.5}, lo, hi), 0.5, 1e-15);  // diagonal: x and y cut it
  EXPECT_DOUBLE_EQ(boxShare({0.5, 3.0, 1.0}, {0.5, 3.0, 2.0}, lo, hi), 0.0);    // parallel, outside in y
  EXPECT_DOUBLE_EQ(boxShare({0.5, 1.0, 1.0}, {0.5, 1.0, 1.0}, lo, hi), 1.0);    // a point: in or out
  EXPECT_DOUBLE_EQ(boxShare({1.5, 1.0, 1.0}, {1.5, 1.0, 1.0}, lo, hi), 0.0);
}

}  // namespace
}  // namespace eik
