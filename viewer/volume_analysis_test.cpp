// The viewer's volume analysis on small hand-made volumes: the active region and the absorbing
// region with their one-voxel margins (clamped to the box), the homogeneous bricks with their
// margins, whether the material touches the box, the constant media of sharp materials, and the
// box of smoke in the air (on voxelized procedural shapes).
#include "viewer/volume_analysis.h"

#include <gtest/gtest.h>

#include "lightsim/test_scenes.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace eik {
namespace {

// dims voxels of size 1 from `origin`; air (n = 1, ∇n = 0) throughout.
Volume air(glm::ivec3 dims, glm::dvec3 origin = glm::dvec3(0.0)) {
  Volume v;
  v.grid.dims = dims;
  v.grid.bounds_min = origin;
  v.grid.bounds_max = origin + glm::dvec3(dims);
  v.addField("ior", 1).data.assign(v.grid.count(), 1.0f);
  v.addField("ior_grad", 3);
  return v;
}

float& ior(Volume& v, int i, int j, int k) { return v.fields.at("ior").data[v.grid.index(i, j, k)]; }
float* field(Volume& v, const char* name, int i, int j, int k) {
  return v.fields.at(name).voxel(v.grid.index(i, j, k));
}

void expectBox(const glm::dvec3& lo, const glm::dvec3& hi, glm::dvec3 want_lo, glm::dvec3 want_hi) {
  for (int c = 0; c < 3; ++c) {
    EXPECT_DOUBLE_EQ(lo[c], want_lo[c]) << "lo[" << c << "]";
    EXPECT_DOUBLE_EQ(hi[c], want_hi[c]) << "hi[" << c << "]";
  }
}

float brick(const std::vector<float>& bricks, glm::ivec3 dims, int x, int y, int z) {
  return bricks[(static_cast<std::size_t>(z) * dims.y + y) * dims.x + x];
}

TEST(ActiveRegion, IsFalseForAirThroughout) {
  Volume v = air({6, 6, 6});
  glm::dvec3 lo, hi;
  EXPECT_FALSE(activeRegion(v, lo, hi));
}

TEST(ActiveRegion, IsTheNonTrivialVoxelsWithOneVoxelOfMargin) {
  Volume v = air({8, 8, 8}, glm::dvec3(-4.0));
  ior(v, 3, 4, 5) = 1.5f;                      // glass in one voxel
  field(v, "ior_grad", 5, 4, 5)[1] = 0.01f;    // a gradient next to it, along x
  glm::dvec3 lo, hi;
  ASSERT_TRUE(activeRegion(v, lo, hi));
  // Voxels x 3..5, y 4, z 5; their faces at origin + index, one voxel more on each side.
  expectBox(lo, hi, glm::dvec3(-4.0) + glm::dvec3(2, 3, 4), glm::dvec3(-4.0) + glm::dvec3(7, 6, 7));
}

TEST(ActiveRegion, CountsEveryKindOfMediumAndClampsTheMarginToTheBox) {
  Volume v = air({8, 8, 8});
  v.addField("sigma_a", 3);
  v.addField("emission", 3);
  v.addField("scatter", 2);
  v.addField("opaque", 4);
  field(v, "sigma_a", 0, 0, 0)[2] = 0.1f;  // at the corner: the margin stops at the box
  field(v, "emission", 7, 1, 1)[0] = 1.0f;
  field(v, "scatter", 1, 7, 1)[0] = 0.5f;
  field(v, "opaque", 1, 1, 6)[3] = 1.0f;
  glm::dvec3 lo, hi;
  ASSERT_TRUE(activeRegion(v, lo, hi));
  expectBox(lo, hi, glm::dvec3(0.0), glm::dvec3(8, 8, 8));

  Volume only_scatter = air({8, 8, 8});
  only_scatter.addField("scatter", 2);
  field(only_scatter, "scatter", 4, 4, 4)[1] = 0.9f;  // g without albedo scatters nothing
  EXPECT_FALSE(activeRegion(only_scatter, lo, hi));
}

TEST(ActiveRegion, IgnoresIndicesAndGradientsWithinTheTolerance) {
  Volume v = air({6, 6, 6});
  ior(v, 2, 2, 2) = 1.0f + 5e-6f;               // |n − 1| ≤ 1e-5
  field(v, "ior_grad", 3, 3, 3)[0] = 5e-7f;    // |∇n|·h ≤ 1e-6
  glm::dvec3 lo, hi;
  EXPECT_FALSE(activeRegion(v, lo, hi));
}

TEST(HomogeneousBricks, UniformGlassIsHomogeneousEverywhere) {
  Volume v = air({9, 8, 4});
  v.fields.at("ior").data.assign(v.grid.count(), 1.5f);
  glm::ivec3 dims;
  const std::vector<float> bricks = homogeneousBricks(v, dims);
  EXPECT_EQ(dims, glm::ivec3(3, 2, 1));  // ⌈dims / 4⌉
  ASSERT_EQ(bricks.size(), 6u);
  for (float b : bricks) EXPECT_EQ(b, 1.0f);
}

TEST(HomogeneousBricks, AGradientMarksItsBrickAndTheNeighboursWithinTheMargin) {
  Volume v = air({12, 4, 4});
  field(v, "ior_grad", 5, 0, 0)[0] = 0.1f;  // in brick 1 (x 4..7), 1 voxel from brick 0, 2 from brick 2
  glm::ivec3 dims;
  const std::vector<float> bricks = homogeneousBricks(v, dims);
  ASSERT_EQ(dims, glm::ivec3(3, 1, 1));
  EXPECT_EQ(brick(bricks, dims, 0, 0, 0), 0.0f);  // brick 0 looks 2 voxels past x = 3: up to x = 5
  EXPECT_EQ(brick(bricks, dims, 1, 0, 0), 0.0f);
  EXPECT_EQ(brick(bricks, dims, 2, 0, 0), 1.0f);  // brick 2 looks back to x = 6 only
}

TEST(HomogeneousBricks, ChangesOfIndexOrAbsorptionAndMediaBreakHomogeneity) {
  glm::ivec3 dims;
  Volume step = air({8, 4, 4});
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 6; i < 8; ++i) ior(step, i, j, k) = 1.5f;  // n jumps at x = 6 (no gradient stored)
  std::vector<float> bricks = homogeneousBricks(step, dims);
  EXPECT_EQ(brick(bricks, dims, 0, 0, 0), 1.0f);  // looks up to x = 5
  EXPECT_EQ(brick(bricks, dims, 1, 0, 0), 0.0f);

