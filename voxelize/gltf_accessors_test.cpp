// glTF accessors read from an in-memory model: component types, normalisation, strides, sparse
// substitution, and every out-of-range read refused with the field named.
#include "voxelize/gltf_accessors.h"

#include <tiny_gltf.h>

#include <gtest/gtest.h>

#include <cstdlib>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/testing.h"

namespace eik {
namespace {

using test_support::inputErrorOf;

// A model with one buffer holding `bytes` in one view (stride `stride`, 0: tightly packed).
tinygltf::Model modelWith(const std::vector<unsigned char>& bytes, std::size_t stride = 0) {
  tinygltf::Model model;
  tinygltf::Buffer buffer;
  buffer.data = bytes;
  model.buffers.push_back(buffer);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = 0;
  view.byteLength = bytes.size();
  view.byteStride = stride;
  model.bufferViews.push_back(view);
  return model;
}

tinygltf::Accessor accessor(int component_type, int type, std::size_t count, std::size_t offset = 0) {
  tinygltf::Accessor a;
  a.bufferView = 0;
  a.byteOffset = offset;
  a.componentType = component_type;
  a.type = type;
  a.count = count;
  return a;
}

template <typename T>
std::vector<unsigned char> bytesOf(const std::vector<T>& values) {
  std::vector<unsigned char> bytes(values.size() * sizeof(T));
  std::memcpy(bytes.data(), values.data(), bytes.size());
  return bytes;
}

TEST(GltfAccessors, ComponentsAndTheirNames) {
  const unsigned char b[4] = {0x81, 0xff, 0x00, 0x80};
  EXPECT_EQ(readComponent(b, TINYGLTF_COMPONENT_TYPE_BYTE, false), -127.0);
  EXPECT_EQ(readComponent(b, TINYGLTF_COMPONENT_TYPE_BYTE, true), -1.0);
  EXPECT_EQ(readComponent(b + 1, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true), 1.0);
  EXPECT_EQ(readComponent(b + 2, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false), 32768.0);
  EXPECT_EQ(readComponent(b, TINYGLTF_COMPONENT_TYPE_DOUBLE, false), 0.0) << "not a glTF vertex type";
  EXPECT_EQ(componentTypeName(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT), "UNSIGNED_SHORT");
  EXPECT_EQ(componentTypeName(TINYGLTF_COMPONENT_TYPE_FLOAT), "FLOAT");
  EXPECT_EQ(componentTypeName(1), "1");
}

TEST(GltfAccessors, ReadsStridedAndSparseData) {
  // Two VEC3 floats, 16 bytes apart (a padding float after each).
  tinygltf::Model model = modelWith(bytesOf(std::vector<float>{1, 2, 3, -9, 4, 5, 6, -9}), 16);
  model.accessors.push_back(accessor(TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 2));
  std::vector<std::string> warnings;
  const GltfAccessors accessors(model, {"m.gltf", &warnings});
  int components = 0;
  EXPECT_EQ(accessors.read<double>(0, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, "POSITION", &components),
            (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(components, 3);

  // Scalars 10, 20, 30 with element 1 replaced sparsely by 99 (indices and values after them).
  tinygltf::Model sparse = modelWith(bytesOf(std::vector<std::uint32_t>{10, 20, 30, 1, 99}));
  tinygltf::Accessor a = accessor(TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, 3);
  a.sparse.isSparse = true;
  a.sparse.count = 1;
  a.sparse.indices.bufferView = 0;
  a.sparse.indices.byteOffset = 12;
  a.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  a.sparse.values.bufferView = 0;
  a.sparse.values.byteOffset = 16;
  sparse.accessors.push_back(a);
  const GltfAccessors sparse_accessors(sparse, {"m.gltf", &warnings});
  EXPECT_EQ(sparse_accessors.read<std::uint32_t>(0, {TINYGLTF_TYPE_SCALAR}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT}, "indices"),
            (std::vector<std::uint32_t>{10, 99, 30}));
  EXPECT_TRUE(warnings.empty());
}

TEST(GltfAccessors, RefusesEveryReadItCannotCheck) {
  tinygltf::Model model = modelWith(bytesOf(std::vector<float>{1, 2, 3, 4, 5, 6}));
  model.accessors.push_back(accessor(TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 3));       // 36 bytes of 24
  model.accessors.push_back(accessor(TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, 1));
  model.accessors.push_back(accessor(TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_TYPE_VEC3, 1));
  model.accessors.push_back(accessor(TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 1));
  model.accessors.back().bufferView = 5;
  std::vector<std::string> warnings;
  const GltfAccessors accessors(model, {"m.gltf", &warnings});
  auto errorOf = [&](int index) {
    return inputErrorOf([&] {
      accessors.read<double>(index, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, "POSITION");
    });
  };
  EXPECT_EQ(errorOf(0), "m.gltf: accessors[0]: reads past the end of bufferViews[0]: 3 elements from byteOffset 0 need "
                        "36 bytes, the view has 24");
  EXPECT_EQ(errorOf(1), "m.gltf: accessors[1].type: element type 2 cannot be used as POSITION");
  EXPECT_EQ(errorOf(2), "m.gltf: accessors[2].componentType: SHORT cannot be used as POSITION");
  EXPECT_EQ(errorOf(3), "m.gltf: accessors[3].bufferView: buffer view 5 out of range (the file has 1 buffer views)");
  EXPECT_EQ(errorOf(4), "m.gltf: POSITION: accessor 4 out of range (the file has 4 accessors)");
}

// A huge count on a tiny buffer is refused by the bounds check before any value is allocated: 2·10⁹
// VEC3 elements as doubles would be 48 GB (the check used to come after the allocation, which
// failed with a bare "out of memory" or took 7 GB for a count of 3·10⁸). A sparse accessor without
// a buffer view that would need more memory than the machine has is refused alike.
TEST(GltfAccessors, HugeCountsAreRefusedBeforeAllocating) {
  tinygltf::Model model = modelWith(bytesOf(std::vector<float>{1, 2, 3, 4, 5, 6}));
  model.accessors.push_back(accessor(TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 2'000'000'000));
  tinygltf::Accessor sparse = accessor(TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 2'000'000'000);
  sparse.bufferView = -1;
  sparse.sparse.isSparse = true;
  sparse.sparse.count = 0;
  model.accessors.push_back(sparse);
  std::vector<std::string> warnings;
  const GltfAccessors accessors(model, {"m.gltf", &warnings});
  auto errorOf = [&](int index) {
    return inputErrorOf([&] {
      accessors.read<double>(index, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, "POSITION");
    });
  };
  EXPECT_NE(errorOf(0).find("m.gltf: accessors[0]: reads past the end of bufferViews[0]: 2000000000 elements"),
            std::string::npos);
  ::setenv("EIKONAL_MEMORY_LIMIT_BYTES", "1000000000", 1);  // 1 GB, whatever this machine has
  EXPECT_EQ(errorOf(1), "m.gltf: accessors[1].count: 2000000000 elements need more memory than this machine has");
  ::unsetenv("EIKONAL_MEMORY_LIMIT_BYTES");
}

}  // namespace
}  // namespace eik
