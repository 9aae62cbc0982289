#include "voxelize/gltf_accessors.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "core/limits.h"

namespace eik {
namespace {

constexpr std::size_t kMaxElements = std::size_t(1) << 31;

}  // namespace

double readComponent(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto v = static_cast<std::int8_t>(p[0]);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? v / 4294967295.0 : v;
    }
    default:
      return 0.0;
  }
}

std::string componentTypeName(int t) {
  switch (t) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "DOUBLE";
    default: return std::to_string(t);
  }
}

GltfAccessors::GltfAccessors(const tinygltf::Model& model, GltfDiagnostics diag) : model_(model), diag_(std::move(diag)) {}

template <typename T>
std::vector<T> GltfAccessors::read(int index, std::initializer_list<int> types, std::initializer_list<int> component_types,
                                   const std::string& usage, int* components_out) const {
  if (index < 0 || static_cast<std::size_t>(index) >= model_.accessors.size())
    diag_.fail(usage, "accessor " + str(index) + " out of range (the file has " + str(model_.accessors.size()) +
                          " accessors)");
  const tinygltf::Accessor& acc = model_.accessors[static_cast<std::size_t>(index)];
  const std::string field = indexed("accessors", static_cast<std::size_t>(index));
  const int components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(acc.type));
  if (components <= 0 || std::find(types.begin(), types.end(), acc.type) == types.end())
    diag_.fail(field + ".type", "element type " + str(acc.type) + " cannot be used as " + usage);
  const int csize = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(acc.componentType));
  if (csize <= 0 ||
      std::find(component_types.begin(), component_types.end(), acc.componentType) == component_types.end())
    diag_.fail(field + ".componentType", componentTypeName(acc.componentType) + " cannot be used as " + usage);
  const std::size_t element_size = static_cast<std::size_t>(components) * static_cast<std::size_t>(csize);
  const std::size_t count = acc.count;
  if (count > kMaxElements) diag_.fail(field + ".count", str(count) + " elements is more than this program reads");
  if (components_out) *components_out = components;

  // Checked before the values are allocated (a count of 3·10⁸ on a tiny buffer allocated 7 GB before
  // the bounds check refused it): a count backed by a buffer view must fit it; a sparse accessor
  // without one is zeros plus its sparse values, so it must fit in memory.
  const unsigned char* view_data = nullptr;
  std::size_t view_stride = element_size;
  if (acc.bufferView >= 0) {
    const auto [data, view_length, stride] = bufferView(acc.bufferView, field + ".bufferView", element_size);
    if (stride < element_size)
      diag_.fail(indexed("bufferViews", static_cast<std::size_t>(acc.bufferView)) + ".byteStride",
                 str(stride) + " is smaller than the " + str(element_size) + "-byte elements of " + field);
    if (count > 0) {
      const unsigned __int128 need = static_cast<unsigned __int128>(acc.byteOffset) +
                                     static_cast<unsigned __int128>(stride) * (count - 1) + element_size;
      if (need > view_length)
        diag_.fail(field, "reads past the end of bufferViews[" + str(acc.bufferView) + "]: " + str(count) +
                              " elements from byteOffset " + str(acc.byteOffset) + " need " +
                              str(static_cast<std::size_t>(need)) + " bytes, the view has " + str(view_length));
    }
    view_data = data;
    view_stride = stride;
  } else if (!acc.sparse.isSparse && count > 0) {
    diag_.fail(field + ".bufferView", "missing (and the accessor is not sparse)");
  } else if (static_cast<std::uint64_t>(count) * components * sizeof(T) > physicalMemoryBytes()) {
    diag_.fail(field + ".count", str(count) + " elements need more memory than this machine has");
  }
  std::vector<T> values(count * static_cast<std::size_t>(components), T(0));
  auto read = [&](const unsigned char* element, std::size_t i) {
    for (int c = 0; c < components; ++c)
      values[i * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)] =
          static_cast<T>(readComponent(element + static_cast<std::size_t>(c * csize), acc.componentType, acc.normalized));
  };

  if (view_data)
    for (std::size_t i = 0; i < count; ++i) read(view_data + acc.byteOffset + i * view_stride, i);

  if (acc.sparse.isSparse) {
    const std::string sfield = field + ".sparse";
    const int scount = acc.sparse.count;
    if (scount < 0 || static_cast<std::size_t>(scount) > count)
      diag_.fail(sfield + ".count", str(scount) + " is not in [0, " + str(count) + "]");
    const int itype = acc.sparse.indices.componentType;
    const int isize = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(itype));
    if (itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      diag_.fail(sfield + ".indices.componentType", componentTypeName(itype) + " is not an unsigned integer type");
    if (acc.sparse.indices.byteOffset < 0 || acc.sparse.values.byteOffset < 0)
      diag_.fail(sfield, "negative byteOffset");
    const auto [idata, ilength, istride] =
        bufferView(acc.sparse.indices.bufferView, sfield + ".indices.bufferView", static_cast<std::size_t>(isize));
    const auto [vdata, vlength, vstride] =
        bufferView(acc.sparse.values.bufferView, sfield + ".values.bufferView", element_size);
    (void)istride;
    (void)vstride;
    const auto ioff = static_cast<std::size_t>(acc.sparse.indices.byteOffset);
    const auto voff = static_cast<std::size_t>(acc.sparse.values.byteOffset);
    const auto n = static_cast<std::size_t>(scount);
    if (ioff + n * static_cast<std::size_t>(isize) > ilength)
      diag_.fail(sfield + ".indices", "reads past the end of its buffer view");
    if (voff + n * element_size > vlength) diag_.fail(sfield + ".values", "reads past the end of its buffer view");
    for (std::size_t s = 0; s < n; ++s) {
      const auto target = static_cast<std::size_t>(readComponent(idata + ioff + s * static_cast<std::size_t>(isize), itype, false));
      if (target >= count)
        diag_.fail(sfield + ".indices", "index " + str(target) + " is out of range (count " + str(count) + ")");
      read(vdata + voff + s * element_size, target);
    }
  }
  return values;
}

GltfAccessors::ViewBytes GltfAccessors::bufferView(int index, const std::string& usage,
                                                   std::size_t default_stride) const {
  if (index < 0 || static_cast<std::size_t>(index) >= model_.bufferViews.size())
    diag_.fail(usage, "buffer view " + str(index) + " out of range (the file has " + str(model_.bufferViews.size()) +
                          " buffer views)");
  const tinygltf::BufferView& view = model_.bufferViews[static_cast<std::size_t>(index)];
  const std::string field = indexed("bufferViews", static_cast<std::size_t>(index));
  if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model_.buffers.size())
    diag_.fail(field + ".buffer", "buffer " + str(view.buffer) + " out of range (the file has " +
                                      str(model_.buffers.size()) + " buffers)");
  const std::vector<unsigned char>& data = model_.buffers[static_cast<std::size_t>(view.buffer)].data;
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
    diag_.fail(field, "byteOffset " + str(view.byteOffset) + " + byteLength " + str(view.byteLength) +
                          " runs past the end of buffers[" + str(view.buffer) + "] (" + str(data.size()) + " bytes)");
  return {data.data() + view.byteOffset, view.byteLength, view.byteStride ? view.byteStride : default_stride};
}

template std::vector<double> GltfAccessors::read<double>(int, std::initializer_list<int>, std::initializer_list<int>,
                                                         const std::string&, int*) const;
template std::vector<std::uint32_t> GltfAccessors::read<std::uint32_t>(int, std::initializer_list<int>,
                                                                       std::initializer_list<int>, const std::string&,
                                                                       int*) const;

}  // namespace eik
