// Receiver maps on disk (receiver_map.h, volume.h): written beside the fields as oriented NRRDs,
// listed in the manifest, read back exactly; malformed entries named.
#include "core/receiver_map.h"

#include <gtest/gtest.h>

#include "core/testing.h"
#include "core/volume.h"

namespace eik {
namespace {

using test_support::inputErrorOf;
using test_support::TempDir;

ReceiverMap sampleMap() {
  ReceiverMap map;
  map.point = {0.0, -0.5, 0.0};
  receiverAxes(map.normal, map.u, map.v);
  map.origin = {-1.0, -0.75};
  map.pitch = 0.25;
  map.texels = {8, 6};
  map.irradiance.resize(map.texelCount() * 3);
  for (std::size_t i = 0; i < map.irradiance.size(); ++i) map.irradiance[i] = 0.5f * static_cast<float>(i);
  return map;
}

TEST(ReceiverMap, AxesAreOrthonormalWithUCrossVTheNormal) {
  for (const glm::dvec3 n : {glm::dvec3(0, 1, 0), glm::normalize(glm::dvec3(0.3, 1, -0.2)), glm::dvec3(0, 0, -1)}) {
    glm::dvec3 u, v;
    receiverAxes(n, u, v);
    EXPECT_NEAR(glm::dot(u, n), 0.0, 1e-12);
    EXPECT_NEAR(glm::length(u), 1.0, 1e-12);
    EXPECT_NEAR(glm::length(glm::cross(u, v) - n), 0.0, 1e-12);
  }
}

TEST(ReceiverMap, TexelCentresAndPlaneCoordinatesAgree) {
  const ReceiverMap map = sampleMap();
  const glm::dvec3 c = map.texelCenter(2, 3);
  EXPECT_NEAR(c.y, -0.5, 1e-12);
  const glm::dvec2 uv = map.planeCoordinates(c);
  EXPECT_NEAR(uv.x, -1.0 + 2.5 * 0.25, 1e-12);
  EXPECT_NEAR(uv.y, -0.75 + 3.5 * 0.25, 1e-12);
}

TEST(ReceiverMap, RoundTripsThroughAVolume) {
  TempDir dir;
  Volume v;
  v.grid.dims = {2, 2, 2};
  v.grid.bounds_max = glm::dvec3(1.0);
  v.addField("ior", 1);
  v.receivers.push_back(sampleMap());
  const std::string generation = writeVolume(v, dir / "r.vol.json");
  const std::filesystem::path file = dir / ("r." + generation + ".receiver-ground.nrrd");
  EXPECT_TRUE(std::filesystem::exists(file));
  const Volume back = readVolume(dir / "r.vol.json");
  ASSERT_EQ(back.receivers.size(), 1u);
  const ReceiverMap& m = back.receivers[0];
  EXPECT_EQ(m.texels, glm::ivec2(8, 6));
  EXPECT_EQ(m.irradiance, sampleMap().irradiance);
  EXPECT_NEAR(glm::length(m.v - sampleMap().v), 0.0, 1e-12);
  // The NRRD stands where the plane is: origin at texel (0, 0)'s centre, axes pitch·u, pitch·v.
  const NrrdHeader h = readNrrdHeader(file);
  EXPECT_EQ(h.generation, generation);
  EXPECT_NEAR(glm::length(h.origin - sampleMap().texelCenter(0, 0)), 0.0, 1e-9);
  EXPECT_NEAR(glm::length(h.directions[1] - 0.25 * sampleMap().v), 0.0, 1e-12);
  EXPECT_FALSE(readVolumeHeader(dir / "r.vol.json").receivers.empty());
}

// A map whose channels agree in every texel (a white light through clear glass) is kept and
// written grey, one value a texel, and reads back as it was; one texel that differs keeps it RGB.
TEST(ReceiverMap, AGreyMapKeepsOneValueATexelOnDiskAndReadsBackTheSame) {
  ReceiverMap grey = sampleMap();
  for (std::size_t t = 0; t < grey.texelCount(); ++t)
    for (int c = 0; c < 3; ++c) grey.irradiance[3 * t + static_cast<std::size_t>(c)] = 0.25f * static_cast<float>(t);
  ReceiverMap coloured = grey;
  coloured.irradiance[3 * 17 + 2] += 1e-6f;  // one channel of one texel off: not grey
  EXPECT_FALSE(coloured.makeGrey());
  EXPECT_EQ(coloured.components, 3);
  EXPECT_EQ(coloured.irradiance.size(), 3 * coloured.texelCount());
  const ReceiverMap rgb = grey;
  ASSERT_TRUE(grey.makeGrey());
  EXPECT_EQ(grey.components, 1);
  ASSERT_EQ(grey.irradiance.size(), grey.texelCount());
  for (std::size_t t = 0; t < grey.texelCount(); ++t) ASSERT_EQ(grey.rgb(t), rgb.rgb(t)) << t;

  TempDir dir;
  Volume v;
  v.grid.dims = {2, 2, 2};
  v.grid.bounds_max = glm::dvec3(1.0);
  v.addField("ior", 1);
  v.receivers = {grey, coloured};
  v.receivers[1].name = "coloured";
  const std::string generation = writeVolume(v, dir / "g.vol.json");
  EXPECT_EQ(readNrrdHeader(dir / ("g." + generation + ".receiver-ground.nrrd")).components, 1);
  EXPECT_EQ(readNrrdHeader(dir / ("g." + generation + ".receiver-coloured.nrrd")).components, 3);
  const nlohmann::json manifest = nlohmann::json::parse(test_support::readFile(dir / "g.vol.json"));
  EXPECT_CONTAINS(manifest["receivers"][0]["quantity"].get<std::string>(), "grey");
  EXPECT_CONTAINS(manifest["receivers"][1]["quantity"].get<std::string>(), "RGB");
  const Volume back = readVolume(dir / "g.vol.json");
  ASSERT_EQ(back.receivers.size(), 2u);
  EXPECT_EQ(back.receivers[0].components, 1);
  EXPECT_EQ(back.receivers[0].irradiance, grey.irradiance);
  EXPECT_EQ(back.receivers[1].components, 3);
  EXPECT_EQ(back.receivers[1].irradiance, coloured.irradiance);
  // A map of any other number of components is refused, naming the file.
  NrrdHeader two = grey.nrrdHeader();
  two.components = 2;
  EXPECT_CONTAINS(inputErrorOf([&] { checkReceiverHeader(grey, two, "v.json", "receivers[0]", "m.nrrd"); }),
                  "m.nrrd: expected 3 components (RGB) or 1 (grey)");
}

TEST(ReceiverMap, MalformedEntriesNameTheKey) {
  std::string file;
  nlohmann::json good = sampleMap().toJson("x.nrrd");
  EXPECT_NO_THROW(receiverFromJson(good, "v.json", "receivers[0]", file));
  EXPECT_EQ(file, "x.nrrd");
  nlohmann::json bad = good;
  bad["pitch"] = -1;
  EXPECT_CONTAINS(inputErrorOf([&] { receiverFromJson(bad, "v.json", "receivers[0]", file); }), "receivers[0].pitch");
  bad = good;
  bad["u"] = {0, 1, 0};
  EXPECT_CONTAINS(inputErrorOf([&] { receiverFromJson(bad, "v.json", "receivers[0]", file); }), "u × v = normal");
  bad = good;
  bad["texels"] = {0, 4};
  EXPECT_CONTAINS(inputErrorOf([&] { receiverFromJson(bad, "v.json", "receivers[0]", file); }), "receivers[0].texels");
  bad = good;
  bad.erase("origin");
  EXPECT_CONTAINS(inputErrorOf([&] { receiverFromJson(bad, "v.json", "receivers[0]", file); }), "receivers[0].origin: missing");
  bad = good;
  bad["name"] = "../ground";  // becomes part of a file name when the volume is written again
  EXPECT_CONTAINS(inputErrorOf([&] { receiverFromJson(bad, "v.json", "receivers[0]", file); }), "receivers[0].name: a receiver name");
}

}  // namespace
}  // namespace eik
