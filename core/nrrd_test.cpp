#include "core/nrrd.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/testing.h"

namespace eik {
namespace {
namespace fs = std::filesystem;

using test_support::inputErrorOf;
using test_support::readFile;
using test_support::TempDir;
using test_support::writeFile;

// Little-endian float32 bytes (the test hosts are little-endian; checked below).
std::string floatBytes(const std::vector<float>& values) {
  static_assert(std::endian::native == std::endian::little);
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
}

std::string gzipBytes(const std::string& bytes) {
  z_stream z{};
  EXPECT_EQ(deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&z, bytes.size()) + 64, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = static_cast<uInt>(bytes.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

std::vector<float> ramp(std::size_t count, float scale = 0.25f) {
  std::vector<float> values(count);
  for (std::size_t i = 0; i < count; ++i) values[i] = static_cast<float>(i) * scale - 3.0f;
  return values;
}

// A 2×3×4 scalar volume, attached raw, with the given header lines (after the magic).
const std::string kScalarHeader =
    "type: float\ndimension: 3\nsizes: 2 3 4\nendian: little\nencoding: raw\n";

// Expects readNrrd(file) to fail naming the file and `field` ("FILE: FIELD: ...") and mentioning `detail`.
void expectRejected(const fs::path& file, const std::string& field, const std::string& detail = "") {
  std::string message = inputErrorOf([&] { readNrrd(file); });
  EXPECT_CONTAINS(message, file.string() + ": " + field + ": ");
  if (!detail.empty()) {
    EXPECT_CONTAINS(message, detail);
  }
}

NrrdImage randomImage(int components, glm::ivec3 sizes) {
  NrrdImage image;
  image.components = components;
  image.sizes = sizes;
  image.origin = {-1.25, 0.5, 3.0 + 1.0 / 3.0};
  image.directions = glm::dmat3(0.1, 0, 0, 0, 0.2, 0, 0, 0, 1.0 / 7.0);
  std::mt19937 random(1234u + static_cast<unsigned>(components));
  std::normal_distribution<float> normal(0.0f, 10.0f);
  image.data.resize(image.voxelCount() * static_cast<std::size_t>(components));
  for (float& v : image.data) v = normal(random);
  image.data[0] = -0.0f;
  // The smallest normal float: subnormals are written as 0 (and refused when read: the sign of a
  // wrong byte order), everything else round-trips bit for bit.
  image.data[1 % image.data.size()] = std::numeric_limits<float>::min();
  image.data[2 % image.data.size()] = std::numeric_limits<float>::max();
  return image;
}

// ---------------------------------------------------------------------------------------------
// Round trips

class NrrdRoundTrip : public ::testing::TestWithParam<std::tuple<int, bool, bool>> {};

TEST_P(NrrdRoundTrip, IsBitExact) {
  auto [components, gzip, detached] = GetParam();
  TempDir dir;
  NrrdImage image = randomImage(components, {9, 7, 5});
  fs::path path = dir / (detached ? "field.nhdr" : "field.nrrd");
  writeNrrd(path, image, {gzip, detached});

  std::vector<std::string> expected_files = {path.filename().string()};
  if (detached) expected_files.push_back(gzip ? "field.raw.gz" : "field.raw");
  std::sort(expected_files.begin(), expected_files.end());
  EXPECT_EQ(dir.entries(), expected_files);  // and no temporaries left

  NrrdImage back = readNrrd(path);
  EXPECT_EQ(back.components, components);
  EXPECT_EQ(back.sizes, image.sizes);
  EXPECT_EQ(back.origin, image.origin);
  EXPECT_EQ(back.directions, image.directions);
  ASSERT_EQ(back.data.size(), image.data.size());
  EXPECT_EQ(std::memcmp(back.data.data(), image.data.data(), image.data.size() * sizeof(float)), 0);

  NrrdHeader header = readNrrdHeader(path);
  EXPECT_EQ(header.components, components);
  EXPECT_EQ(header.sizes, image.sizes);
  EXPECT_EQ(header.origin, image.origin);
}

INSTANTIATE_TEST_SUITE_P(AllLayouts, NrrdRoundTrip,
                         ::testing::Combine(::testing::Values(1, 2, 3, 4), ::testing::Bool(), ::testing::Bool()),
                         [](const auto& info) {
                           return std::to_string(std::get<0>(info.param)) + "comp_" +
                                  (std::get<1>(info.param) ? "gzip" : "raw") + "_" +
                                  (std::get<2>(info.param) ? "detached" : "attached");
                         });

TEST(Nrrd, HeaderCarriesWhatSlicerAndParaViewNeed) {
  TempDir dir;
  writeNrrd(dir / "v.nrrd", randomImage(3, {4, 4, 4}), {});
  std::string text = readFile(dir / "v.nrrd");
  std::string header = text.substr(0, text.find("\n\n") + 1);
  EXPECT_EQ(header.rfind("NRRD0004\n", 0), 0u);
  for (const char* line : {"\n# Eikonal", "\ntype: float\n", "\ndimension: 4\n", "\nspace: right-anterior-superior\n",
                           "\nsizes: 3 4 4 4\n", "\nspace directions: none (0.1,0,0) (0,0.2,0) (0,0,",
                           "\nkinds: 3-vector domain domain domain\n", "\nendian: little\n", "\nencoding: gzip\n",
                           "\nspace origin: (-1.25,0.5,3.3333333333333335)\n"}) {
    EXPECT_CONTAINS(header, line);
  }
  // The data section is one gzip member right after the blank line.
  std::size_t data = text.find("\n\n") + 2;
  ASSERT_LT(data + 2, text.size());
  EXPECT_EQ(static_cast<unsigned char>(text[data]), 0x1f);
  EXPECT_EQ(static_cast<unsigned char>(text[data + 1]), 0x8b);

  writeNrrd(dir / "s.nhdr", randomImage(1, {4, 4, 4}), {false, true});
  std::string scalar = readFile(dir / "s.nhdr");
  EXPECT_CONTAINS(scalar, "\ndimension: 3\n");
  EXPECT_CONTAINS(scalar, "\nkinds: domain domain domain\n");
  EXPECT_CONTAINS(scalar, "\nspace directions: (0.1,0,0) (0,0.2,0) (0,0,");
  EXPECT_CONTAINS(scalar, "\nencoding: raw\n");
  EXPECT_CONTAINS(scalar, "\ndata file: s.raw\n");

  writeNrrd(dir / "two.nrrd", randomImage(2, {2, 2, 2}), {});
  EXPECT_CONTAINS(readFile(dir / "two.nrrd"), "\nkinds: vector domain domain domain\n");
}

TEST(Nrrd, LargeGzipDataIsOneStandardGzipMember) {
  // Over 4 MiB, so the writer's parallel blocks (and their dictionaries and CRC combination) are used.
  TempDir dir;
  NrrdImage image = randomImage(1, {128, 128, 72});
  for (std::size_t i = 0; i < image.data.size(); i += 3) image.data[i] = 1.0f;  // something to match
  writeNrrd(dir / "big.nrrd", image);
  EXPECT_EQ(readNrrd(dir / "big.nrrd").data, image.data);

  // Plain zlib, asked for a single gzip member, finds the whole data and a valid trailer.
  std::string text = readFile(dir / "big.nrrd");
  std::size_t start = text.find("\n\n") + 2;
  z_stream z{};
  ASSERT_EQ(inflateInit2(&z, 15 + 16), Z_OK);
  std::string out(image.data.size() * sizeof(float) + 16, '\0');
  z.next_in = reinterpret_cast<Bytef*>(text.data() + start);
  z.avail_in = static_cast<uInt>(text.size() - start);
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(inflate(&z, Z_FINISH), Z_STREAM_END);
  EXPECT_EQ(z.avail_in, 0u);
  EXPECT_EQ(z.total_out, image.data.size() * sizeof(float));
  EXPECT_EQ(std::memcmp(out.data(), image.data.data(), image.data.size() * sizeof(float)), 0);
  inflateEnd(&z);
}

TEST(Nrrd, ReadsSpacingsWithoutSpaceDirections) {
  TempDir dir;
  fs::path file = dir / "hand.nhdr";
  writeFile(dir / "hand.raw", floatBytes(ramp(2 * 3 * 4 * 2)));
  writeFile(file,
        "NRRD0001\n# written by hand\ncontent: test\ntype: float\ndimension: 4\nsizes: 2 2 3 4\n"
        "spacings: nan 0.5 0.25 2\naxis mins: nan 1 2 3\ncenters: ??? cell cell cell\n"
        "endian: little\nencoding: raw\ndata file: ./hand.raw\nunits:=cm\n");
  NrrdImage image = readNrrd(file);
  EXPECT_EQ(image.components, 2);
  EXPECT_EQ(image.sizes, glm::ivec3(2, 3, 4));
  EXPECT_EQ(image.directions, glm::dmat3(0.5, 0, 0, 0, 0.25, 0, 0, 0, 2));
  EXPECT_EQ(image.origin, glm::dvec3(1.25, 2.125, 4.0));  // cell-centred: axis min + half a step
  EXPECT_EQ(image.data, ramp(48));
}

TEST(Nrrd, NoOrientationMeansUnitSpacingAtTheOrigin) {
  TempDir dir;
  writeFile(dir / "plain.nrrd", "NRRD0004\n" + kScalarHeader + "\n" + floatBytes(ramp(24)));
  NrrdImage image = readNrrd(dir / "plain.nrrd");
  EXPECT_EQ(image.directions, glm::dmat3(1.0));
  EXPECT_EQ(image.origin, glm::dvec3(0.0));
}

TEST(Nrrd, ConvertsLpsToRas) {
  TempDir dir;
  writeFile(dir / "lps.nrrd",
        "NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\nsizes: 2 3 4\n"
        "space directions: (0.5,0,0) (0,0.25, 0) (0.1,0,2)\nkinds: domain domain domain\nendian: little\n"
        "encoding: raw\nspace origin: (10,-20,30)\n\n" +
            floatBytes(ramp(24)));
  NrrdImage image = readNrrd(dir / "lps.nrrd");
  EXPECT_EQ(image.origin, glm::dvec3(-10, 20, 30));
  EXPECT_EQ(image.directions[0], glm::dvec3(-0.5, 0, 0));
  EXPECT_EQ(image.directions[1], glm::dvec3(0, -0.25, 0));
  EXPECT_EQ(image.directions[2], glm::dvec3(-0.1, 0, 2));
}

TEST(Nrrd, ReadsBigEndian) {
  TempDir dir;
  std::vector<float> values = ramp(24);
  std::string bytes = floatBytes(values);
  for (std::size_t i = 0; i < bytes.size(); i += 4) std::reverse(bytes.begin() + i, bytes.begin() + i + 4);
  writeFile(dir / "be.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nendian: big\nencoding: raw\n\n" + bytes);
  EXPECT_EQ(readNrrd(dir / "be.nrrd").data, values);
}

TEST(Nrrd, HonoursLineSkipAndByteSkip) {
  TempDir dir;
  std::vector<float> values = ramp(24);
  writeFile(dir / "skip.raw", "first line\nsecond\nXYZW" + floatBytes(values));
  writeFile(dir / "skip.nhdr", "NRRD0004\n" + kScalarHeader + "data file: skip.raw\nline skip: 2\nbyte skip: 4\n");
  EXPECT_EQ(readNrrd(dir / "skip.nhdr").data, values);

  // For gzip, byte skip counts decompressed bytes (teem).
  writeFile(dir / "skipz.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nendian: little\nencoding: gzip\n"
                            "byte skip: 8\n\n" + gzipBytes("12345678" + floatBytes(values)));
  EXPECT_EQ(readNrrd(dir / "skipz.nrrd").data, values);
}

TEST(Nrrd, ReadsConcatenatedGzipMembers) {
  TempDir dir;
  std::vector<float> values = ramp(24);
  std::string bytes = floatBytes(values);
  writeFile(dir / "multi.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nendian: little\nencoding: gz\n\n" +
                                gzipBytes(bytes.substr(0, 40)) + gzipBytes(bytes.substr(40)));
  EXPECT_EQ(readNrrd(dir / "multi.nrrd").data, values);
}

TEST(Nrrd, ReadsAsciiAndCrLfHeaders) {
  TempDir dir;
  writeFile(dir / "text.nrrd", "NRRD0004\r\ntype: float\r\ndimension: 3\r\nsizes: 2 1 1\r\nencoding: ascii\r\n\r\n1.5 -2\n");
  EXPECT_EQ(readNrrd(dir / "text.nrrd").data, (std::vector<float>{1.5f, -2.0f}));
}

TEST(Nrrd, HeaderOnlyReadDoesNotTouchTheData) {
  TempDir dir;
  writeFile(dir / "short.nrrd", "NRRD0004\n" + kScalarHeader + "\n" + floatBytes(ramp(3)));
  EXPECT_EQ(readNrrdHeader(dir / "short.nrrd").sizes, glm::ivec3(2, 3, 4));
  expectRejected(dir / "short.nrrd", "data", "truncated");
}

// ---------------------------------------------------------------------------------------------
// Malformed input: every case names the file and the field (docs/programs.md).

TEST(NrrdMalformed, WrongMagic) {
  TempDir dir;
  writeFile(dir / "a.nrrd", "NRRD0009\n" + kScalarHeader + "\n" + floatBytes(ramp(24)));
  expectRejected(dir / "a.nrrd", "magic", "NRRD0009");
  writeFile(dir / "b.nrrd", "P6\n2 3\n255\n");
  expectRejected(dir / "b.nrrd", "magic", "not a NRRD file");
  writeFile(dir / "c.nrrd", "");
  expectRejected(dir / "c.nrrd", "magic", "empty");
}

// A field of n = 1 whose header says big-endian though the bytes are little-endian reads as
// 4.6·10⁻⁴¹ (it was accepted): subnormal values are refused, the message pointing at the
// endianness. Zero reads as zero either way, so the first non-zero voxel is named.
TEST(NrrdMalformed, MislabelledEndiannessIsRefused) {
  TempDir dir;
  std::vector<float> values(24, 1.0f);
  values[0] = 0.0f;
  writeFile(dir / "swapped.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nendian: big\nencoding: raw\n\n" +
                                      floatBytes(values));
  expectRejected(dir / "swapped.nrrd", "data", "subnormal value 4.6e-41 at voxel (1, 0, 0)");
  EXPECT_CONTAINS(inputErrorOf([&] { readNrrd(dir / "swapped.nrrd"); }), "endian");
  // The writer never writes one: below FLT_MIN becomes 0, and the file reads back.
  NrrdImage image = randomImage(1, {2, 3, 4});
  image.data[5] = 1e-40f;
  image.data[6] = -3e-39f;
  writeNrrd(dir / "tiny.nrrd", image, {});
  const NrrdImage back = readNrrd(dir / "tiny.nrrd");
  EXPECT_EQ(back.data[5], 0.0f);
  EXPECT_EQ(back.data[6], 0.0f);
  EXPECT_EQ(back.data[7], image.data[7]);
}

// A tiny gzip or ASCII file whose header declares a huge grid is refused before the data is
// allocated (a 250-byte gzip NRRD declaring 1024³·3 values took 12 GiB and seconds of zero-filling):
// deflate expands at most 1032:1, an ASCII value takes two characters.
TEST(NrrdMalformed, HugeSizesInATinyEncodedFileAreRefusedBeforeAllocating) {
  TempDir dir;
  writeFile(dir / "bomb.nrrd", "NRRD0004\ntype: float\ndimension: 4\nsizes: 3 1024 1024 1024\nendian: little\n"
                               "encoding: gzip\n\n" + gzipBytes(floatBytes(ramp(24))));
  expectRejected(dir / "bomb.nrrd", "data", "bytes holds at most");
  writeFile(dir / "text.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 1024 1024 1024\nencoding: ascii\n\n1 2 3 4\n");
  expectRejected(dir / "text.nrrd", "data", "bytes of text hold at most");
  // What fits is still read (and a short stream still reported as truncated by the reader).
  writeFile(dir / "fits.nrrd", "NRRD0004\n" + std::string("type: float\ndimension: 3\nsizes: 2 3 4\nencoding: ascii\n\n") +
                                   "0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23\n");
  EXPECT_EQ(readNrrd(dir / "fits.nrrd").data.size(), 24u);
}

TEST(NrrdMalformed, TruncatedRawData) {
  TempDir dir;
  writeFile(dir / "t.nrrd", "NRRD0004\n" + kScalarHeader + "\n" + floatBytes(ramp(23)));
  expectRejected(dir / "t.nrrd", "data", "truncated: sizes need 96 bytes of float32 data, found 92");
  writeFile(dir / "t.raw", floatBytes(ramp(10)));
  writeFile(dir / "t.nhdr", "NRRD0004\n" + kScalarHeader + "data file: t.raw\n");
  expectRejected(dir / "t.nhdr", "data", (dir / "t.raw").string() + ": truncated");
}

TEST(NrrdMalformed, TruncatedGzipData) {
  TempDir dir;
  std::string header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nendian: little\nencoding: gzip\n\n";
  std::string full = gzipBytes(floatBytes(ramp(24)));
  writeFile(dir / "cut.nrrd", header + full.substr(0, full.size() / 2));
  expectRejected(dir / "cut.nrrd", "data", "truncated");
  writeFile(dir / "tail.nrrd", header + full.substr(0, full.size() - 4));  // all data, checksum trailer cut
  expectRejected(dir / "tail.nrrd", "data", "truncated");
  writeFile(dir / "short.nrrd", header + gzipBytes(floatBytes(ramp(20))));  // complete stream, too little data
  expectRejected(dir / "short.nrrd", "data", "found 80");
  std::string corrupt = full;
  corrupt[corrupt.size() / 2] ^= 0x55;
  corrupt[corrupt.size() / 2 + 1] ^= 0x55;
  writeFile(dir / "corrupt.nrrd", header + corrupt);
  expectRejected(dir / "corrupt.nrrd", "data");
}

TEST(NrrdMalformed, TooMuchData) {
  TempDir dir;
  writeFile(dir / "raw.nrrd", "NRRD0004\n" + kScalarHeader + "\n" + floatBytes(ramp(25)));
  expectRejected(dir / "raw.nrrd", "data", "4 bytes more data than sizes call for");
  writeFile(dir / "gz.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nendian: little\nencoding: gzip\n\n" +
                             gzipBytes(floatBytes(ramp(30))));
  expectRejected(dir / "gz.nrrd", "data", "more data than sizes call for");
}

TEST(NrrdMalformed, SizesDisagreeWithDimension) {
  TempDir dir;
  writeFile(dir / "x.ior.nrrd", "NRRD0004\ntype: float\ndimension: 4\nsizes: 3 2 2\nendian: little\nencoding: raw\n\n" +
                                floatBytes(ramp(12)));
  expectRejected(dir / "x.ior.nrrd", "sizes", "expected 4 values for dimension 4, got 3");
}

TEST(NrrdMalformed, UnsupportedType) {
  TempDir dir;
  for (std::string type : {"short", "double", "unsigned char", "int8"}) {
    writeFile(dir / "t.nrrd", "NRRD0004\ntype: " + type + "\ndimension: 3\nsizes: 2 3 4\nendian: little\nencoding: raw\n\n" +
                              floatBytes(ramp(48)));
    expectRejected(dir / "t.nrrd", "type", type);
  }
}

TEST(NrrdMalformed, UnsupportedEncoding) {
  TempDir dir;
  for (std::string encoding : {"hex", "bzip2", "lz4"}) {
    writeFile(dir / "e.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nendian: little\nencoding: " + encoding +
                              "\n\n" + floatBytes(ramp(24)));
    expectRejected(dir / "e.nrrd", "encoding", encoding);
  }
}

// Fields are checked in blocks of values: a bad value deep in a large field (past the first
// blocks) is found and named where it is, and a field whose only bad value is its last is refused.
TEST(NrrdMalformed, BadSamplesDeepInALargeFieldAreFoundWhereTheyAre) {
  TempDir dir;
  const std::string header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 50 40 3\nendian: little\nencoding: raw\n\n";
  std::vector<float> values(6000, 1.0f);
  values[4321] = std::numeric_limits<float>::infinity();  // voxel (21, 6, 2): 4321 = 21 + 50·(6 + 40·2)
  values[5000] = std::numeric_limits<float>::quiet_NaN();
  writeFile(dir / "inf.nrrd", header + floatBytes(values));
  expectRejected(dir / "inf.nrrd", "data", "at voxel (21, 6, 2)");
  values.assign(6000, 1.0f);
  values[5999] = 2e-40f;  // subnormal, the last value: voxel (49, 39, 2)
  writeFile(dir / "tiny.nrrd", header + floatBytes(values));
  expectRejected(dir / "tiny.nrrd", "data", "subnormal value 2e-40 at voxel (49, 39, 2)");
  values[5999] = 1.0f;
  writeFile(dir / "good.nrrd", header + floatBytes(values));
  EXPECT_EQ(readNrrd(dir / "good.nrrd").data, values);
}

TEST(NrrdMalformed, NonFiniteSamples) {
  TempDir dir;
  std::vector<float> values = ramp(24);
  values[7] = std::numeric_limits<float>::quiet_NaN();
  writeFile(dir / "nan.nrrd", "NRRD0004\n" + kScalarHeader + "\n" + floatBytes(values));
  expectRejected(dir / "nan.nrrd", "data", "NaN at voxel (1, 0, 1)");

  values = ramp(48);
  values[5] = -std::numeric_limits<float>::infinity();
  writeFile(dir / "inf.nrrd", "NRRD0004\ntype: float\ndimension: 4\nsizes: 2 2 3 4\nendian: little\nencoding: gzip\n\n" +
                              gzipBytes(floatBytes(values)));
  expectRejected(dir / "inf.nrrd", "data", "-Inf at voxel (0, 1, 0) component 1");
}

TEST(NrrdMalformed, SizesOverTheAxisLimitFailBeforeReading) {
  TempDir dir;
  writeFile(dir / "big.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2048 2 2\nendian: little\nencoding: raw\n\n" +
                              floatBytes(ramp(4)));
  expectRejected(dir / "big.nrrd", "sizes", "2048 voxels along x exceeds the limit of 1024");
  writeFile(dir / "huge.nrrd",
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 8 8 99999999999999999\nendian: little\nencoding: raw\n\n");
  expectRejected(dir / "huge.nrrd", "sizes");
  EXPECT_THROW(readNrrdHeader(dir / "big.nrrd"), InputError);
}

// Sets an environment variable for the lifetime of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_.empty()) {
      ::unsetenv(name_);
    } else {
      ::setenv(name_, old_.c_str(), 1);
    }
  }

 private:
  const char* name_;
  std::string old_;
};

TEST(NrrdMalformed, SizesOverTheMemoryLimitFailBeforeAllocating) {
  TempDir dir;
  // 3 × 512³ floats = 1.5 GiB against a pretend machine of 64 MiB; only a header and 8 bytes are on disk.
  writeFile(dir / "mem.nrrd", "NRRD0004\ntype: float\ndimension: 4\nsizes: 3 512 512 512\nendian: little\nencoding: raw\n\n" +
                              floatBytes(ramp(2)));
  ScopedEnv limit("EIKONAL_MEMORY_LIMIT_BYTES", "67108864");
  expectRejected(dir / "mem.nrrd", "sizes", "needs 1.5 GiB of memory, more than the 64.0 MiB");
}

TEST(NrrdMalformed, MissingRequiredFields) {
  TempDir dir;
  const std::string data = "\n" + floatBytes(ramp(24));
  writeFile(dir / "1.nrrd", "NRRD0004\ndimension: 3\nsizes: 2 3 4\nendian: little\nencoding: raw\n" + data);
  expectRejected(dir / "1.nrrd", "type", "missing");
  writeFile(dir / "2.nrrd", "NRRD0004\ntype: float\nsizes: 2 3 4\nendian: little\nencoding: raw\n" + data);
  expectRejected(dir / "2.nrrd", "dimension", "missing");
  writeFile(dir / "3.nrrd", "NRRD0004\ntype: float\ndimension: 3\nendian: little\nencoding: raw\n" + data);
  expectRejected(dir / "3.nrrd", "sizes", "missing");
  writeFile(dir / "4.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nendian: little\n" + data);
  expectRejected(dir / "4.nrrd", "encoding", "missing");
  writeFile(dir / "5.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nencoding: raw\n" + data);
  expectRejected(dir / "5.nrrd", "endian", "missing");
}

TEST(NrrdMalformed, DetachedDataFile) {
  TempDir dir;
  writeFile(dir / "gone.nhdr", "NRRD0004\n" + kScalarHeader + "data file: gone.raw\n");
  expectRejected(dir / "gone.nhdr", "data file", (dir / "gone.raw").string() + ": not found");
  EXPECT_THROW(readNrrdHeader(dir / "gone.nhdr"), InputError);
  writeFile(dir / "none.nhdr", "NRRD0004\n" + kScalarHeader);
  expectRejected(dir / "none.nhdr", "data file", "missing");
  writeFile(dir / "list.nhdr", "NRRD0004\n" + kScalarHeader + "data file: LIST\na.raw\n");
  expectRejected(dir / "list.nhdr", "data file", "multi-file");
}

TEST(NrrdMalformed, DimensionAndComponents) {
  TempDir dir;
  writeFile(dir / "d2.nrrd", "NRRD0004\ntype: float\ndimension: 2\nsizes: 4 6\nendian: little\nencoding: raw\n\n" +
                             floatBytes(ramp(24)));
  expectRejected(dir / "d2.nrrd", "dimension", "2 is not supported");
  writeFile(dir / "d5.nrrd", "NRRD0004\ntype: float\ndimension: 5\nsizes: 1 2 1 3 4\nendian: little\nencoding: raw\n\n" +
                             floatBytes(ramp(24)));
  expectRejected(dir / "d5.nrrd", "dimension", "5 is not supported");
  writeFile(dir / "c5.nrrd", "NRRD0004\ntype: float\ndimension: 4\nsizes: 5 2 3 4\nendian: little\nencoding: raw\n\n" +
                             floatBytes(ramp(120)));
  expectRejected(dir / "c5.nrrd", "sizes", "component axis (the first) has 5 values; expected 1 to 4");
  writeFile(dir / "k.nrrd", "NRRD0004\ntype: float\ndimension: 4\nsizes: 2 2 3 4\nkinds: 3-vector domain domain domain\n"
                        "endian: little\nencoding: raw\n\n" + floatBytes(ramp(48)));
  expectRejected(dir / "k.nrrd", "kinds", "3-vector");
  writeFile(dir / "k4.nrrd", "NRRD0004\ntype: float\ndimension: 4\nsizes: 2 2 3 4\nkinds: domain domain domain domain\n"
                         "endian: little\nencoding: raw\n\n" + floatBytes(ramp(48)));
  expectRejected(dir / "k4.nrrd", "kinds", "4-dimensional domains");
  writeFile(dir / "last.nrrd", "NRRD0004\ntype: float\ndimension: 4\nsizes: 2 3 4 2\nkinds: domain domain domain vector\n"
                           "endian: little\nencoding: raw\n\n" + floatBytes(ramp(48)));
  expectRejected(dir / "last.nrrd", "kinds");
  writeFile(dir / "dir.nrrd", "NRRD0004\ntype: float\ndimension: 4\nsizes: 2 2 3 4\nspace: RAS\n"
                          "space directions: (1,0,0) (1,0,0) (0,1,0) (0,0,1)\nendian: little\nencoding: raw\n\n" +
                              floatBytes(ramp(48)));
  expectRejected(dir / "dir.nrrd", "space directions", "must be 'none'");
}

TEST(NrrdMalformed, NonNumericNumbers) {
  TempDir dir;
  const std::string data = "\n" + floatBytes(ramp(24));
  writeFile(dir / "a.nrrd", "NRRD0004\ntype: float\ndimension: three\nsizes: 2 3 4\nendian: little\nencoding: raw\n" + data);
  expectRejected(dir / "a.nrrd", "dimension", "'three' is not an integer");
  writeFile(dir / "b.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 x 4\nendian: little\nencoding: raw\n" + data);
  expectRejected(dir / "b.nrrd", "sizes", "'x' is not an integer");
  writeFile(dir / "c.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4.5\nendian: little\nencoding: raw\n" + data);
  expectRejected(dir / "c.nrrd", "sizes", "'4.5' is not an integer");
  writeFile(dir / "d.nrrd", "NRRD0004\n" + kScalarHeader + "space: RAS\nspace origin: (0,abc,0)\n" + data);
  expectRejected(dir / "d.nrrd", "space origin", "'abc'");
  writeFile(dir / "e.nrrd", "NRRD0004\n" + kScalarHeader + "space: RAS\nspace directions: (1,0,0) (0,1e,0) (0,0,1)\n" + data);
  expectRejected(dir / "e.nrrd", "space directions", "'1e'");
  writeFile(dir / "f.nrrd", "NRRD0004\n" + kScalarHeader + "spacings: 1 one 1\n" + data);
  expectRejected(dir / "f.nrrd", "spacings", "'one' is not a number");
  writeFile(dir / "g.nrrd", "NRRD0004\n" + kScalarHeader + "byte skip: some\n" + data);
  expectRejected(dir / "g.nrrd", "byte skip", "not an integer");
  writeFile(dir / "h.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 1 1\nencoding: ascii\n\n1.5 pi\n");
  expectRejected(dir / "h.nrrd", "data", "'pi' is not a number");
}

TEST(NrrdMalformed, NonPositiveSizes) {
  TempDir dir;
  for (std::string sizes : {"2 0 4", "2 -3 4"}) {
    writeFile(dir / "s.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: " + sizes +
                              "\nendian: little\nencoding: raw\n\n" + floatBytes(ramp(24)));
    expectRejected(dir / "s.nrrd", "sizes", "must be positive");
  }
}

TEST(NrrdMalformed, OtherHeaderErrors) {
  TempDir dir;
  const std::string data = "\n" + floatBytes(ramp(24));
  writeFile(dir / "skip.nrrd", "NRRD0004\n" + kScalarHeader + "byte skip: -1\n" + data);
  expectRejected(dir / "skip.nrrd", "byte skip", "-1");
  writeFile(dir / "space.nrrd", "NRRD0004\n" + kScalarHeader + "space: right-anterior-superior-time\n" + data);
  expectRejected(dir / "space.nrrd", "space", "not supported");
  writeFile(dir / "twice.nrrd", "NRRD0004\n" + kScalarHeader + "encoding: gzip\n" + data);
  expectRejected(dir / "twice.nrrd", "encoding", "given twice");
  writeFile(dir / "endian.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nendian: middle\nencoding: raw\n" + data);
  expectRejected(dir / "endian.nrrd", "endian", "'middle'");
  writeFile(dir / "junk.nrrd", "NRRD0004\n" + kScalarHeader + "this line is junk\n" + data);
  expectRejected(dir / "junk.nrrd", "header", "line 7");
  writeFile(dir / "flat.nrrd", "NRRD0004\n" + kScalarHeader + "space: RAS\nspace directions: (1,0,0) (2,0,0) (0,0,1)\n" + data);
  expectRejected(dir / "flat.nrrd", "space directions", "linearly dependent");
  writeFile(dir / "vec.nrrd", "NRRD0004\n" + kScalarHeader + "space: RAS\nspace origin: (1,2)\n" + data);
  expectRejected(dir / "vec.nrrd", "space origin", "2 components");
}

TEST(NrrdMalformed, MissingFileIsNamed) {
  TempDir dir;
  std::string message = inputErrorOf([&] { readNrrd(dir / "absent.nrrd"); });
  EXPECT_CONTAINS(message, (dir / "absent.nrrd").string());
  EXPECT_CONTAINS(message, "cannot open");
}

// ---------------------------------------------------------------------------------------------
// Writing

TEST(NrrdWrite, RefusesNonFiniteDataAndLeavesNothing) {
  TempDir dir;
  NrrdImage image = randomImage(3, {4, 4, 4});
  image.data[3 * 5 + 2] = std::numeric_limits<float>::quiet_NaN();
  try {
    writeNrrd(dir / "bad.nrrd", image);
    FAIL() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_CONTAINS(e.what(), (dir / "bad.nrrd").string() + ": data: NaN at voxel (1, 1, 0) component 2");
  }
  EXPECT_TRUE(dir.entries().empty());
}

TEST(NrrdWrite, RefusesDataOfTheWrongSize) {
  TempDir dir;
  NrrdImage image = randomImage(2, {4, 4, 4});
  image.data.pop_back();
  EXPECT_THROW(writeNrrd(dir / "bad.nrrd", image), RuntimeError);
  EXPECT_TRUE(dir.entries().empty());
}

TEST(NrrdWrite, DetachedDataPathDropsTheHeaderExtension) {
  EXPECT_EQ(detachedDataPath("a/b.ior.nhdr", true), fs::path("a/b.ior.raw.gz"));
  EXPECT_EQ(detachedDataPath("b.nrrd", false), fs::path("b.raw"));
  EXPECT_EQ(detachedDataPath("b", false), fs::path("b.raw"));
}

}  // namespace
}  // namespace eik
