#include "voxelize/gltf_container.h"

#include <cctype>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_input.h"
#include "core/paths.h"
#include "voxelize/gltf_diagnostics.h"

namespace eik {
namespace {

constexpr std::uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"

// Percent-decoding of a relative URI (tinygltf does the same when it opens the file).
std::string decodeUri(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out.push_back(static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

// Images are not decoded (voxelize reads no texture), but tinygltf opens external image files
// before handing them to the (skipping) image loader: their URIs obey the folder rule too.
void precheckImageUris(const std::string& file, const nlohmann::json& root, const std::filesystem::path& base_dir) {
  auto images = root.find("images");
  if (images == root.end() || !images->is_array()) return;
  for (std::size_t i = 0; i < images->size(); ++i) {
    const nlohmann::json& image = (*images)[i];
    if (!image.is_object()) continue;  // tinygltf reports it
    auto uri = image.find("uri");
    if (uri == image.end() || !uri->is_string()) continue;
    const std::string u = uri->get<std::string>();
    if (u.rfind("data:", 0) != 0) resolveInsideFolder(base_dir, file, indexed("images", i) + ".uri", decodeUri(u));
  }
}

}  // namespace

std::uint32_t readU32(const unsigned char* p) {
  return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16) |
         (std::uint32_t(p[3]) << 24);
}

bool isGlb(const std::vector<unsigned char>& bytes) { return bytes.size() >= 4 && readU32(bytes.data()) == kGlbMagic; }

std::vector<unsigned char> readGltfBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "file", "cannot be opened");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path.string(), "file", "read error");
  return bytes;
}

GlbParts splitGlb(const std::string& file, const std::vector<unsigned char>& bytes) {
  const std::size_t size = bytes.size();
  if (size < 12) throw InputError(file, "glb header", "truncated: " + str(size) + " bytes, a GLB header needs 12");
  if (readU32(bytes.data()) != kGlbMagic) throw InputError(file, "glb header", "not a binary glTF (magic is not 'glTF')");
  if (std::uint32_t version = readU32(bytes.data() + 4); version != 2)
    throw InputError(file, "glb header", "version " + std::to_string(version) + " is not supported (expected 2)");
  const std::size_t length = readU32(bytes.data() + 8);
  if (length > size)
    throw InputError(file, "glb header", "truncated: the header says " + str(length) + " bytes, the file has " + str(size));
  if (length < 20) throw InputError(file, "glb chunk 0", "truncated: no JSON chunk");
  const std::size_t json_length = readU32(bytes.data() + 12);
  if (readU32(bytes.data() + 16) != kGlbChunkJson) throw InputError(file, "glb chunk 0", "the first chunk is not JSON");
  if (json_length > length - 20)
    throw InputError(file, "glb chunk 0",
                     "truncated: the JSON chunk of " + str(json_length) + " bytes runs past the end of the file (" +
                         str(length) + " bytes)");
  GlbParts parts;
  parts.json.assign(reinterpret_cast<const char*>(bytes.data()) + 20, json_length);
  std::size_t offset = 20 + json_length;
  if (offset < length) {
    if (length - offset < 8) throw InputError(file, "glb chunk 1", "truncated chunk header");
    const std::size_t chunk_length = readU32(bytes.data() + offset);
    if (chunk_length > length - offset - 8)
      throw InputError(file, "glb chunk 1",
                       "truncated: the chunk of " + str(chunk_length) + " bytes runs past the end of the file");
    if (readU32(bytes.data() + offset + 4) == kGlbChunkBin) {
      parts.has_bin = true;
      parts.bin_size = chunk_length;
    }
  }
  return parts;
}

void precheckGltfJson(const std::string& file, const std::string& text, const std::filesystem::path& base_dir,
                      const GlbParts* glb) {
  const nlohmann::json root = parseJsonInput(text, file, "json");
  if (!root.is_object()) throw InputError(file, "json", "the top level is not an object");
  precheckImageUris(file, root, base_dir);
  auto buffers = root.find("buffers");
  if (buffers == root.end() || !buffers->is_array()) return;
  for (std::size_t i = 0; i < buffers->size(); ++i) {
    const nlohmann::json& buffer = (*buffers)[i];
    const std::string field = indexed("buffers", i);
    if (!buffer.is_object()) throw InputError(file, field, "is not an object");
    std::size_t byte_length = 0;
    if (auto bl = buffer.find("byteLength"); bl != buffer.end()) {
      if (!bl->is_number_unsigned()) throw InputError(file, field + ".byteLength", "is not a non-negative integer");
      byte_length = bl->get<std::size_t>();
    }
    auto uri = buffer.find("uri");
    if (uri == buffer.end()) {
      if (glb && i == 0) {
        if (!glb->has_bin) throw InputError(file, field, "refers to the GLB binary chunk, which the file lacks");
        if (glb->bin_size < byte_length)
          throw InputError(file, field, "byteLength " + str(byte_length) + " exceeds the GLB binary chunk (" +
                                            str(glb->bin_size) + " bytes)");
      }
      continue;
    }
    if (!uri->is_string()) throw InputError(file, field + ".uri", "is not a string");
    const std::string u = uri->get<std::string>();
    if (u.rfind("data:", 0) == 0) continue;  // embedded; tinygltf decodes and checks it
    const std::filesystem::path external = resolveInsideFolder(base_dir, file, field + ".uri", decodeUri(u));
    std::error_code ec;
    if (!std::filesystem::is_regular_file(external, ec))
      throw InputError(file, field + ".uri", "external buffer file '" + external.string() + "' not found");
    const auto bytes = std::filesystem::file_size(external, ec);
    if (!ec && bytes < byte_length)
      throw InputError(file, field, "'" + external.string() + "' has " + str(static_cast<std::size_t>(bytes)) +
                                        " bytes, byteLength says " + str(byte_length));
  }
}

}  // namespace eik
