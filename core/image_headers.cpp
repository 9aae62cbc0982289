#include "core/image_headers.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <string>
#include <utility>

#include "core/error.h"

#include <zlib.h>

namespace eik {
namespace {

constexpr std::uint32_t kVersionMask = 0xff;
constexpr std::uint32_t kMultiPartFlag = 0x1000;  // bit 12: several headers, ended by an empty one
constexpr std::size_t kMaxNameBytes = 255;        // with the long-names flag (bit 10); 31 without

// The file as a byte stream with its remaining length known (every declared size is checked
// against it before a byte of the value is skipped).
class FileBytes {
 public:
  explicit FileBytes(const std::filesystem::path& path) : path_(path.string()), in_(path, std::ios::binary) {
    if (!in_) throw InputError(path_, "", "cannot open the file");
    in_.seekg(0, std::ios::end);
    remaining_ = static_cast<std::uint64_t>(in_.tellg());
    in_.seekg(0);
  }

  std::uint64_t remaining() const { return remaining_; }
  const std::string& path() const { return path_; }

  void read(void* out, std::size_t n, const std::string& what) {
    if (n > remaining_ || !in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n)))
      throw InputError(path_, what, "the file ends inside the header");
    remaining_ -= n;
  }
  std::int32_t int32(const std::string& what) {
    std::array<unsigned char, 4> b{};
    read(b.data(), 4, what);
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
                                     static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24);
  }
  // A zero-terminated string of at most kMaxNameBytes bytes (empty: the end of a header).
  std::string name(const std::string& what) {
    std::string s;
    for (;;) {
      char c = 0;
      read(&c, 1, what);
      if (c == '\0') return s;
      if (s.size() == kMaxNameBytes)
        throw InputError(path_, what, "a name longer than " + std::to_string(kMaxNameBytes) + " bytes");
      s.push_back(c);
    }
  }
 private:
  std::string path_;
  std::ifstream in_;
  std::uint64_t remaining_ = 0;
};

std::int64_t int32At(const std::string& v, std::size_t at) {
  const auto b = [&](std::size_t i) { return static_cast<std::uint32_t>(static_cast<unsigned char>(v[at + i])); };
  return static_cast<std::int32_t>(b(0) | b(1) << 8 | b(2) << 16 | b(3) << 24);
}
std::int64_t uint32At(const std::string& v, std::size_t at) { return static_cast<std::uint32_t>(int32At(v, at)); }

// The bytes OpenEXR 3.1 reads for a value of a type with a fixed layout (it reads these whatever
// size the attribute declares, so a declared size that differs would set its reading and ours
// apart: the next attribute it reads is not the one walked here).
std::size_t fixedSize(const std::string& type) {
  static const std::pair<const char*, std::size_t> kTypes[] = {
      {"box2i", 16}, {"box2f", 16}, {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1},
      {"double", 8}, {"envmap", 1}, {"float", 4}, {"int", 4}, {"keycode", 28}, {"lineOrder", 1},
      {"m33f", 36}, {"m33d", 72}, {"m44f", 64}, {"m44d", 128}, {"rational", 8}, {"tiledesc", 9},
      {"timecode", 8}, {"v2i", 8}, {"v2f", 8}, {"v2d", 16}, {"v3i", 12}, {"v3f", 12}, {"v3d", 24}};
  for (const auto& [name, size] : kTypes)
    if (type == name) return size;
  return 0;
}

