// NRRD header parsing field by field, straight from a FILE* (the error messages of malformed files
// as readNrrd reports them are checked in nrrd_test.cpp).
#include "core/nrrd_header.h"

#include <cstdio>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/testing.h"

namespace eik::nrrd {
namespace {
namespace fs = std::filesystem;

using test_support::inputErrorOf;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// `text` as a read-only in-memory file.
FilePtr memoryFile(const std::string& text) {
  return FilePtr(fmemopen(const_cast<char*>(text.data()), text.size(), "rb"));
}

ParsedHeader parse(const std::string& text, const fs::path& path = "mem.nrrd") {
  FilePtr file = memoryFile(text);
  return parseHeader(path, file.get());
}

std::string errorOf(const std::string& text, const fs::path& path = "mem.nrrd") {
  return inputErrorOf([&] { parse(text, path); });
}

TEST(NrrdHeader, FieldsInAnyOrderWithTeemSpellings) {
  const std::string text =
      "NRRD0005\n"
      "# a comment\n"
      "units:=cm\n"  // key:=value pairs are ignored
      "spacedirections: none (0.5,0,0) (0,0.25,0) (0,0,2)\n"
      "Encoding: GZIP\n"
      "kinds: 3-vector domain domain domain\n"
      "sizes: 3 4 5 6\n"
      "endian: big\n"
      "dimension: 4\n"
      "type: float\n"
      "space origin: (1,2,3)\n"
      "\n"
      "DATA";
  FilePtr file = memoryFile(text);
  const ParsedHeader parsed = parseHeader("mem.nrrd", file.get());
  EXPECT_EQ(parsed.dimension, 4);
  EXPECT_EQ(parsed.header.components, 3);
  EXPECT_EQ(parsed.header.sizes, glm::ivec3(4, 5, 6));
  EXPECT_EQ(parsed.encoding, Encoding::Gzip);
  EXPECT_TRUE(parsed.big_endian);
  EXPECT_EQ(parsed.header.directions, glm::dmat3(0.5, 0, 0, 0, 0.25, 0, 0, 0, 2));
  EXPECT_EQ(parsed.header.origin, glm::dvec3(1, 2, 3));
  EXPECT_TRUE(parsed.attached);
  EXPECT_EQ(parsed.data_path, fs::path("mem.nrrd"));
  EXPECT_EQ(std::fgetc(file.get()), 'D') << "the file is left at the first byte of the data";
}

TEST(NrrdHeader, SpaceFlipsToRasAndAxisMinsPlaceCellCentres) {
  const std::string base = "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n";
  const ParsedHeader lps = parse(base + "space: LPS\nspace directions: (1,0,0) (0,2,0) (0,0,3)\nspace origin: (1,1,1)\n\n");
  EXPECT_EQ(lps.header.directions, glm::dmat3(-1, 0, 0, 0, -2, 0, 0, 0, 3));
  EXPECT_EQ(lps.header.origin, glm::dvec3(-1, -1, 1));
  EXPECT_EQ(lps.encoding, Encoding::Ascii);
  EXPECT_FALSE(lps.big_endian) << "ascii needs no endian";
  const ParsedHeader mins = parse(base + "spacings: 2 4 8\naxis mins: 0 1 2\ncenters: cell node cell\n\n");
  EXPECT_EQ(mins.header.directions, glm::dmat3(2, 0, 0, 0, 4, 0, 0, 0, 8));
  EXPECT_EQ(mins.header.origin, glm::dvec3(1, 1, 6));
  const ParsedHeader plain = parse(base + "line skip: 2\nbyteskip: 16\n\n");
  EXPECT_EQ(plain.header.directions, glm::dmat3(1.0));
  EXPECT_EQ(plain.header.origin, glm::dvec3(0.0));
  EXPECT_EQ(plain.line_skip, 2);
  EXPECT_EQ(plain.byte_skip, 16);
}

TEST(NrrdHeader, DetachedDataFileIsRelativeToTheHeader) {
  test_support::TempDir dir;
  test_support::writeFile(dir / "x.raw", "");
  const std::string text = "NRRD0004\ntype: float\ndimension: 3\nsizes: 1 1 1\nendian: little\nencoding: raw\n";
  const ParsedHeader parsed = parse(text + "data file: x.raw\n", dir / "x.nhdr");
  EXPECT_FALSE(parsed.attached);
  EXPECT_EQ(parsed.data_path, dir / "x.raw");
  EXPECT_CONTAINS(errorOf(text + "data file: y.raw\n", dir / "x.nhdr"), "data file: " + (dir / "y.raw").string() + ": not found");
  EXPECT_EQ(errorOf(text, "x.nhdr"), "x.nhdr: data file: missing (a detached header must name its data file)");
}

TEST(NrrdHeader, EachFieldNamesItselfInErrors) {
  const std::string magic = "NRRD0004\n";
  const std::string ok = "type: float\ndimension: 3\nsizes: 2 3 4\nendian: little\nencoding: raw\n";
  EXPECT_EQ(errorOf(""), "mem.nrrd: magic: file is empty (expected 'NRRD0004')");
  EXPECT_EQ(errorOf(magic + "type: float\ntype: float\n\n"), "mem.nrrd: type: given twice (lines 2 and 3)");
  EXPECT_EQ(errorOf(magic + "dimension: 3\n\n"), "mem.nrrd: type: missing (a required NRRD field)");
  EXPECT_EQ(errorOf(magic + "type: double\n\n"),
            "mem.nrrd: type: 'double' is not supported: volume fields must be 32-bit floats ('type: float')");
  EXPECT_EQ(errorOf(magic + "type: float\ndimension: three\n\n"), "mem.nrrd: dimension: 'three' is not an integer");
  EXPECT_EQ(errorOf(magic + "type: float\ndimension: 3\nsizes: 2 3\n\n"),
            "mem.nrrd: sizes: expected 3 values for dimension 3, got 2");
  EXPECT_EQ(errorOf(magic + ok + "kinds: domain domain\n\n"), "mem.nrrd: kinds: expected 3 values for dimension 3, got 2");
  EXPECT_EQ(errorOf(magic + ok + "space: RAS\nspace dimension: 3\n\n"),
            "mem.nrrd: space dimension: given together with 'space' (use one of them)");
  EXPECT_EQ(errorOf(magic + ok + "space directions: (1,0,0) (0,1,0)\n\n"),
            "mem.nrrd: space directions: expected 3 values for dimension 3, got 2");
  EXPECT_EQ(errorOf(magic + ok + "space origin: (1,2)\n\n"),
            "mem.nrrd: space origin: '(1,2)' has 2 components; only 3-dimensional spaces are supported");
  EXPECT_EQ(errorOf(magic + ok + "byte skip: -1\n\n"),
            "mem.nrrd: byte skip: -1 (data at the end of the file) is not supported; give the offset");
  EXPECT_EQ(errorOf(magic + ok),
            "mem.nrrd: data: missing: the header is neither followed by a blank line and data nor names a 'data file'");
}

TEST(NrrdHeader, QuotesAndNumbers) {
  EXPECT_EQ(inQuotes("abc"), "'abc'");
  EXPECT_EQ(inQuotes(std::string("a\0b\x7f", 4)), "'a\\x00b\\x7f'");
  EXPECT_EQ(inQuotes(std::string(70, 'x')), "'" + std::string(60, 'x') + "...'");
  long long i = 0;
  EXPECT_TRUE(parseInteger("+12", i));
  EXPECT_EQ(i, 12);
  EXPECT_FALSE(parseInteger("12 ", i));
  EXPECT_FALSE(parseInteger("", i));
  double d = 0;
  EXPECT_TRUE(parseNumber("-1.5e3", d));
  EXPECT_EQ(d, -1500.0);
  EXPECT_FALSE(parseNumber("1,5", d));
  EXPECT_EQ(inputErrorOf([] { fail("f.nrrd", "sizes", "bad"); }), "f.nrrd: sizes: bad");
}

}  // namespace
}  // namespace eik::nrrd
