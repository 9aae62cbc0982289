#include "core/image_headers.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <utility>

#include "core/error.h"
#include "core/image_io.h"
#include "core/image_test_bytes.h"
#include "core/testing.h"

namespace eik {
namespace {

namespace fs = std::filesystem;
using test_support::TempDir;
using test_support::writeFile;
using namespace test_support::png;

// OpenEXR's layout, built byte by byte (independent of OpenEXR: what a hostile file would hold).
std::string int32(std::int64_t v) {
  const auto u = static_cast<std::uint32_t>(v);
  return std::string{static_cast<char>(u & 0xff), static_cast<char>(u >> 8 & 0xff), static_cast<char>(u >> 16 & 0xff),
                     static_cast<char>(u >> 24 & 0xff)};
}
std::string attribute(const std::string& name, const std::string& type, const std::string& value) {
  return name + '\0' + type + '\0' + int32(static_cast<std::int64_t>(value.size())) + value;
}
std::string box(std::int64_t x0, std::int64_t y0, std::int64_t x1, std::int64_t y1) {
  return int32(x0) + int32(y0) + int32(x1) + int32(y1);
}
const std::string kMagic = "v/1\x01";
std::string version(std::uint32_t flags = 0) { return int32(2 | flags); }
// A plausible header (what matters to the walk; OpenEXR would want more).
std::string header(const std::string& window = box(0, 0, 7, 3)) {
  return attribute("compression", "compression", std::string(1, '\0')) + attribute("dataWindow", "box2i", window) +
         attribute("displayWindow", "box2i", box(0, 0, 7, 3)) + '\0';
}

// Expects `check` (a header walk) to refuse `bytes`, written to `path`, with a message holding
// `expected` and the file's name.
template <typename Check>
void expectRefusedBy(Check check, const fs::path& path, const std::string& bytes, const std::string& expected) {
  writeFile(path, bytes);
  try {
    check(path);
    ADD_FAILURE() << "accepted; expected a refusal with '" << expected << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path.filename().string()), std::string::npos) << "the file is named: " << e.what();
  }
}

// An image of one value, written by the formats' own libraries (writeImage).
Image flatImage(int width, int height, int channels, float value) {
  Image image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.pixels.assign(static_cast<std::size_t>(width) * height * channels, value);
  return image;
}

void expectRefused(const fs::path& dir, const std::string& bytes, const std::string& expected) {
  expectRefusedBy([](const fs::path& p) { checkExrHeaders(p, kMaxImageAxis); }, dir / "map.exr", bytes, expected);
}

TEST(ExrHeader, AFileOpenExrWroteIsAccepted) {
  TempDir dir("eikonal-exr");
  writeImage(dir.path() / "real.exr", flatImage(5, 3, 4, 0.25f));
  EXPECT_NO_THROW(checkExrHeaders(dir.path() / "real.exr", kMaxImageAxis));
  // And the hand-built header passes the walk (so the refusals below are each one's own fault).
  writeFile(dir.path() / "built.exr", kMagic + version() + header() + std::string(64, '\0'));
  EXPECT_NO_THROW(checkExrHeaders(dir.path() / "built.exr", kMaxImageAxis));
}

TEST(ExrHeader, AnAttributeLargerThanTheFileIsRefusedBeforeOpenExrAllocatesIt) {
  TempDir dir("eikonal-exr");
  // 2 GiB declared in a 100-byte file: OpenEXR 3.1 would allocate it for an unknown type.
  const std::string bomb = std::string("bomb") + '\0' + "opaque" + '\0' + int32(0x7fffffff) + "xyz";
  expectRefused(dir.path(), kMagic + version() + bomb, "bomb: declares 2147483647 bytes of opaque but the file has 3 left");
  expectRefused(dir.path(), kMagic + version() + std::string("neg") + '\0' + "int" + '\0' + int32(-4) + "abcd" + '\0',
                "neg: declares -4 bytes");
  // The same through readImage: refused naming the attribute (not a bare OpenEXR failure after
  // the allocation).
  try {
    readImage(dir.path() / "map.exr");
    ADD_FAILURE() << "readImage accepted a negative attribute size";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("neg: declares -4 bytes"), std::string::npos) << e.what();
  }
}