  Volume absorbing = air({8, 4, 4});
  absorbing.addField("sigma_a", 3);
  for (std::size_t i = 0; i < absorbing.grid.count(); ++i) absorbing.fields.at("sigma_a").voxel(i)[0] = 2.0f;
  bricks = homogeneousBricks(absorbing, dims);
  EXPECT_EQ(brick(bricks, dims, 0, 0, 0), 1.0f);  // constant σa is homogeneous
  field(absorbing, "sigma_a", 1, 1, 1)[1] = 0.5f;
  bricks = homogeneousBricks(absorbing, dims);
  EXPECT_EQ(brick(bricks, dims, 0, 0, 0), 0.0f);
  EXPECT_EQ(brick(bricks, dims, 1, 0, 0), 1.0f);  // x = 1 is 3 voxels before brick 1

  for (const char* name : {"emission", "scatter", "opaque"}) {
    Volume medium = air({8, 4, 4});
    const int components = name == std::string("emission") ? 3 : name == std::string("scatter") ? 2 : 4;
    medium.addField(name, components);
    field(medium, name, 7, 3, 3)[components == 4 ? 3 : 0] = 1.0f;
    bricks = homogeneousBricks(medium, dims);
    EXPECT_EQ(brick(bricks, dims, 0, 0, 0), 1.0f) << name;
    EXPECT_EQ(brick(bricks, dims, 1, 0, 0), 0.0f) << name;
  }
}