// The value of an attribute whose reading OpenEXR does not take from its declared size alone:
// refused unless OpenEXR would read exactly `value.size()` bytes, allocating no more than that.
void checkValue(const std::string& path, const std::string& name, const std::string& type, const std::string& value,
                int max_axis) {
  const auto refuse = [&](const std::string& why) { throw InputError(path, name, type + " value: " + why); };
  if (const std::size_t fixed = fixedSize(type)) {
    if (value.size() != fixed)
      refuse("declares " + std::to_string(value.size()) + " bytes where the type has " + std::to_string(fixed));
  } else if (type == "chlist") {  // channels until an empty name: name, then 16 bytes each
    std::size_t at = 0;
    for (;;) {
      const std::size_t end = value.find('\0', at);
      if (end == std::string::npos || end - at > kMaxNameBytes) refuse("a channel name runs past the value");
      if (end == at) {
        if (end + 1 != value.size()) refuse("the channel list ends before its declared size");
        break;
      }
      at = end + 1 + 16;
      if (at > value.size()) refuse("a channel runs past the value");
    }
  } else if (type == "preview") {  // width, height, then width·height RGBA bytes
    if (value.size() < 8) refuse("shorter than its width and height");
    const std::int64_t width = uint32At(value, 0), height = uint32At(value, 4);
    if (width > max_axis || height > max_axis || 8 + 4 * width * height != static_cast<std::int64_t>(value.size()))
      refuse(std::to_string(width) + "x" + std::to_string(height) + " pixels in " + std::to_string(value.size()) + " bytes");
  } else if (type == "stringvector") {  // strings, each its length then its bytes
    std::size_t at = 0;
    while (at < value.size()) {
      if (value.size() - at < 4) refuse("a string's length runs past the value");
      const std::int64_t length = int32At(value, at);
      if (length < 0 || static_cast<std::uint64_t>(length) > value.size() - at - 4)
        refuse("a string of " + std::to_string(length) + " bytes runs past the value");
      at += 4 + static_cast<std::size_t>(length);
    }
  } else if (type == "idmanifest") {
    refuse("not read (no map needs one)");
  }
  // Anything else (string, floatvector, a type OpenEXR does not know): read by its declared size.
  if (name == "dataWindow" && type == "box2i") {
    const std::int64_t width = int32At(value, 8) - int32At(value, 0) + 1, height = int32At(value, 12) - int32At(value, 4) + 1;
    if (width <= 0 || height <= 0 || width > max_axis || height > max_axis)
      throw InputError(path, name,
                       std::to_string(width) + "x" + std::to_string(height) + " pixels (at most " +
                           std::to_string(max_axis) + " an axis)");
  } else if (name == "tiles" && type == "tiledesc") {
    const std::int64_t x_size = uint32At(value, 0), y_size = uint32At(value, 4);
    if (x_size <= 0 || y_size <= 0 || x_size > max_axis || y_size > max_axis)
      throw InputError(path, name,
                       "tiles of " + std::to_string(x_size) + "x" + std::to_string(y_size) + " pixels (at most " +
                           std::to_string(max_axis) + " an axis)");
  }
}

// One header's attributes, up to its terminating zero byte. False when the header is empty (the
// end of a multi-part file's header list).
bool walkHeader(FileBytes& bytes, int max_axis) {
  bool any = false;
  for (;;) {
    const std::string name = bytes.name("header");
    if (name.empty()) return any;
    any = true;
    const std::string type = bytes.name(name);
    const std::int32_t size = bytes.int32(name);
    if (size < 0 || static_cast<std::uint64_t>(size) > bytes.remaining())
      throw InputError(bytes.path(), name,
                       "declares " + std::to_string(size) + " bytes of " + type + " but the file has " +
                           std::to_string(bytes.remaining()) + " left");
    std::string value(static_cast<std::size_t>(size), '\0');
    bytes.read(value.data(), value.size(), name);
    checkValue(bytes.path(), name, type, value, max_axis);
  }
}

std::uint32_t bigEndian32(const unsigned char* b) {
  return static_cast<std::uint32_t>(b[0]) << 24 | static_cast<std::uint32_t>(b[1]) << 16 |
         static_cast<std::uint32_t>(b[2]) << 8 | static_cast<std::uint32_t>(b[3]);
}

// The size zlib data inflates to, counted without keeping it, up to `limit` + 1 bytes; data zlib
// cannot inflate counts what came out before the error (libpng reports the rest).
std::uint64_t inflatedSize(const std::string& compressed, std::uint64_t limit) {
  z_stream z{};
  if (inflateInit(&z) != Z_OK) throw RuntimeError("zlib: inflateInit failed");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  z.avail_in = static_cast<uInt>(compressed.size());
  unsigned char scratch[16384];
  std::uint64_t total = 0;
  for (;;) {
    z.next_out = scratch;
    z.avail_out = sizeof scratch;
    const int status = inflate(&z, Z_NO_FLUSH);
    total += sizeof scratch - z.avail_out;
    if (status != Z_OK || total > limit || (z.avail_in == 0 && z.avail_out != 0)) break;
  }
  inflateEnd(&z);
  return total;
}

