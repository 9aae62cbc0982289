// The glTF container, checked before tinygltf sees it (tinygltf trusts it): the file's bytes, the
// GLB header and chunk table against the file size, and the JSON's syntax and buffers (the GLB
// binary chunk, external files and their sizes). Errors are InputErrors naming the file and the
// field ("scene.glb: glb chunk 0: ...").
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace eik {

constexpr std::uint32_t kGlbMagic = 0x46546C67;  // "glTF"

// Little-endian uint32 at `p`.
std::uint32_t readU32(const unsigned char* p);

// Whether `bytes` start with the GLB magic.
bool isGlb(const std::vector<unsigned char>& bytes);

// The whole file; InputError "FILE: file: cannot be opened" / "read error".
std::vector<unsigned char> readGltfBytes(const std::filesystem::path& path);

// What the GLB container holds: the JSON chunk, and the size of the binary chunk if there is one.
struct GlbParts {
  std::string json;
  bool has_bin = false;
  std::size_t bin_size = 0;
};

// The GLB container's parts, its header and chunk table checked against the file size.
GlbParts splitGlb(const std::string& file, const std::vector<unsigned char>& bytes);

// JSON syntax and external buffer files, checked with messages that name the field. `glb`: the
// container the JSON came from (nullptr for a .gltf).
void precheckGltfJson(const std::string& file, const std::string& text, const std::filesystem::path& base_dir,
                      const GlbParts* glb);

}  // namespace eik