// Each brick read voxel by voxel over its box (the brick and its margin): the definition the
// separable ranges of homogeneousBricks must reproduce exactly.
std::vector<float> bricksVoxelByVoxel(const Volume& v) {
  const glm::ivec3 dims = v.grid.dims, bd = (dims + kBrickVoxels - 1) / kBrickVoxels;
  const Field& n = v.fields.at("ior");
  const Field* g = v.find("ior_grad");
  const Field* sigma = v.find("sigma_a");
  const Field* emission = v.find("emission");
  std::vector<float> out(static_cast<std::size_t>(bd.x) * bd.y * bd.z);
  for (int bz = 0; bz < bd.z; ++bz)
    for (int by = 0; by < bd.y; ++by)
      for (int bx = 0; bx < bd.x; ++bx) {
        const glm::ivec3 lo = glm::max(glm::ivec3(bx, by, bz) * kBrickVoxels - kBrickMargin, glm::ivec3(0));
        const glm::ivec3 hi = glm::min(glm::ivec3(bx, by, bz) * kBrickVoxels + kBrickVoxels + kBrickMargin, dims);
        const std::size_t first = v.grid.index(lo.x, lo.y, lo.z);
        bool homogeneous = true;
        for (int k = lo.z; k < hi.z; ++k)
          for (int j = lo.y; j < hi.y; ++j)
            for (int i = lo.x; i < hi.x; ++i) {
              const std::size_t at = v.grid.index(i, j, k);
              if (std::abs(n.data[at] - n.data[first]) > 1e-4f) homogeneous = false;
              if (g && (std::abs(g->voxel(at)[0]) + std::abs(g->voxel(at)[1]) + std::abs(g->voxel(at)[2])) > 1e-4) homogeneous = false;
              if (emission && emission->voxel(at)[1] > 0) homogeneous = false;
              if (sigma)
                for (int c = 0; c < 3; ++c)
                  if (std::abs(sigma->voxel(at)[c] - sigma->voxel(first)[c]) > 1e-6f * (1.0f + sigma->voxel(first)[c]))
                    homogeneous = false;
            }
        out[(static_cast<std::size_t>(bz) * bd.y + by) * bd.x + bx] = homogeneous ? 1.0f : 0.0f;
      }
  return out;
}

// Random volumes (grids that are and are not multiples of the brick, n in plateaus with changes at
// and just around the tolerance, σa likewise, a few voxels of ∇n and of emission): the bricks are
// those of reading every voxel of every box.
TEST(HomogeneousBricks, TheSeparableRangesAreThoseOfEveryVoxel) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int homogeneous = 0, marched = 0;
  for (const glm::ivec3 dims : {glm::ivec3(17, 9, 12), glm::ivec3(16, 16, 8), glm::ivec3(5, 23, 3)}) {
    for (int variant = 0; variant < 4; ++variant) {
      Volume v = air(dims);
      if (variant >= 2) v.addField("sigma_a", 3);
      if (variant == 3) v.addField("emission", 3);
      for (std::size_t i = 0; i < v.grid.count(); ++i) {
        const float r = u(rng);
        // Mostly 1.5; some voxels off by 0.5e-4 (within the tolerance), fewer by 1.5e-4 (beyond) or a step.
        v.fields.at("ior").data[i] = r < 0.98f ? 1.5f : r < 0.999f ? 1.50005f : r < 0.9995f ? 1.50015f : 1.33f;
        if (u(rng) < 0.0005f) v.fields.at("ior_grad").voxel(i)[u(rng) < 0.5f ? 0 : 2] = 0.3f;
        if (variant >= 2) {
          float* s = v.fields.at("sigma_a").voxel(i);
          s[0] = 2.0f;
          s[1] = u(rng) < 0.0005f ? 2.0f : 0.5f;
          s[2] = u(rng) < 0.01f ? 0.5f + 1e-7f : 0.5f;  // within 1e-6·(1 + σa)
        }
        if (variant == 3 && u(rng) < 0.0005f) v.fields.at("emission").voxel(i)[1] = 1.0f;
      }
      glm::ivec3 bd;
      const std::vector<float> bricks = homogeneousBricks(v, bd);
      EXPECT_EQ(bd, (dims + kBrickVoxels - 1) / kBrickVoxels);
      const std::vector<float> want = bricksVoxelByVoxel(v);
      ASSERT_EQ(bricks.size(), want.size());
      for (std::size_t b = 0; b < want.size(); ++b) {
        EXPECT_EQ(bricks[b], want[b]) << "brick " << b << ", grid " << dims.x << "x" << dims.y << "x" << dims.z << ", variant " << variant;
        (want[b] != 0.0f ? homogeneous : marched) += 1;
      }
    }
  }
  EXPECT_GT(homogeneous, 20);  // both kinds are there to compare
  EXPECT_GT(marched, 20);
}


