// Test support (header-only, tests only): PNG files built byte by byte, independent of libpng —
// what a hostile file would hold, or a known image in a layout the test chooses.
#pragma once

#include <zlib.h>

#include <cstdint>
#include <stdexcept>
#include <string>

namespace eik::test_support::png {

inline std::string bigEndian(std::uint32_t v) {
  return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16 & 0xff), static_cast<char>(v >> 8 & 0xff),
                     static_cast<char>(v & 0xff)};
}

// A chunk: its big-endian length, its type, its data and the CRC-32 of type and data.
inline std::string chunk(const std::string& type, const std::string& data) {
  const std::string body = type + data;
  const auto crc = static_cast<std::uint32_t>(
      crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size())));
  return bigEndian(static_cast<std::uint32_t>(data.size())) + body + bigEndian(crc);
}

inline const std::string kPngSignature = "\x89PNG\r\n\x1a\n";

// zlib's deflate of `data` (a PNG's IDAT and compressed text hold zlib streams).
inline std::string deflated(const std::string& data) {
  uLongf size = compressBound(static_cast<uLong>(data.size()));
  std::string out(size, '\0');
  if (compress(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(data.data()),
               static_cast<uLong>(data.size())) != Z_OK)
    throw std::runtime_error("compress failed");
  out.resize(size);
  return out;
}

}  // namespace eik::test_support::png
