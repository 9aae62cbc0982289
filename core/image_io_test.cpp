#include "core/image_io.h"

#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image_test_bytes.h"
#include "core/testing.h"

namespace eik {
namespace {

namespace fs = std::filesystem;
using test_support::inputErrorOf;
using test_support::readFile;
using test_support::TempDir;
using test_support::writeFile;
using namespace test_support::png;

// The sRGB transfer function's inverse (IEC 61966-2-1), in double: the reference for PNG reads.
double srgbToLinear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

Image gradient(int width, int height, int channels) {
  Image image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.pixels.resize(static_cast<std::size_t>(width) * height * channels);
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = 0.001f * std::pow(1.37f, static_cast<float>(i % 37));  // 0.001 … 84
  return image;
}

// A PNG of one IDAT holding `rows` (each row's filter byte 0, then its samples), with `extra`
// chunks between IHDR and IDAT.
std::string pngFile(std::uint32_t width, std::uint32_t height, int depth, int colour_type, const std::string& rows,
                    const std::string& extra = "") {
  const std::string ihdr = bigEndian(width) + bigEndian(height) +
                           std::string{static_cast<char>(depth), static_cast<char>(colour_type), 0, 0, 0};
  return kPngSignature + chunk("IHDR", ihdr) + extra + chunk("IDAT", deflated(rows)) + chunk("IEND", "");
}

TEST(ImageIo, ExrKeepsLinearValuesToHalfPrecision) {
  TempDir dir("eikonal-image");
  for (int channels : {1, 3, 4}) {
    const Image written = gradient(7, 5, channels);
    writeImage(dir.path() / "a.exr", written);
    const Image read = readImage(dir.path() / "a.exr");
    ASSERT_EQ(read.width, 7);
    ASSERT_EQ(read.height, 5);
    ASSERT_EQ(read.channels, channels);
    // Half floats keep 11 significant bits: rounding to nearest is within 2⁻¹¹ of the value (all
    // written values are normal halves, 0.001 to 84).
    for (std::size_t i = 0; i < written.pixels.size(); ++i)
      EXPECT_NEAR(read.pixels[i], written.pixels[i], written.pixels[i] * 0x1p-11f) << channels << " channels, sample " << i;
  }
}

// OpenEXR files as other programs write them: a 32-bit float Y channel (kept as float, beyond
// half's range) in a data window away from the origin; the window's first pixel is the image's.
TEST(ImageIo, ExrFloatChannelsAndDataWindowsAreRead) {
  TempDir dir("eikonal-image");
  const Imath::Box2i window(Imath::V2i(5, 7), Imath::V2i(7, 8));  // 3 × 2
  Imf::Header header(Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(9, 9)), window);
  header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
  const std::vector<float> values = {1e6f, 2.5f, 3.0f, 1e-7f, 70000.0f, 0.125f};
  {
    Imf::OutputFile file((dir.path() / "y.exr").c_str(), header);
    Imf::FrameBuffer frame;
    frame.insert("Y", Imf::Slice::Make(Imf::FLOAT, values.data(), window));
    file.setFrameBuffer(frame);
    file.writePixels(2);
  }
  const Image read = readImage(dir.path() / "y.exr");
  ASSERT_EQ(read.width, 3);
  ASSERT_EQ(read.height, 2);
  ASSERT_EQ(read.channels, 1);
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(read.pixels[i], values[i]) << i;
}

// The fuzz seeds: the same 8 × 4 image with every compression and as tiles (the tiled one 8 × 8
// RGBA), read by the one reader to the same values.
TEST(ImageIo, ExrOfEveryCompressionReadsTheSame) {
  const fs::path corpus = fs::path(EIKONAL_SOURCE_DIR) / "fuzz" / "corpus" / "image";
  const Image none = readImage(corpus / "none.exr");
  ASSERT_EQ(none.width, 8);
  ASSERT_EQ(none.height, 4);
  ASSERT_EQ(none.channels, 3);
  float largest = 0.0f;
  for (float v : none.pixels) largest = std::max(largest, v);
  EXPECT_GT(largest, 0.0f);
  for (const char* name : {"zip.exr", "piz.exr", "rle.exr"}) {
    const Image other = readImage(corpus / name);
    EXPECT_EQ(other.pixels, none.pixels) << name;  // lossless compressions: the same bits
  }
  const Image tiled = readImage(corpus / "tiled.exr");
  EXPECT_EQ(tiled.channels, 4);
}

TEST(ImageIo, PngHoldsTheToneMappedDisplayValues) {
  TempDir dir("eikonal-image");
  const Image written = gradient(6, 4, 4);
  ImageWriteOptions options;
  options.exposure_ev = -3.0f;
  options.tonemap = ToneMapper::Reinhard;
  writeImage(dir.path() / "a.png", written, options);
  const Image read = readImage(dir.path() / "a.png");
  ASSERT_EQ(read.channels, 3);  // RGB: alpha is not written
  for (std::size_t p = 0; p < 24; ++p) {
    const float* in = written.pixels.data() + 4 * p;
    const glm::vec3 display = toDisplay(glm::vec3(in[0], in[1], in[2]), options.exposure_ev, options.tonemap);
    for (int c = 0; c < 3; ++c) {
      // The 8-bit code nearest the display value, decoded: exact but for float rounding (1e-6).
      const double code = std::round(std::clamp(static_cast<double>(display[c]), 0.0, 1.0) * 255.0);
      EXPECT_NEAR(read.pixels[3 * p + static_cast<std::size_t>(c)], srgbToLinear(code / 255.0), 1e-6) << p << " " << c;
    }
  }
}

// PNGs of every colour type libpng expands, built byte by byte: 16-bit grey, a palette with
// transparency, 8-bit grey and alpha, and RGB declared linear (gAMA of 1).
TEST(ImageIo, PngsOfEveryKindAreReadAsLinearFloats) {
  TempDir dir("eikonal-image");
  const fs::path path = dir.path() / "a.png";
  auto decoded = [](double v) { return static_cast<float>(srgbToLinear(v)); };

  // 16-bit grey, big-endian samples 0x0000 0x8000 0xffff.
  writeFile(path, pngFile(3, 1, 16, 0, std::string{0, 0, 0, '\x80', 0, '\xff', '\xff'}));
  Image image = readImage(path);
  ASSERT_EQ(image.channels, 1);
  EXPECT_EQ(image.pixels[0], 0.0f);
  EXPECT_NEAR(image.pixels[1], decoded(32768.0 / 65535.0), 1e-6);
  EXPECT_NEAR(image.pixels[2], 1.0f, 1e-6);

  // A palette of two colours, the second half transparent.
  const std::string palette = chunk("PLTE", std::string{'\xff', 0, 0, 0, '\x40', '\x80'}) + chunk("tRNS", std::string{'\xff', '\x80'});
  writeFile(path, pngFile(2, 1, 8, 3, std::string{0, 0, 1}, palette));
  image = readImage(path);
  ASSERT_EQ(image.channels, 4);
  const float expected[8] = {1.0f, 0.0f, 0.0f, 1.0f, 0.0f, decoded(64 / 255.0), decoded(128 / 255.0), 128 / 255.0f};
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(image.pixels[static_cast<std::size_t>(i)], expected[i], 1e-6) << i;  // alpha stays linear

  // Grey and alpha, 8-bit.
  writeFile(path, pngFile(1, 1, 8, 4, std::string{0, '\x66', '\x33'}));
  image = readImage(path);
  ASSERT_EQ(image.channels, 2);
  EXPECT_NEAR(image.pixels[0], decoded(0x66 / 255.0), 1e-6);
  EXPECT_NEAR(image.pixels[1], 0x33 / 255.0f, 1e-6);

  // RGB with gAMA 100000 (γ = 1): the codes are linear already.
  writeFile(path, pngFile(1, 1, 8, 2, std::string{0, '\x10', '\x80', '\xf0'}, chunk("gAMA", bigEndian(100000))));
  image = readImage(path);
  ASSERT_EQ(image.channels, 3);
  EXPECT_NEAR(image.pixels[0], 0x10 / 255.0f, 1e-6);
  EXPECT_NEAR(image.pixels[1], 0x80 / 255.0f, 1e-6);
  EXPECT_NEAR(image.pixels[2], 0xf0 / 255.0f, 1e-6);
}

// Radiance RGBE built byte by byte, flat scanlines: a pixel (r, g, b, e) is (r, g, b)·2^(e − 136).
TEST(ImageIo, RadianceHdrIsReadAsRgbe) {
  TempDir dir("eikonal-image");
  const std::string pixels = std::string{'\x80', '\x40', '\x20', '\x81'} + std::string{'\xff', 0, 1, '\x88'} +
                             std::string{'\x10', '\x20', '\x30', '\x70'} + std::string{0, 0, 0, 0};
  writeFile(dir.path() / "a.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n" + pixels);
  const Image image = readImage(dir.path() / "a.hdr");
  ASSERT_EQ(image.width, 2);
  ASSERT_EQ(image.height, 2);
  ASSERT_EQ(image.channels, 3);
  for (int p = 0; p < 4; ++p)
    for (int c = 0; c < 3; ++c) {
      const auto m = static_cast<unsigned char>(pixels[static_cast<std::size_t>(4 * p + c)]);
      const auto e = static_cast<unsigned char>(pixels[static_cast<std::size_t>(4 * p + 3)]);
      const double value = e == 0 ? 0.0 : std::ldexp(static_cast<double>(m), e - 136);
      // Decoders differ by at most half a mantissa step (Radiance's own adds ½ to m).
      const double step = e == 0 ? 0.0 : std::ldexp(0.5, e - 136);
      EXPECT_NEAR(image.pixels[static_cast<std::size_t>(3 * p + c)], value, step + 1e-7 * value) << p << " " << c;
    }
}

TEST(ImageIo, BrokenFilesAreRefusedNamingTheFile) {
  TempDir dir("eikonal-image");
  writeImage(dir.path() / "good.exr", gradient(16, 16, 3));
  writeImage(dir.path() / "good.png", gradient(16, 16, 3));
  const std::string exr = readFile(dir.path() / "good.exr"), png = readFile(dir.path() / "good.png");
  auto refused = [&](const std::string& name, const std::string& bytes, const std::string& expected) {
    writeFile(dir.path() / name, bytes);
    const std::string message = inputErrorOf([&] { readImage(dir.path() / name); });
    EXPECT_NE(message.find(name), std::string::npos) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << name << ": " << message;
  };
  refused("cut.exr", exr.substr(0, exr.size() * 2 / 3), "cannot read image as exr");
  refused("cut.png", png.substr(0, png.size() * 2 / 3), "chunk IDAT: declares");  // the walk's
  // Chunks whole, but the image data's zlib stream cut short (libpng's own refusal).
  const std::string rows = deflated(std::string(2 * 3, '\x40'));
  refused("short.png", kPngSignature + chunk("IHDR", bigEndian(2) + bigEndian(2) + std::string{8, 0, 0, 0, 0}) +
                           chunk("IDAT", rows.substr(0, rows.size() / 2)) + chunk("IEND", ""),
          "cannot read image data");
  // A PNG whose IDAT is no zlib stream (its CRC right, so libpng reads on to the data).
  refused("bad.png", kPngSignature + chunk("IHDR", bigEndian(2) + bigEndian(2) + std::string{8, 0, 0, 0, 0}) + chunk("IDAT", "not zlib") +
                         chunk("IEND", ""),
          "cannot read image data");
  refused("png.exr", png, "not an OpenEXR file");
  refused("png.hdr", png, "not a Radiance .hdr file");
  refused("exr.png", exr, "not a PNG file");
  refused("empty.hdr", "", "not a Radiance .hdr file");
  refused("short.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n\x80\x40", "cannot read image data");
  // Found by fuzz_image: a run-length scanline (8 wide) whose first component is one run and
  // whose file then ends. stb_image alone loops for ever there (runs of length 0 past the end).
  refused("cut_rle.hdr", std::string("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n") + "\x02\x02" + '\0' + "\x08\x88\x40",
          "cannot read image data");
  // A header cut short inside its resolution line.
  refused("cut_header.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +", "cannot read image as hdr");
  // Found by fuzz_image: a header whose lines run to the end of the file (looped for ever on the
  // bytes fed past the end, before those were bounded).
  refused("lines.hdr", std::string("#?RADIANCE\nFAT=3\n\x08-YP\x90\x80"), "the file ends inside its header");
  // A non-finite pixel (half infinity) in an otherwise good file.
  Image inf = gradient(2, 2, 3);
  inf.pixels[4] = INFINITY;
  writeImage(dir.path() / "inf.exr", inf);
  refused("inf.exr", readFile(dir.path() / "inf.exr"), "contains NaN or infinite values");
  // Writing: only what readImage reads back, or a clear refusal.
  EXPECT_NE(inputErrorOf([&] { writeImage(dir.path() / "x.jpg", gradient(2, 2, 3)); }).find("unknown image type '.jpg'"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir.path() / "x.jpg"));
}

}  // namespace
}  // namespace eik