// The compressed part of a zTXt, iCCP or iTXt chunk's data, or nothing (not compressed, or too
// malformed for libpng to inflate it: it refuses those itself).
std::string compressedPart(const std::string& type, const std::string& data) {
  const std::size_t keyword_end = data.find('\0');
  if (keyword_end == std::string::npos) return {};
  if (type == "zTXt" || type == "iCCP") return keyword_end + 2 <= data.size() ? data.substr(keyword_end + 2) : std::string();
  // iTXt: keyword, compression flag, method, language tag, translated keyword, text.
  if (keyword_end + 3 > data.size() || data[keyword_end + 1] == 0) return {};
  const std::size_t language_end = data.find('\0', keyword_end + 3);
  if (language_end == std::string::npos) return {};
  const std::size_t translated_end = data.find('\0', language_end + 1);
  return translated_end == std::string::npos ? std::string() : data.substr(translated_end + 1);
}

}  // namespace

void checkPngChunks(const std::filesystem::path& path, std::uint64_t max_inflated_bytes) {
  FileBytes bytes(path);
  unsigned char signature[8];
  bytes.read(signature, 8, "signature");
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!std::equal(signature, signature + 8, kSignature))
    throw InputError(path.string(), "", "not a PNG file (its first bytes are not the PNG signature)");
  // Chunks: length (big-endian), type, data, CRC, up to IEND. A file that ends early is left to
  // libpng, which reads what is there and says what is missing.
  while (bytes.remaining() >= 8) {
    unsigned char head[8];
    bytes.read(head, 8, "chunk");
    const std::uint32_t length = bigEndian32(head);
    std::string type(reinterpret_cast<const char*>(head + 4), 4);
    for (char& c : type)
      if (!std::isalpha(static_cast<unsigned char>(c))) c = '?';
    if (length > 0x7fffffffu || std::uint64_t{length} + 4 > bytes.remaining())
      throw InputError(path.string(), "chunk " + type,
                       "declares " + std::to_string(length) + " bytes but the file has " +
                           std::to_string(bytes.remaining() >= 4 ? bytes.remaining() - 4 : 0) + " left");
    std::string data(length, '\0');
    bytes.read(data.data(), length, "chunk " + type);
    bytes.read(head, 4, "chunk " + type);  // CRC (libpng checks it)
    if (type == "zTXt" || type == "iCCP" || type == "iTXt") {
      const std::string compressed = compressedPart(type, data);
      if (!compressed.empty() && inflatedSize(compressed, max_inflated_bytes) > max_inflated_bytes)
        throw InputError(path.string(), "chunk " + type,
                         "inflates to more than " + std::to_string(max_inflated_bytes) + " bytes");
    }
    if (type == "IEND") break;
  }
}

void checkExrHeaders(const std::filesystem::path& path, int max_axis) {
  FileBytes bytes(path);
  std::array<unsigned char, 4> magic{};
  bytes.read(magic.data(), 4, "magic");
  if (magic != std::array<unsigned char, 4>{0x76, 0x2f, 0x31, 0x01})
    throw InputError(path.string(), "", "not an OpenEXR file (its first bytes are not the OpenEXR magic)");
  const auto version = static_cast<std::uint32_t>(bytes.int32("version"));
  if ((version & kVersionMask) != 2)
    throw InputError(path.string(), "version", "OpenEXR version " + std::to_string(version & kVersionMask) + " (only 2 exists)");
  if (!(version & kMultiPartFlag)) {
    if (!walkHeader(bytes, max_axis)) throw InputError(path.string(), "header", "the header has no attributes");
    return;
  }
  while (walkHeader(bytes, max_axis)) {
  }
}

}  // namespace eik