TEST(MaterialTouchesBox, OnlyWhereNDiffersFromOneOnAFace) {
  Volume v = air({6, 6, 6});
  for (int k = 1; k < 5; ++k)
    for (int j = 1; j < 5; ++j)
      for (int i = 1; i < 5; ++i) ior(v, i, j, k) = 1.5f;  // glass inside, air on every face
  EXPECT_FALSE(materialTouchesBox(v));
  ior(v, 3, 5, 2) = 1.0005f;  // within 1e-3 of air
  EXPECT_FALSE(materialTouchesBox(v));
  ior(v, 3, 5, 2) = 1.5f;  // on the top face
  EXPECT_TRUE(materialTouchesBox(v));
  // Glass at one voxel of each of the six faces (a box of 5 × 6 × 7 voxels), the rest air.
  const glm::ivec3 on_face[6] = {{0, 2, 3}, {4, 3, 2}, {2, 0, 4}, {1, 5, 3}, {3, 2, 0}, {2, 4, 6}};
  for (const glm::ivec3& f : on_face) {
    Volume w = air({5, 6, 7});
    ior(w, f.x, f.y, f.z) = 1.2f;
    EXPECT_TRUE(materialTouchesBox(w)) << f.x << ", " << f.y << ", " << f.z;
  }
}

TEST(AbsorbingRegion, IsTheBoxOfPositiveSigmaWithOneVoxelOfMargin) {
  glm::dvec3 lo, hi;
  Volume v = air({8, 8, 8}, glm::dvec3(1.0, 2.0, 3.0));
  EXPECT_FALSE(absorbingRegion(v, lo, hi));  // no sigma_a field
  v.addField("sigma_a", 3);
  EXPECT_FALSE(absorbingRegion(v, lo, hi));  // all zero
  field(v, "sigma_a", 2, 3, 4)[0] = 0.5f;
  field(v, "sigma_a", 4, 3, 7)[1] = 0.5f;  // at the last z layer: the margin stops at the box
  ior(v, 0, 0, 0) = 1.5f;                  // glass does not absorb
  ASSERT_TRUE(absorbingRegion(v, lo, hi));
  expectBox(lo, hi, glm::dvec3(1.0, 2.0, 3.0) + glm::dvec3(1, 2, 3), glm::dvec3(1.0, 2.0, 3.0) + glm::dvec3(6, 5, 8));
}

// Sharp slabs along x on 16×4×4 unit voxels: slot 0 where x < 6, slot 1 where 6 ≤ x < `outer`
// (its solid is x < outer, under slot 0), air beyond; the distances of the unused slots are far
// out. Each material's σa and scatter where it is deep, and a blend of both sides within a voxel
// of each surface (as compositing mixes them), which slotMedia must not read.
struct SharpSlabs {
  Volume volume = air({16, 4, 4});
  InterfaceTable table;
  SharpSlabs(glm::vec3 sa0, glm::vec3 sa1, glm::vec2 sc0, glm::vec2 sc1, double outer = 12.0) {
    table.band = 4.0;
    table.slots = {InterfaceSlot{"inner", 1.5, 0.0, false, false}, InterfaceSlot{"outer", 1.4, 0.0, false, false}};
    Field& d = volume.addField("interfaces", 4);
    Field& sigma = volume.addField("sigma_a", 3);
    Field& scatter = volume.addField("scatter", 2);
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 16; ++i) {
          const std::size_t v = volume.grid.index(i, j, k);
          const double x = i + 0.5;
          const float d0 = static_cast<float>(std::clamp(x - 6.0, -4.0, 4.0));
          const float d1 = static_cast<float>(std::clamp(x - outer, -4.0, 4.0));
          d.voxel(v)[0] = d0;
          d.voxel(v)[1] = d1;
          d.voxel(v)[2] = d.voxel(v)[3] = 4.0f;
          const glm::vec3 sa = x < 6 ? sa0 : x < outer ? sa1 : glm::vec3(0.0f);
          const glm::vec2 sc = x < 6 ? sc0 : x < outer ? sc1 : glm::vec2(0.0f);
          const bool blended = std::abs(d0) < 1.0f || std::abs(d1) < 1.0f;
          for (int c = 0; c < 3; ++c) sigma.voxel(v)[c] = blended ? 0.5f * sa[c] + 0.123f : sa[c];
          for (int c = 0; c < 2; ++c) scatter.voxel(v)[c] = blended ? 0.5f * sc[c] + 0.07f : sc[c];
        }
  }
  float* at(const char* name, int i) { return field(volume, name, i, 1, 2); }
};

