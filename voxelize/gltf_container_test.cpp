// The glTF container checks that run before tinygltf: the GLB header and chunk table against the
// file size, JSON syntax, buffers against the GLB binary chunk and external files.
#include "voxelize/gltf_container.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/testing.h"

namespace eik {
namespace {

using test_support::inputErrorOf;

void put32(std::vector<unsigned char>& bytes, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

// A GLB: header, a JSON chunk holding `json`, and a binary chunk of `bin` bytes when bin >= 0.
std::vector<unsigned char> glb(const std::string& json, int bin = -1) {
  std::vector<unsigned char> chunks;
  put32(chunks, static_cast<std::uint32_t>(json.size()));
  put32(chunks, 0x4E4F534A);
  chunks.insert(chunks.end(), json.begin(), json.end());
  if (bin >= 0) {
    put32(chunks, static_cast<std::uint32_t>(bin));
    put32(chunks, 0x004E4942);
    chunks.insert(chunks.end(), static_cast<std::size_t>(bin), 0);
  }
  std::vector<unsigned char> bytes;
  put32(bytes, kGlbMagic);
  put32(bytes, 2);
  put32(bytes, static_cast<std::uint32_t>(12 + chunks.size()));
  bytes.insert(bytes.end(), chunks.begin(), chunks.end());
  return bytes;
}

TEST(GltfContainer, SplitsAGlb) {
  const std::vector<unsigned char> bytes = glb("{\"asset\":{}}", 16);
  EXPECT_TRUE(isGlb(bytes));
  EXPECT_FALSE(isGlb(std::vector<unsigned char>{'{', '}'}));
  EXPECT_EQ(readU32(bytes.data() + 4), 2u);
  const GlbParts parts = splitGlb("a.glb", bytes);
  EXPECT_EQ(parts.json, "{\"asset\":{}}");
  EXPECT_TRUE(parts.has_bin);
  EXPECT_EQ(parts.bin_size, 16u);
  EXPECT_FALSE(splitGlb("a.glb", glb("{}")).has_bin);
}

TEST(GltfContainer, BrokenGlbsNameTheirPart) {
  auto errorOf = [](const std::vector<unsigned char>& bytes) { return inputErrorOf([&] { splitGlb("a.glb", bytes); }); };
  std::vector<unsigned char> bytes = glb("{}", 8);
  EXPECT_EQ(errorOf({bytes.begin(), bytes.begin() + 8}), "a.glb: glb header: truncated: 8 bytes, a GLB header needs 12");
  std::vector<unsigned char> v1 = bytes;
  v1[4] = 1;
  EXPECT_EQ(errorOf(v1), "a.glb: glb header: version 1 is not supported (expected 2)");
  EXPECT_EQ(errorOf({bytes.begin(), bytes.end() - 1}),
            "a.glb: glb header: truncated: the header says " + std::to_string(bytes.size()) + " bytes, the file has " +
                std::to_string(bytes.size() - 1));
  std::vector<unsigned char> long_json = glb("{}");
  long_json[12] = 200;
  EXPECT_CONTAINS(errorOf(long_json), "a.glb: glb chunk 0: truncated: the JSON chunk of 200 bytes");
  std::vector<unsigned char> long_bin = bytes;
  long_bin[12 + 8 + 2] = 99;
  EXPECT_CONTAINS(errorOf(long_bin), "a.glb: glb chunk 1: truncated: the chunk of 99 bytes");
}

TEST(GltfContainer, JsonAndBuffersAreCheckedBeforeTinygltf) {
  test_support::TempDir dir;
  auto errorOf = [&](const std::string& json, const GlbParts* parts = nullptr) {
    return inputErrorOf([&] { precheckGltfJson("s.gltf", json, dir.path(), parts); });
  };
  EXPECT_CONTAINS(errorOf("{\"asset\": "), "s.gltf: json: ");
  EXPECT_EQ(errorOf("[1]"), "s.gltf: json: the top level is not an object");
  EXPECT_EQ(errorOf("{\"buffers\": [1]}"), "s.gltf: buffers[0]: is not an object");
  EXPECT_EQ(errorOf("{\"buffers\": [{\"byteLength\": -1}]}"), "s.gltf: buffers[0].byteLength: is not a non-negative integer");
  EXPECT_EQ(errorOf("{\"buffers\": [{\"byteLength\": 4, \"uri\": 7}]}"), "s.gltf: buffers[0].uri: is not a string");
  EXPECT_EQ(errorOf("{\"buffers\": [{\"byteLength\": 4, \"uri\": \"b%20c.bin\"}]}"),
            "s.gltf: buffers[0].uri: external buffer file '" + (dir / "b c.bin").string() + "' not found");
  test_support::writeFile(dir / "b c.bin", "abc");
  EXPECT_EQ(errorOf("{\"buffers\": [{\"byteLength\": 4, \"uri\": \"b%20c.bin\"}]}"),
            "s.gltf: buffers[0]: '" + (dir / "b c.bin").string() + "' has 3 bytes, byteLength says 4");
  precheckGltfJson("s.gltf", "{\"buffers\": [{\"byteLength\": 3, \"uri\": \"b%20c.bin\"}]}", dir.path(), nullptr);
  precheckGltfJson("s.gltf", "{\"buffers\": [{\"byteLength\": 3, \"uri\": \"data:application/octet-stream;base64,\"}]}",
                   dir.path(), nullptr);  // embedded: tinygltf's to check

  GlbParts parts;
  EXPECT_EQ(errorOf("{\"buffers\": [{\"byteLength\": 4}]}", &parts),
            "s.gltf: buffers[0]: refers to the GLB binary chunk, which the file lacks");
  parts.has_bin = true;
  parts.bin_size = 2;
  EXPECT_EQ(errorOf("{\"buffers\": [{\"byteLength\": 4}]}", &parts),
            "s.gltf: buffers[0]: byteLength 4 exceeds the GLB binary chunk (2 bytes)");
}

TEST(GltfContainer, ReadsTheWholeFile) {
  test_support::TempDir dir;
  test_support::writeFile(dir / "x.gltf", std::string("a\0b", 3));
  EXPECT_EQ(readGltfBytes(dir / "x.gltf"), (std::vector<unsigned char>{'a', 0, 'b'}));
  EXPECT_EQ(inputErrorOf([&] { readGltfBytes(dir / "none.gltf"); }), (dir / "none.gltf").string() + ": file: cannot be opened");
}

}  // namespace
}  // namespace eik
