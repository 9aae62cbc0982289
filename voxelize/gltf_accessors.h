// Reading glTF accessors for the loader (gltf_loader.h): every accessor (component type, element
// type, count, stride, offsets, sparse parts) is validated against its buffer view and buffer before
// a byte is read; errors are InputErrors naming the glTF field ("scene.gltf: accessors[2]: ...").
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "voxelize/gltf_diagnostics.h"

namespace tinygltf {
class Model;
}

namespace eik {

// One component of glTF type `component_type` (TINYGLTF_COMPONENT_TYPE_*) at `p`; a normalized
// integer maps to [0, 1] (unsigned) or [−1, 1] (signed).
double readComponent(const unsigned char* p, int component_type, bool normalized);

// "FLOAT", "UNSIGNED_SHORT", ... for messages.
std::string componentTypeName(int t);

class GltfAccessors {
 public:
  GltfAccessors(const tinygltf::Model& model, GltfDiagnostics diag);

  // Reads accessor `index` into `components` values per element, after checking everything the
  // read relies on: the element type must be one of `types` (TINYGLTF_TYPE_*), the component type
  // one of `component_types`. `usage` says what it is for, in messages. T is double or
  // std::uint32_t.
  template <typename T>
  std::vector<T> read(int index, std::initializer_list<int> types, std::initializer_list<int> component_types,
                      const std::string& usage, int* components_out = nullptr) const;

 private:
  struct ViewBytes {
    const unsigned char* data;
    std::size_t length;
    std::size_t stride;
  };

  ViewBytes bufferView(int index, const std::string& usage, std::size_t default_stride) const;

  const tinygltf::Model& model_;
  GltfDiagnostics diag_;
};

extern template std::vector<double> GltfAccessors::read<double>(int, std::initializer_list<int>,
                                                                std::initializer_list<int>, const std::string&,
                                                                int*) const;
extern template std::vector<std::uint32_t> GltfAccessors::read<std::uint32_t>(int, std::initializer_list<int>,
                                                                              std::initializer_list<int>,
                                                                              const std::string&, int*) const;

}  // namespace eik