TEST(SlotMedia, AreEachMaterialsConstantsWhereTheyAreOneThroughout) {
  SharpSlabs slabs({1, 2, 3}, {0.5f, 0, 0}, {0.2f, 0.3f}, {0, 0});
  const SlotMedia media = slotMedia(slabs.volume, slabs.table);
  ASSERT_TRUE(media.sigma_a_constant);
  ASSERT_TRUE(media.scatter_constant);
  ASSERT_EQ(media.media.size(), 3u);  // air, slot 0, slot 1
  EXPECT_EQ(media.media[0].sigma_a, glm::dvec3(0.0));
  EXPECT_EQ(media.media[1].sigma_a, glm::dvec3(1, 2, 3));
  EXPECT_EQ(media.media[2].sigma_a, glm::dvec3(0.5f, 0, 0));
  EXPECT_EQ(media.media[1].scatter, glm::dvec2(0.2f, 0.3f));
  EXPECT_EQ(media.media[2].scatter, glm::dvec2(0.0));
}

TEST(SlotMedia, VaryWhereAMaterialDisagreesWithItselfOrIsNeverDeep) {
  {  // one deep voxel of slot 1 with another σa (two objects of one n share the slot)
    SharpSlabs slabs({1, 2, 3}, {0.5f, 0, 0}, {0.2f, 0.3f}, {0, 0});
    slabs.at("sigma_a", 9)[2] = 0.25f;
    const SlotMedia media = slotMedia(slabs.volume, slabs.table);
    EXPECT_FALSE(media.sigma_a_constant);
    EXPECT_TRUE(media.scatter_constant);
    EXPECT_EQ(media.media[1].sigma_a, glm::dvec3(0.0));  // no constants reported for a varying field
  }
  {  // smoke in the air: the air scatters in one place
    SharpSlabs slabs({1, 2, 3}, {0.5f, 0, 0}, {0.2f, 0.3f}, {0, 0});
    slabs.at("scatter", 14)[0] = 0.35f;
    const SlotMedia media = slotMedia(slabs.volume, slabs.table);
    EXPECT_TRUE(media.sigma_a_constant);
    EXPECT_FALSE(media.scatter_constant);
  }
  {  // slot 1 two voxels thick: none of its voxels is a voxel from both surfaces
    SharpSlabs slabs({1, 2, 3}, {0.5f, 0, 0}, {0.2f, 0.3f}, {0, 0}, 7.5);
    const SlotMedia media = slotMedia(slabs.volume, slabs.table);
    EXPECT_FALSE(media.sigma_a_constant);
    EXPECT_FALSE(media.scatter_constant);
  }
  {  // the thin slot with its σa in the slot table (the voxelizer records it): known, not its scatter
    SharpSlabs slabs({1, 2, 3}, {0.5f, 0, 0}, {0.2f, 0.3f}, {0, 0}, 7.5);
    slabs.table.slots[1].sigma_a = glm::dvec3(0.5, 0.0, 0.0);
    const SlotMedia media = slotMedia(slabs.volume, slabs.table);
    EXPECT_TRUE(media.sigma_a_constant);
    EXPECT_EQ(media.media[2].sigma_a, glm::dvec3(0.5, 0.0, 0.0));
    EXPECT_FALSE(media.scatter_constant);
    // A table that disagrees with the deep voxels of a thick slot: the field decides.
    SharpSlabs thick({1, 2, 3}, {0.5f, 0, 0}, {0.2f, 0.3f}, {0, 0});
    thick.table.slots[0].sigma_a = glm::dvec3(1.0, 2.0, 3.5);
    EXPECT_FALSE(slotMedia(thick.volume, thick.table).sigma_a_constant);
  }
  {  // an opaque slot is not read, whatever it holds
    SharpSlabs slabs({1, 2, 3}, {0.5f, 0, 0}, {0.2f, 0.3f}, {0, 0});
    slabs.table.slots[0].opaque = true;
    slabs.at("sigma_a", 1)[0] = 7.0f;
    EXPECT_TRUE(slotMedia(slabs.volume, slabs.table).sigma_a_constant);
  }
  {  // without sharp interfaces there are no materials to know
    SharpSlabs slabs({1, 2, 3}, {0.5f, 0, 0}, {0.2f, 0.3f}, {0, 0});
    const SlotMedia media = slotMedia(slabs.volume, InterfaceTable{});
    EXPECT_FALSE(media.sigma_a_constant);
    EXPECT_FALSE(media.scatter_constant);
  }
}