// Found by fuzz_image (its input is fuzz/corpus/image/found-chlist-runs-past-its-size.exr, replayed
// by every fuzz smoke run): a channel list that declares fewer bytes than its channels take. OpenEXR
// reads a chlist by its contents, not its size, so it went on from another offset than the walk and
// read a string attribute declaring 606 MB, three times (1.8 GB before refusing the file).
TEST(ExrHeader, AValueOpenExrReadsToAnotherLengthThanItsSizeIsRefused) {
  TempDir dir("eikonal-exr");
  const std::string channel = std::string("R") + '\0' + int32(1) + std::string(4, '\0') + int32(1) + int32(1);
  const std::string hidden = attribute("x", "string", std::string(4, 'a'));
  // chlist declares 10 bytes; its one channel and the end take 19.
  const std::string chlist = std::string("channels") + '\0' + "chlist" + '\0' + int32(10) + channel + '\0' + hidden;
  expectRefused(dir.path(), kMagic + version() + chlist + header(), "channels: chlist value: a channel runs past the value");
  // The other way: the list ends before its declared size.
  expectRefused(dir.path(), kMagic + version() + attribute("channels", "chlist", channel + '\0' + "xyz") + header(),
                "the channel list ends before its declared size");
  expectRefused(dir.path(), kMagic + version() + attribute("compression", "compression", std::string(5, '\0')) + header(),
                "compression: compression value: declares 5 bytes where the type has 1");
  // A preview of 65535² (16 GiB for OpenEXR to allocate) in 12 bytes.
  expectRefused(dir.path(), kMagic + version() + attribute("preview", "preview", int32(65535) + int32(65535) + "abcd") + header(),
                "preview value: 65535x65535 pixels in 12 bytes");
  expectRefused(dir.path(), kMagic + version() + attribute("names", "stringvector", int32(0x7fffffff) + "ab") + header(),
                "stringvector value: a string of 2147483647 bytes runs past the value");
  // Values that are what they declare pass.
  writeFile(dir.path() / "ok.exr", kMagic + version() + attribute("channels", "chlist", channel + '\0') +
                                       attribute("preview", "preview", int32(1) + int32(2) + std::string(8, 'p')) +
                                       attribute("names", "stringvector", int32(2) + "ab" + int32(0)) + header() +
                                       std::string(16, '\0'));
  EXPECT_NO_THROW(checkExrHeaders(dir.path() / "ok.exr", kMaxImageAxis));
}

// The two inputs fuzz_image found, as it found them, through readImage (as the viewer reads an
// environment map): refused by the walks, before OpenEXR or libpng allocate.
TEST(ImageHeaders, TheFuzzFindingsAreRefusedByTheWalks) {
  const fs::path corpus = fs::path(EIKONAL_SOURCE_DIR) / "fuzz" / "corpus" / "image";
  const std::pair<const char*, const char*> findings[] = {
      {"found-chlist-runs-past-its-size.exr", "channels: chlist value: a channel runs past the value"},
      {"found-png-chunk-longer-than-file.png", "chunk tEXt: declares 1634886912 bytes but the file has 148 left"}};
  for (const auto& [name, expected] : findings) {
    try {
      readImage(corpus / name);
      ADD_FAILURE() << name << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << name << ": " << e.what();
    }
  }
}

TEST(ExrHeader, ADataWindowOrTilesOverTheLimitAreRefused) {
  TempDir dir("eikonal-exr");
  expectRefused(dir.path(), kMagic + version() + header(box(0, 0, 32767, 0)) + std::string(8, '\0'),
                "dataWindow: 32768x1 pixels (at most 16384 an axis)");
  // Extents computed in 64 bits: xMax − xMin + 1 overflows 32 bits here.
  expectRefused(dir.path(), kMagic + version() + header(box(-2147483647 - 1, 0, 2147483647, 0)),
                "dataWindow: 4294967296x1 pixels");
  expectRefused(dir.path(), kMagic + version() + header(box(5, 0, 3, 0)), "dataWindow: -1x1 pixels");
  const std::string tiles = attribute("tiles", "tiledesc", int32(0) + int32(16) + std::string(1, '\0'));
  expectRefused(dir.path(), kMagic + version(0x200) + tiles + header(), "tiles: tiles of 0x16 pixels");
  const std::string big_tiles = attribute("tiles", "tiledesc", int32(1 << 20) + int32(16) + std::string(1, '\0'));
  expectRefused(dir.path(), kMagic + version(0x200) + big_tiles + header(), "tiles: tiles of 1048576x16 pixels");
}

TEST(ExrHeader, EveryPartOfAMultiPartFileIsWalked) {
  TempDir dir("eikonal-exr");
  const std::string second = attribute("name", "string", "b") + header(box(0, 0, 0, 99999));
  expectRefused(dir.path(), kMagic + version(0x1000) + attribute("name", "string", "a") + header() + second + '\0',
                "dataWindow: 1x100000 pixels");
  // Two good parts and the empty header that ends the list.
  writeFile(dir.path() / "two.exr", kMagic + version(0x1000) + header() + header() + '\0' + std::string(16, '\0'));
  EXPECT_NO_THROW(checkExrHeaders(dir.path() / "two.exr", kMaxImageAxis));
}

