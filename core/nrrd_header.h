// Parsing of NRRD headers (teem format spec https://teem.sourceforge.net/nrrd/format.html,
// "NRRD0001" to "NRRD0005"; docs/volume-format.md): the magic line, the field lines in any order,
// then one function per field. Every malformed or unsupported field raises InputError naming the
// file and the field. Used by the reader in nrrd.cpp; the public interface is nrrd.h.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/nrrd.h"

namespace eik::nrrd {

enum class Encoding { Raw, Gzip, Ascii };

// What a header says: the image's shape and placement, and where and how its samples are stored.
struct ParsedHeader {
  NrrdHeader header;
  int dimension = 3;
  Encoding encoding = Encoding::Raw;
  bool big_endian = false;
  std::filesystem::path data_path;  // the file holding the samples
  bool attached = true;             // samples follow the header in the same file
  long long line_skip = 0;
  long long byte_skip = 0;
};

// Reads the header of `path` from the start of `file`. For attached data `file` is left at the first
// byte after the blank line that ends the header. Checks the sizes against the limits
// (core/limits.h) and, for a detached header, that the data file exists.
ParsedHeader parseHeader(const std::filesystem::path& path, std::FILE* file);

// Throws InputError "FILE: FIELD: WHAT".
[[noreturn]] void fail(const std::filesystem::path& file, std::string_view field, const std::string& what);

// Quotes a piece of (possibly binary) input for an error message: at most 60 characters,
// unprintable bytes as \xHH.
std::string inQuotes(std::string_view text);

// A whole number ('+' allowed); false for anything else.
bool parseInteger(std::string_view text, long long& value);
bool parseNumber(std::string_view text, double& value);

}  // namespace eik::nrrd