// A glass ball in a box of smoke (ior 1: no surface of its own, so the air's σa and ω̂ vary), as
// voxelize writes it: the smoke's faces where the coverage of their voxels puts them, off the
// voxel lattice on every axis.
const char* kSmokeBox = "procedural:box,size=0.7:0.62:0.77,center=0.03:-0.02:0.01,ior=1,sigma_a=0.5:2:4,scatter=0.6,g=0.4";
const char* kGlassBall = "procedural:sphere,r=0.15,center=0:0:0,ior=1.5,sigma_a=0.25:0.5:1,scatter=0.3,g=0.2";

TEST(AirMediumBox, IsTheSmokesBoxWithItsFacesWhereTheirCoverageSays) {
  for (int res : {32, 45}) {
    const Volume v = test_scenes::sharpVolume(std::vector<std::string>{kGlassBall, kSmokeBox}, res,
                                              test_scenes::box({-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}));
    const InterfaceTable table = interfaceTable(v);
    ASSERT_EQ(table.slots.size(), 1u) << "the smoke has no surface of its own";
    const SlotMedia media = slotMedia(v, table);
    ASSERT_TRUE(media.sigma_a_constant && media.scatter_constant) << res;
    ASSERT_TRUE(media.air_box.has_value()) << res;
    const glm::dvec3 lo(0.03 - 0.35, -0.02 - 0.31, 0.01 - 0.385), hi(0.03 + 0.35, -0.02 + 0.31, 0.01 + 0.385);
    for (int c = 0; c < 3; ++c) {
      // The voxelizer's coverage of a face parallel to an axis is exact (implicit_voxelizer.h);
      // what is left is float rounding of the shares: 1e-6 of the box.
      EXPECT_NEAR(media.air_box->lo[c], lo[c], 1e-6) << res << " lo " << c;
      EXPECT_NEAR(media.air_box->hi[c], hi[c], 1e-6) << res << " hi " << c;
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(media.air_box->sigma_a[c], glm::dvec3(0.5, 2, 4)[c], 1e-6);
    EXPECT_NEAR(media.air_box->scatter.x, 0.6, 1e-6);
    EXPECT_NEAR(media.air_box->scatter.y, 0.4, 1e-6);
    EXPECT_EQ(media.media[0].sigma_a, glm::dvec3(0.0)) << "outside the box the air is clear";
    EXPECT_EQ(media.media[0].scatter, glm::dvec2(0.0));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(media.media[1].sigma_a[c], glm::dvec3(0.25, 0.5, 1)[c], 1e-6);
    EXPECT_NEAR(media.media[1].scatter.x, 0.3, 1e-6);
  }
}

TEST(AirMediumBox, IsNoneWhereTheSmokeIsNotOneBoxOfOneValue) {
  const Bounds bounds = test_scenes::box({-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6});
  auto media = [&](std::vector<std::string> specs) {
    const Volume v = test_scenes::sharpVolume(specs, 32, bounds);
    return slotMedia(v, interfaceTable(v));
  };
  // A ball of smoke: its bounding box holds clear air in the corners.
  SlotMedia ball = media({kGlassBall, "procedural:sphere,r=0.45,center=0:0:0,ior=1,sigma_a=0.5:2:4,scatter=0.6"});
  EXPECT_FALSE(ball.air_box.has_value());
  EXPECT_FALSE(ball.sigma_a_constant);
  // Two boxes of smoke side by side, one denser.
  SlotMedia two = media({kGlassBall, "procedural:box,size=0.4:0.8:0.8,center=-0.2:0:0,ior=1,sigma_a=0.5:2:4,scatter=0.6",
                         "procedural:box,size=0.4:0.8:0.8,center=0.2:0:0,ior=1,sigma_a=1:2:4,scatter=0.6"});
  EXPECT_FALSE(two.air_box.has_value());
  EXPECT_FALSE(two.sigma_a_constant);
  // Two boxes of the same smoke with clear air between them.
  SlotMedia apart = media({kGlassBall, "procedural:box,size=0.3:0.8:0.8,center=-0.3:0:0,ior=1,sigma_a=0.5:2:4",
                           "procedural:box,size=0.3:0.8:0.8,center=0.3:0:0,ior=1,sigma_a=0.5:2:4"});
  EXPECT_FALSE(apart.air_box.has_value());
  EXPECT_FALSE(apart.sigma_a_constant);
  // Clear air: every material's constants without a box.
  SlotMedia clear = media({kGlassBall});
  EXPECT_FALSE(clear.air_box.has_value());
  EXPECT_TRUE(clear.sigma_a_constant && clear.scatter_constant);
}

}  // namespace
}  // namespace eik