TEST(ExrHeader, TruncatedOrForeignFilesAreRefused) {
  TempDir dir("eikonal-exr");
  expectRefused(dir.path(), "\x89PNG\r\n\x1a\n", "not an OpenEXR file");
  expectRefused(dir.path(), kMagic + int32(1), "version: OpenEXR version 1");
  expectRefused(dir.path(), kMagic + version() + header().substr(0, 20), "the file ends inside the header");
  expectRefused(dir.path(), kMagic + version() + std::string(300, 'a'), "a name longer than 255 bytes");
  expectRefused(dir.path(), kMagic, "version: the file ends inside the header");
}

const std::string kIhdr = chunk("IHDR", bigEndian(4) + bigEndian(4) + std::string{8, 2, 0, 0, 0});

void expectPngRefused(const fs::path& dir, const std::string& bytes, const std::string& expected) {
  expectRefusedBy([](const fs::path& p) { checkPngChunks(p); }, dir / "map.png", bytes, expected);
}

TEST(PngChunks, AFileLibpngWroteIsAccepted) {
  TempDir dir("eikonal-png");
  writeImage(dir.path() / "real.png", flatImage(5, 3, 3, 0.5f));
  EXPECT_NO_THROW(checkPngChunks(dir.path() / "real.png"));
  // Hand-built chunks, a text that inflates to 1 MB among them, pass (the refusals below are each
  // one's own fault).
  writeFile(dir.path() / "built.png", kPngSignature + kIhdr +
                                          chunk("zTXt", std::string("Comment") + '\0' + '\0' + deflated(std::string(1 << 20, 'z'))) +
                                          chunk("IDAT", "xx") + chunk("IEND", ""));
  EXPECT_NO_THROW(checkPngChunks(dir.path() / "built.png"));
}

// Found by fuzz_image: a 300-byte PNG with a chunk declaring 1.6 GB, which libpng allocated.
TEST(PngChunks, AChunkLongerThanTheFileIsRefusedBeforeLibpngAllocatesIt) {
  TempDir dir("eikonal-png");
  expectPngRefused(dir.path(), kPngSignature + kIhdr + bigEndian(1634886913) + "tEXt" + "abc",
                   "chunk tEXt: declares 1634886913 bytes but the file has 0 left");
  expectPngRefused(dir.path(), kPngSignature + bigEndian(0x80000000u) + "IDAT" + std::string(16, 'x'),
                   "chunk IDAT: declares 2147483648 bytes");
  // A chunk of the right length but no room left for its CRC.
  expectPngRefused(dir.path(), kPngSignature + bigEndian(4) + "IDAT" + "abcd", "chunk IDAT: declares 4 bytes but the file has 0 left");
  expectPngRefused(dir.path(), "v/1\x01 not a png", "not a PNG file");
}

TEST(PngChunks, CompressedTextOrProfilesThatInflateTooFarAreRefused) {
  TempDir dir("eikonal-png");
  // 64 MB of zeros deflate to about 64 KB: the bomb libpng would inflate without a bound.
  const std::string bomb = deflated(std::string(64u << 20, '\0'));
  ASSERT_LT(bomb.size(), 100000u);
  expectPngRefused(dir.path(), kPngSignature + kIhdr + chunk("zTXt", std::string("k") + '\0' + '\0' + bomb),
                   "chunk zTXt: inflates to more than 8000000 bytes");
  expectPngRefused(dir.path(), kPngSignature + kIhdr + chunk("iCCP", std::string("icc") + '\0' + '\0' + bomb),
                   "chunk iCCP: inflates to more than 8000000 bytes");
  expectPngRefused(dir.path(), kPngSignature + kIhdr + chunk("iTXt", std::string("k") + '\0' + '\1' + '\0' + "en" + '\0' + '\0' + bomb),
                   "chunk iTXt: inflates to more than 8000000 bytes");
  // An uncompressed iTXt of the same bytes is not inflated.
  writeFile(dir.path() / "plain.png", kPngSignature + kIhdr + chunk("iTXt", std::string("k") + '\0' + '\0' + '\0' + "en" + '\0' + '\0' + bomb) + chunk("IEND", ""));
  EXPECT_NO_THROW(checkPngChunks(dir.path() / "plain.png"));
}

}  // namespace
}  // namespace eik
