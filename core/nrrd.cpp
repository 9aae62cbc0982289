#include "core/nrrd.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"

namespace eik {
namespace fs = std::filesystem;

std::size_t NrrdHeader::voxelCount() const {
  if (sizes.x <= 0 || sizes.y <= 0 || sizes.z <= 0) return 0;
  return static_cast<std::size_t>(sizes.x) * static_cast<std::size_t>(sizes.y) * static_cast<std::size_t>(sizes.z);
}

fs::path detachedDataPath(const fs::path& path, bool gzip) {
  fs::path name = path.filename();
  std::string ext = name.extension().string();
  std::string stem = (ext == ".nhdr" || ext == ".nrrd") ? name.stem().string() : name.string();
  return path.parent_path() / (stem + (gzip ? ".raw.gz" : ".raw"));
}

namespace {

// ---------------------------------------------------------------------------------------------
// Small text helpers

[[noreturn]] void fail(const fs::path& file, std::string_view field, const std::string& what) {
  throw InputError(file.string(), std::string(field), what);
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.remove_suffix(1);
  return text;
}

std::string lower(std::string_view text) {
  std::string result(text);
  for (char& c : result) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return result;
}

std::vector<std::string_view> splitWords(std::string_view text) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    std::size_t start = i;
    while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (i > start) words.push_back(text.substr(start, i - start));
  }
  return words;
}

// Quotes a piece of (possibly binary) input for an error message.
std::string inQuotes(std::string_view text) {
  std::string result = "'";
  for (char c : text.substr(0, 60)) {
    if (std::isprint(static_cast<unsigned char>(c))) {
      result += c;
    } else {
      char escape[8];
      std::snprintf(escape, sizeof escape, "\\x%02x", static_cast<unsigned char>(c));
      result += escape;
    }
  }
  if (text.size() > 60) result += "...";
  return result + "'";
}

bool parseInteger(std::string_view text, long long& value) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size() && !text.empty();
}

bool parseNumber(std::string_view text, double& value) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size() && !text.empty();
}

std::string formatNumber(double value) {
  char text[32];
  auto [end, ec] = std::to_chars(text, text + sizeof text, value);  // shortest exact round trip
  return ec == std::errc() ? std::string(text, end) : std::string("nan");
}

std::string formatVector(const glm::dvec3& v) {
  return "(" + formatNumber(v.x) + "," + formatNumber(v.y) + "," + formatNumber(v.z) + ")";
}

// ---------------------------------------------------------------------------------------------
// Files

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

FilePtr openForReading(const fs::path& path, const fs::path& reported, std::string_view field) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) fail(reported, field, path.string() + ": is a directory, not a file");
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) fail(reported, field, path.string() + ": cannot open: " + std::strerror(errno));
  return file;
}

// One header line without its terminator ('\n' or "\r\n"); false at the end of the file.
constexpr std::size_t kMaxHeaderLine = 1 << 16;
bool readLine(std::FILE* file, std::string& line, const fs::path& path, int line_number) {
  line.clear();
  int c;
  bool any = false;
  while ((c = std::getc(file)) != EOF) {
    any = true;
    if (c == '\n') break;
    line.push_back(static_cast<char>(c));
    if (line.size() > kMaxHeaderLine) {
      fail(path, line_number == 1 ? "magic" : "header",
           "line " + std::to_string(line_number) + " is longer than " + std::to_string(kMaxHeaderLine) +
               " bytes (not a NRRD header?)");
    }
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return any;
}

// ---------------------------------------------------------------------------------------------
// Header parsing (teem format spec, "NRRD0004")

enum class Encoding { Raw, Gzip, Ascii };

struct ParsedHeader {
  NrrdHeader header;
  int dimension = 3;
  Encoding encoding = Encoding::Raw;
  bool big_endian = false;
  fs::path data_path;          // the file holding the samples
  bool attached = true;        // samples follow the header in the same file
  long long line_skip = 0;
  long long byte_skip = 0;
};

struct FieldLine {
  std::string value;
  int line = 0;
};

// Canonical teem field names, including the spellings teem accepts without spaces.
std::string canonicalFieldName(std::string_view name) {
  std::string key = lower(trim(name));
  static const std::map<std::string, std::string, std::less<>> aliases = {
      {"datafile", "data file"},     {"lineskip", "line skip"},       {"byteskip", "byte skip"},
      {"centerings", "centers"},     {"axismins", "axis mins"},       {"axismaxs", "axis maxs"},
      {"spacedimension", "space dimension"}, {"spacedirections", "space directions"},
      {"spaceorigin", "space origin"}, {"spaceunits", "space units"}, {"measurementframe", "measurement frame"},
      {"oldmin", "old min"},         {"oldmax", "old max"},           {"blocksize", "block size"},
      {"sampleunits", "sample units"}};
  auto it = aliases.find(key);
  return it == aliases.end() ? key : it->second;
}

// Parses "(x,y,z)" into a vector of 3 finite numbers.
glm::dvec3 parseVector(std::string_view text, const fs::path& path, std::string_view field) {
  text = trim(text);
  if (text.size() < 2 || text.front() != '(' || text.back() != ')') {
    fail(path, field, inQuotes(text) + " is not a vector '(x,y,z)'");
  }
  std::string_view inner = text.substr(1, text.size() - 2);
  std::vector<double> values;
  std::size_t start = 0;
  while (true) {
    std::size_t comma = inner.find(',', start);
    std::string_view item = trim(inner.substr(start, comma == std::string_view::npos ? std::string_view::npos
                                                                                        : comma - start));
    double value = 0;
    if (!parseNumber(item, value)) fail(path, field, inQuotes(item) + " in " + inQuotes(text) + " is not a number");
    if (!std::isfinite(value)) fail(path, field, inQuotes(text) + " has a non-finite component");
    values.push_back(value);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (values.size() != 3) {
    fail(path, field, inQuotes(text) + " has " + std::to_string(values.size()) +
                          " components; only 3-dimensional spaces are supported");
  }
  return {values[0], values[1], values[2]};
}

// Splits "none (1,0,0) (0, 1, 0) (0,0,1)" into items; a vector may contain spaces.
std::vector<std::string_view> splitVectorList(std::string_view text, const fs::path& path, std::string_view field) {
  std::vector<std::string_view> items;
  std::size_t i = 0;
  while (i < text.size()) {
    if (std::isspace(static_cast<unsigned char>(text[i]))) {
      ++i;
      continue;
    }
    std::size_t start = i;
    if (text[i] == '(') {
      std::size_t close = text.find(')', i);
      if (close == std::string_view::npos) fail(path, field, "unbalanced '(' in " + inQuotes(text));
      i = close + 1;
    } else {
      while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    }
    items.push_back(text.substr(start, i - start));
  }
  return items;
}

// Sign flips that take a named teem space to RAS (our world x, y, z).
glm::dvec3 spaceToRas(std::string_view space, const fs::path& path) {
  std::string name = lower(trim(space));
  if (name == "right-anterior-superior" || name == "ras" || name == "3d-right-handed" || name == "scanner-xyz" ||
      name == "3d-left-handed") {
    return {1, 1, 1};
  }
  if (name == "left-posterior-superior" || name == "lps") return {-1, -1, 1};
  if (name == "left-anterior-superior" || name == "las") return {-1, 1, 1};
  fail(path, "space",
       inQuotes(space) + " is not supported (expected right-anterior-superior, left-posterior-superior, "
                       "left-anterior-superior or 3D-right-handed)");
}

bool isSpatialKind(const std::string& kind) {
  return kind == "domain" || kind == "space" || kind == "???" || kind == "none";
}

// Component count a fixed-size teem kind implies, 0 for kinds of any size ("vector", "list", ...).
int fixedKindSize(const std::string& kind) {
  static const std::map<std::string, int, std::less<>> sizes = {
      {"2-vector", 2},   {"3-vector", 3}, {"4-vector", 4},   {"3-color", 3},     {"4-color", 4},
      {"rgb-color", 3},  {"hsv-color", 3}, {"xyz-color", 3}, {"rgba-color", 4},  {"complex", 2},
      {"3-gradient", 3}, {"3-normal", 3}, {"quaternion", 4}, {"2d-symmetric-matrix", 3},
      {"2d-masked-symmetric-matrix", 4}, {"2d-matrix", 4}};
  auto it = sizes.find(kind);
  return it == sizes.end() ? 0 : it->second;
}

ParsedHeader parseHeader(const fs::path& path, std::FILE* file) {
  std::string line;
  if (!readLine(file, line, path, 1)) fail(path, "magic", "file is empty (expected 'NRRD0004')");
  if (line.size() != 8 || line.compare(0, 7, "NRRD000") != 0 || line[7] < '1' || line[7] > '5') {
    fail(path, "magic", "expected 'NRRD0001' to 'NRRD0005', got " + inQuotes(line) + " (not a NRRD file?)");
  }

  // Collect the fields first: teem requires an order, we do not.
  std::map<std::string, FieldLine, std::less<>> fields;
  bool blank_line = false;
  int line_number = 1;
  while (readLine(file, line, path, ++line_number)) {
    if (line.empty()) {
      blank_line = true;
      break;
    }
    if (line.front() == '#') continue;
    std::size_t colon = line.find(':');
    if (colon == std::string::npos) {
      fail(path, "header",
           "line " + std::to_string(line_number) + ": " + inQuotes(line) +
               " is neither a field ('name: value'), a key ('key:=value') nor a comment ('#')");
    }
    if (colon + 1 < line.size() && line[colon + 1] == '=') continue;  // key:=value pairs are carried by no one
    std::string name = canonicalFieldName(std::string_view(line).substr(0, colon));
    std::string value(trim(std::string_view(line).substr(colon + 1)));
    if (fields.count(name)) {
      fail(path, name, "given twice (lines " + std::to_string(fields[name].line) + " and " +
                           std::to_string(line_number) + ")");
    }
    if (name == "data file" && (value.rfind("LIST", 0) == 0 || value.find('%') != std::string::npos)) {
      fail(path, name, "multi-file data (" + inQuotes(value) + ") is not supported; name one data file");
    }
    fields[name] = {value, line_number};
  }

  auto find = [&](std::string_view name) -> const std::string* {
    auto it = fields.find(name);
    return it == fields.end() ? nullptr : &it->second.value;
  };
  auto require = [&](std::string_view name) -> const std::string& {
    const std::string* value = find(name);
    if (!value) fail(path, name, "missing (a required NRRD field)");
    return *value;
  };

  ParsedHeader parsed;

  // type: float32 only (DESIGN §4.1).
  std::string type = lower(require("type"));
  if (type != "float") {
    fail(path, "type", inQuotes(type) + " is not supported: volume fields must be 32-bit floats ('type: float')");
  }

  // dimension: 3 (scalar) or 4 (component axis first).
  long long dimension = 0;
  if (!parseInteger(trim(require("dimension")), dimension)) {
    fail(path, "dimension", inQuotes(require("dimension")) + " is not an integer");
  }
  if (dimension != 3 && dimension != 4) {
    fail(path, "dimension",
         std::to_string(dimension) + " is not supported (expected 3, or 4 with the component axis first)");
  }
  parsed.dimension = static_cast<int>(dimension);
  const int first_spatial = parsed.dimension - 3;

  // sizes
  std::vector<std::string_view> size_words = splitWords(require("sizes"));
  if (static_cast<long long>(size_words.size()) != dimension) {
    fail(path, "sizes",
         "expected " + std::to_string(dimension) + " values for dimension " + std::to_string(dimension) + ", got " +
             std::to_string(size_words.size()));
  }
  std::vector<long long> sizes;
  for (std::size_t a = 0; a < size_words.size(); ++a) {
    long long size = 0;
    if (!parseInteger(size_words[a], size)) fail(path, "sizes", inQuotes(size_words[a]) + " is not an integer");
    if (size <= 0) fail(path, "sizes", "axis " + std::to_string(a) + " has size " + std::to_string(size) + "; sizes must be positive");
    sizes.push_back(size);
  }
  if (parsed.dimension == 4 && (sizes[0] < 1 || sizes[0] > 4)) {
    fail(path, "sizes",
         "the component axis (the first) has " + std::to_string(sizes[0]) + " values; expected 1 to 4");
  }
  parsed.header.components = parsed.dimension == 4 ? static_cast<int>(sizes[0]) : 1;
  glm::ivec3 spatial;
  for (int a = 0; a < 3; ++a) {
    spatial[a] = static_cast<int>(std::min<long long>(sizes[static_cast<std::size_t>(first_spatial + a)], INT_MAX));
  }
  checkGridLimits(path.string(), "sizes", spatial);
  checkMemoryLimit(path.string(), "sizes", fieldBytes(spatial, parsed.header.components));
  parsed.header.sizes = spatial;

  // encoding / endian
  std::string encoding = lower(require("encoding"));
  if (encoding == "raw") {
    parsed.encoding = Encoding::Raw;
  } else if (encoding == "gzip" || encoding == "gz") {
    parsed.encoding = Encoding::Gzip;
  } else if (encoding == "ascii" || encoding == "text" || encoding == "txt") {
    parsed.encoding = Encoding::Ascii;
  } else if (encoding == "hex" || encoding == "bzip2" || encoding == "bz2" || encoding == "zrl") {
    fail(path, "encoding", inQuotes(encoding) + " is not supported (use raw or gzip)");
  } else {
    fail(path, "encoding", inQuotes(encoding) + " is not a NRRD encoding (expected raw or gzip)");
  }
  if (parsed.encoding != Encoding::Ascii) {
    std::string endian = lower(require("endian"));
    if (endian == "little") {
      parsed.big_endian = false;
    } else if (endian == "big") {
      parsed.big_endian = true;
    } else {
      fail(path, "endian", inQuotes(endian) + " is neither 'little' nor 'big'");
    }
  }

  // kinds: the component axis first, then three spatial axes.
  if (const std::string* kinds_text = find("kinds")) {
    std::vector<std::string_view> kinds = splitWords(*kinds_text);
    if (static_cast<int>(kinds.size()) != parsed.dimension) {
      fail(path, "kinds",
           "expected " + std::to_string(parsed.dimension) + " values for dimension " +
               std::to_string(parsed.dimension) + ", got " + std::to_string(kinds.size()));
    }
    for (int a = 0; a < parsed.dimension; ++a) {
      std::string kind = lower(kinds[static_cast<std::size_t>(a)]);
      if (a < first_spatial) {
        if (kind == "domain" || kind == "space" || kind == "time") {
          fail(path, "kinds",
               "axis 0 is '" + kind + "': 4-dimensional domains are not supported (the first of 4 axes must "
               "hold the components, e.g. 'vector')");
        }
        int fixed = fixedKindSize(kind);
        if (fixed != 0 && fixed != parsed.header.components) {
          fail(path, "kinds", "axis 0 is '" + kind + "', which needs " + std::to_string(fixed) +
                                  " values, but sizes gives " + std::to_string(parsed.header.components));
        }
      } else if (!isSpatialKind(kind)) {
        fail(path, "kinds",
             "axis " + std::to_string(a) + " is '" + kind +
                 "', expected a spatial axis ('domain' or 'space'); components must be the first axis");
      }
    }
  }

  // Orientation: space + space directions + space origin, or spacings (+ axis mins).
  glm::dvec3 flip{1, 1, 1};
  const std::string* space = find("space");
  const std::string* space_dimension = find("space dimension");
  if (space && space_dimension) fail(path, "space dimension", "given together with 'space' (use one of them)");
  if (space) {
    flip = spaceToRas(*space, path);
  } else if (space_dimension) {
    long long dims = 0;
    if (!parseInteger(trim(*space_dimension), dims)) {
      fail(path, "space dimension", inQuotes(*space_dimension) + " is not an integer");
    }
    if (dims != 3) fail(path, "space dimension", std::to_string(dims) + " is not supported (expected 3)");
  }

  glm::dmat3 directions(1.0);
  if (const std::string* text = find("space directions")) {
    std::vector<std::string_view> items = splitVectorList(*text, path, "space directions");
    if (static_cast<int>(items.size()) != parsed.dimension) {
      fail(path, "space directions",
           "expected " + std::to_string(parsed.dimension) + " values for dimension " +
               std::to_string(parsed.dimension) + ", got " + std::to_string(items.size()));
    }
    for (int a = 0; a < parsed.dimension; ++a) {
      std::string_view item = items[static_cast<std::size_t>(a)];
      if (a < first_spatial) {
        if (lower(item) != "none") {
          fail(path, "space directions", "the component axis (the first) must be 'none', got " + inQuotes(item));
        }
        continue;
      }
      if (lower(item) == "none") {
        fail(path, "space directions", "spatial axis " + std::to_string(a) + " is 'none'; it needs a vector");
      }
      directions[a - first_spatial] = parseVector(item, path, "space directions") * flip;
    }
  } else if (const std::string* text = find("spacings")) {
    std::vector<std::string_view> items = splitWords(*text);
    if (static_cast<int>(items.size()) != parsed.dimension) {
      fail(path, "spacings",
           "expected " + std::to_string(parsed.dimension) + " values for dimension " +
               std::to_string(parsed.dimension) + ", got " + std::to_string(items.size()));
    }
    for (int a = first_spatial; a < parsed.dimension; ++a) {
      double spacing = 0;
      std::string_view item = items[static_cast<std::size_t>(a)];
      if (!parseNumber(item, spacing)) fail(path, "spacings", inQuotes(item) + " is not a number");
      if (!std::isfinite(spacing) || spacing == 0) {
        fail(path, "spacings", "axis " + std::to_string(a) + " spacing " + std::string(item) +
                                   " must be finite and non-zero");
      }
      directions[a - first_spatial] = glm::dvec3(0.0);
      directions[a - first_spatial][a - first_spatial] = spacing;
    }
  }
  for (int a = 0; a < 3; ++a) {
    if (glm::length(directions[a]) == 0) {
      fail(path, "space directions", "axis " + std::to_string(a + first_spatial) + " has zero length");
    }
  }
  if (glm::determinant(directions) == 0) {
    fail(path, "space directions", "the three axes are linearly dependent");
  }
  parsed.header.directions = directions;

  glm::dvec3 origin(0.0);
  if (const std::string* text = find("space origin")) {
    origin = parseVector(*text, path, "space origin") * flip;
  } else if (const std::string* text = find("axis mins")) {
    // Without a space origin, teem places axis sample 0 at "axis min" (cell-centred: half a step in).
    std::vector<std::string_view> items = splitWords(*text);
    if (static_cast<int>(items.size()) != parsed.dimension) {
      fail(path, "axis mins", "expected " + std::to_string(parsed.dimension) + " values, got " +
                                  std::to_string(items.size()));
    }
    std::vector<std::string_view> centers;
    if (const std::string* centers_text = find("centers")) centers = splitWords(*centers_text);
    for (int a = first_spatial; a < parsed.dimension; ++a) {
      double min = 0;
      std::string_view item = items[static_cast<std::size_t>(a)];
      if (!parseNumber(item, min) || !std::isfinite(min)) fail(path, "axis mins", inQuotes(item) + " is not a finite number");
      bool cell = static_cast<int>(centers.size()) == parsed.dimension &&
                  lower(centers[static_cast<std::size_t>(a)]) == "cell";
      int s = a - first_spatial;
      origin[s] = min + (cell ? 0.5 * directions[s][s] : 0.0);
    }
  }
  parsed.header.origin = origin;

  // Where the data is.
  if (const std::string* data_file = find("data file")) {
    fs::path data_path(*data_file);
    if (data_path.is_relative()) data_path = path.parent_path() / data_path;
    std::error_code ec;
    if (!fs::is_regular_file(data_path, ec)) fail(path, "data file", data_path.string() + ": not found");
    parsed.data_path = data_path;
    parsed.attached = false;
  } else if (blank_line) {
    parsed.data_path = path;
    parsed.attached = true;  // `file` is positioned at the first byte after the blank line
  } else if (path.extension() == ".nhdr") {
    fail(path, "data file", "missing (a detached header must name its data file)");
  } else {
    fail(path, "data", "missing: the header is neither followed by a blank line and data nor names a 'data file'");
  }

  auto readSkip = [&](std::string_view name, long long& skip) {
    const std::string* text = find(name);
    if (!text) return;
    if (!parseInteger(trim(*text), skip)) fail(path, name, inQuotes(*text) + " is not an integer");
    if (skip == -1) {
      fail(path, name, "-1 (data at the end of the file) is not supported; give the offset");
    }
    if (skip < 0) fail(path, name, std::to_string(skip) + " is negative");
  };
  readSkip("line skip", parsed.line_skip);
  readSkip("byte skip", parsed.byte_skip);
  return parsed;
}

// ---------------------------------------------------------------------------------------------
// Data section

// Reports where the samples come from: the header itself, or "data file NAME".
std::string dataSource(const ParsedHeader& parsed) {
  return parsed.attached ? std::string() : parsed.data_path.string() + ": ";
}

void skipLines(std::FILE* file, long long count, const fs::path& path, const ParsedHeader& parsed) {
  for (long long n = 0; n < count; ++n) {
    int c;
    while ((c = std::getc(file)) != EOF && c != '\n') {
    }
    if (c == EOF) {
      fail(path, "line skip", dataSource(parsed) + "file ends after " + std::to_string(n) + " of " +
                                  std::to_string(count) + " lines");
    }
  }
}

std::string truncatedMessage(const ParsedHeader& parsed, std::uint64_t expected, std::uint64_t got) {
  return dataSource(parsed) + "truncated: sizes need " + std::to_string(expected) + " bytes of float32 data, found " +
         std::to_string(got);
}

std::string tooMuchMessage(const ParsedHeader& parsed, std::uint64_t expected, std::uint64_t extra, bool at_least) {
  return dataSource(parsed) + (at_least ? "at least " : "") + std::to_string(extra) +
         " bytes more data than sizes call for (" + std::to_string(expected) + " bytes); sizes disagree with the data";
}

void readRaw(std::FILE* file, std::span<std::byte> out, const fs::path& path, const ParsedHeader& parsed) {
  if (parsed.byte_skip > 0 && fseeko(file, static_cast<off_t>(parsed.byte_skip), SEEK_CUR) != 0) {
    fail(path, "byte skip", dataSource(parsed) + "cannot skip " + std::to_string(parsed.byte_skip) + " bytes");
  }
  std::size_t got = std::fread(out.data(), 1, out.size(), file);
  if (got != out.size()) {
    if (std::ferror(file)) fail(path, "data", dataSource(parsed) + "read error: " + std::strerror(errno));
    fail(path, "data", truncatedMessage(parsed, out.size(), got));
  }
  if (std::fgetc(file) != EOF) {
    off_t here = ftello(file) - 1;
    off_t end = (fseeko(file, 0, SEEK_END) == 0) ? ftello(file) : here + 1;
    fail(path, "data", tooMuchMessage(parsed, out.size(), static_cast<std::uint64_t>(end - here), false));
  }
}

// For raw data the file length tells, before anything is allocated, whether sizes fit the data.
void checkRawLength(std::FILE* file, const fs::path& path, const ParsedHeader& parsed) {
  off_t here = ftello(file);
  if (here < 0 || fseeko(file, 0, SEEK_END) != 0) return;  // not seekable: readRaw checks as it reads
  off_t end = ftello(file);
  fseeko(file, here, SEEK_SET);
  const std::uint64_t expected = parsed.header.valueCount() * sizeof(float);
  const std::uint64_t available =
      end - here > parsed.byte_skip ? static_cast<std::uint64_t>(end - here - parsed.byte_skip) : 0;
  if (available < expected) fail(path, "data", truncatedMessage(parsed, expected, available));
  if (available > expected) fail(path, "data", tooMuchMessage(parsed, expected, available - expected, false));
}

struct InflateStream {
  z_stream z{};
  bool ready = false;
  ~InflateStream() {
    if (ready) inflateEnd(&z);
  }
};

// Streams a gzip (or zlib) data section into `out`: the first byte_skip decompressed bytes are
// dropped (teem applies byte skip after decompression), concatenated members are followed, and
// missing or surplus data is an error.
void readGzip(std::FILE* file, std::span<std::byte> out, const fs::path& path, const ParsedHeader& parsed) {
  InflateStream stream;
  if (inflateInit2(&stream.z, 15 + 32) != Z_OK) throw RuntimeError(path.string() + ": data: zlib init failed");
  stream.ready = true;
  z_stream& z = stream.z;

  std::vector<unsigned char> input(std::size_t{1} << 20);
  std::vector<unsigned char> scratch(std::size_t{1} << 16);
  std::uint64_t skip_left = static_cast<std::uint64_t>(parsed.byte_skip);
  std::size_t filled = 0;
  std::uint64_t extra = 0;
  bool end_of_file = false;
  bool stream_ended = false;

  while (true) {
    if (z.avail_in == 0 && !end_of_file) {
      std::size_t n = std::fread(input.data(), 1, input.size(), file);
      if (n == 0) {
        if (std::ferror(file)) fail(path, "data", dataSource(parsed) + "read error: " + std::strerror(errno));
        end_of_file = true;
      }
      z.next_in = input.data();
      z.avail_in = static_cast<uInt>(n);
    }
    if (stream_ended) {
      if (z.avail_in == 0 && end_of_file) break;
      if (z.avail_in == 0) continue;
      inflateReset(&z);  // another gzip member follows
      stream_ended = false;
    }

    enum { Skip, Fill, Surplus } phase = skip_left > 0 ? Skip : (filled < out.size() ? Fill : Surplus);
    uInt capacity;
    if (phase == Skip) {
      z.next_out = scratch.data();
      capacity = static_cast<uInt>(std::min<std::uint64_t>(scratch.size(), skip_left));
    } else if (phase == Fill) {
      z.next_out = reinterpret_cast<unsigned char*>(out.data() + filled);
      capacity = static_cast<uInt>(std::min<std::size_t>(out.size() - filled, std::size_t{1} << 30));
    } else {
      z.next_out = scratch.data();
      capacity = static_cast<uInt>(scratch.size());
    }
    z.avail_out = capacity;
    int status = inflate(&z, Z_NO_FLUSH);
    std::size_t produced = capacity - z.avail_out;
    if (phase == Skip) {
      skip_left -= produced;
    } else if (phase == Fill) {
      filled += produced;
    } else {
      extra += produced;
      if (extra > 0) fail(path, "data", tooMuchMessage(parsed, out.size(), extra, true));
    }
    if (status == Z_STREAM_END) {
      stream_ended = true;
    } else if (status == Z_BUF_ERROR) {
      // No progress is possible: more input is needed, and there is none.
      if (z.avail_in == 0 && end_of_file) {
        if (filled < out.size()) {
          fail(path, "data", truncatedMessage(parsed, out.size(), filled) + " (the gzip stream ends early)");
        }
        fail(path, "data", dataSource(parsed) + "truncated gzip stream (its end marker and checksum are missing)");
      }
    } else if (status != Z_OK) {
      fail(path, "data", dataSource(parsed) + "corrupt gzip data (" + (z.msg ? z.msg : "zlib error") + ")");
    }
  }
  if (skip_left > 0) {
    fail(path, "byte skip", dataSource(parsed) + "the data ends within the " + std::to_string(parsed.byte_skip) +
                                " bytes to skip");
  }
  if (filled < out.size()) fail(path, "data", truncatedMessage(parsed, out.size(), filled));
}

void readAscii(std::FILE* file, std::span<float> out, const fs::path& path, const ParsedHeader& parsed) {
  if (parsed.byte_skip > 0 && fseeko(file, static_cast<off_t>(parsed.byte_skip), SEEK_CUR) != 0) {
    fail(path, "byte skip", dataSource(parsed) + "cannot skip " + std::to_string(parsed.byte_skip) + " bytes");
  }
  std::string text;
  char buffer[1 << 16];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, file)) > 0) text.append(buffer, n);
  std::size_t count = 0;
  std::size_t i = 0;
  auto separator = [](char c) { return std::isspace(static_cast<unsigned char>(c)) || c == ','; };
  while (true) {
    while (i < text.size() && separator(text[i])) ++i;
    if (i == text.size()) break;
    std::size_t start = i;
    while (i < text.size() && !separator(text[i])) ++i;
    std::string_view word(text.data() + start, i - start);
    double value = 0;
    if (!parseNumber(word, value)) fail(path, "data", dataSource(parsed) + inQuotes(word) + " is not a number");
    if (count == out.size()) {
      fail(path, "data", dataSource(parsed) + "more than the " + std::to_string(out.size()) +
                             " values sizes call for; sizes disagree with the data");
    }
    out[count++] = static_cast<float>(value);
  }
  if (count < out.size()) {
    fail(path, "data", dataSource(parsed) + "truncated: sizes call for " + std::to_string(out.size()) +
                           " values, found " + std::to_string(count));
  }
}

void swapBytes(std::span<float> values) {
  for (float& value : values) {
    std::uint32_t bits = std::bit_cast<std::uint32_t>(value);
    bits = (bits >> 24) | ((bits >> 8) & 0xFF00u) | ((bits << 8) & 0xFF0000u) | (bits << 24);
    value = std::bit_cast<float>(bits);
  }
}

// Index of the first NaN/Inf, or values.size().
std::size_t firstNonFinite(std::span<const float> values) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) return i;
  }
  return values.size();
}

std::string describeSample(const NrrdHeader& header, std::size_t index, float value) {
  std::size_t components = static_cast<std::size_t>(header.components);
  std::size_t voxel = index / components;
  std::size_t sx = static_cast<std::size_t>(header.sizes.x), sy = static_cast<std::size_t>(header.sizes.y);
  std::string where = "voxel (" + std::to_string(voxel % sx) + ", " + std::to_string((voxel / sx) % sy) + ", " +
                      std::to_string(voxel / (sx * sy)) + ")";
  if (components > 1) where += " component " + std::to_string(index % components);
  return std::string(std::isnan(value) ? "NaN" : (value > 0 ? "+Inf" : "-Inf")) + " at " + where;
}

// ---------------------------------------------------------------------------------------------
// Writing

void checkWritable(const fs::path& path, const NrrdHeader& header, std::span<const float> data) {
  const std::string name = path.string();
  if (header.components < 1 || header.components > 4) {
    throw RuntimeError(name + ": components: " + std::to_string(header.components) + " (expected 1 to 4)");
  }
  for (int a = 0; a < 3; ++a) {
    if (header.sizes[a] < 1 || header.sizes[a] > kMaxVolumeAxis) {
      throw RuntimeError(name + ": sizes: " + std::to_string(header.sizes[a]) + " voxels along " + "xyz"[a] +
                         " (expected 1 to " + std::to_string(kMaxVolumeAxis) + ")");
    }
  }
  if (data.size() != header.valueCount()) {
    throw RuntimeError(name + ": data: " + std::to_string(data.size()) + " values for sizes that need " +
                       std::to_string(header.valueCount()));
  }
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(header.origin[a]) || !std::isfinite(header.directions[a].x) ||
        !std::isfinite(header.directions[a].y) || !std::isfinite(header.directions[a].z)) {
      throw RuntimeError(name + ": space directions/space origin: non-finite geometry");
    }
  }
  if (glm::determinant(header.directions) == 0) {
    throw RuntimeError(name + ": space directions: the three axes are linearly dependent");
  }
  std::size_t bad = firstNonFinite(data);
  if (bad != data.size()) {
    throw RuntimeError(name + ": data: " + describeSample(header, bad, data[bad]) +
                       " (a field must hold finite values)");
  }
}

std::string headerText(const NrrdHeader& header, const NrrdWriteOptions& options, const std::string& data_file) {
  const bool vector = header.components > 1;
  std::string text = "NRRD0004\n";
  text += "# Eikonal volume field (float32, x fastest; DESIGN section 4.1)\n";
  text += "# format: http://teem.sourceforge.net/nrrd/format.html\n";
  text += "type: float\n";
  text += vector ? "dimension: 4\n" : "dimension: 3\n";
  text += "space: right-anterior-superior\n";
  text += "sizes:";
  if (vector) text += " " + std::to_string(header.components);
  for (int a = 0; a < 3; ++a) text += " " + std::to_string(header.sizes[a]);
  text += "\nspace directions:";
  if (vector) text += " none";
  for (int a = 0; a < 3; ++a) text += " " + formatVector(header.directions[a]);
  text += "\nkinds: ";
  if (vector) text += header.components == 3 ? "3-vector " : "vector ";
  text += "domain domain domain\n";
  text += "endian: little\n";
  text += options.gzip ? "encoding: gzip\n" : "encoding: raw\n";
  text += "space origin: " + formatVector(header.origin) + "\n";
  if (!data_file.empty()) text += "data file: " + data_file + "\n";
  return text;
}

class OutputFile {
 public:
  OutputFile(const fs::path& temporary, const fs::path& target) : target_(target) {
    file_.reset(std::fopen(temporary.c_str(), "wb"));
    if (!file_) throw RuntimeError(target.string() + ": cannot create file: " + std::strerror(errno));
    std::setvbuf(file_.get(), nullptr, _IOFBF, std::size_t{1} << 20);
  }
  void write(const void* bytes, std::size_t size) {
    if (size != 0 && std::fwrite(bytes, 1, size, file_.get()) != size) {
      throw RuntimeError(target_.string() + ": write failed: " + std::strerror(errno));
    }
  }
  void close() {
    if (std::fclose(file_.release()) != 0) {
      throw RuntimeError(target_.string() + ": write failed: " + std::strerror(errno));
    }
  }

 private:
  FilePtr file_;
  fs::path target_;
};

struct DeflateStream {
  z_stream z{};
  bool ready = false;
  ~DeflateStream() {
    if (ready) deflateEnd(&z);
  }
};

// One gzip member (RFC 1952) compressed pigz-style on all worker threads: the data is cut into
// blocks deflated independently (raw deflate, each primed with the 32 KiB before it as dictionary,
// ended by a sync flush so the bit streams concatenate), then written in order between a gzip header
// and the combined CRC-32 trailer. Any gzip reader (teem/ITK, VTK, pynrrd) sees one ordinary stream.
void writeGzip(OutputFile& out, std::span<const unsigned char> bytes, const fs::path& target) {
  constexpr std::size_t kBlock = std::size_t{4} << 20;
  constexpr std::size_t kWindow = 32768;
  const std::size_t blocks = std::max<std::size_t>(1, (bytes.size() + kBlock - 1) / kBlock);
  // ID1 ID2 CM=deflate FLG=0 MTIME=0 (reproducible output) XFL=4 (fastest) OS=3 (Unix)
  const unsigned char header[10] = {0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 4, 3};
  out.write(header, sizeof header);

  uLong crc = crc32(0, Z_NULL, 0);
  const std::size_t batch = 2 * static_cast<std::size_t>(workerThreads());
  std::vector<std::string> compressed(batch);
  std::vector<uLong> crcs(batch);
  for (std::size_t first = 0; first < blocks; first += batch) {
    const std::size_t count = std::min(batch, blocks - first);
    parallelFor(0, static_cast<std::int64_t>(count), [&](std::int64_t k) {
      const std::size_t block = first + static_cast<std::size_t>(k);
      const std::size_t begin = block * kBlock;
      const std::size_t length = std::min(kBlock, bytes.size() - begin);
      const bool last = block + 1 == blocks;
      DeflateStream stream;
      // Level 1: float fields compress little better at higher levels, and 200 MB must write in seconds.
      if (deflateInit2(&stream.z, Z_BEST_SPEED, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
        throw RuntimeError(target.string() + ": zlib init failed");
      }
      stream.ready = true;
      z_stream& z = stream.z;
      if (block > 0) deflateSetDictionary(&z, bytes.data() + begin - kWindow, static_cast<uInt>(kWindow));
      std::string& output = compressed[static_cast<std::size_t>(k)];
      output.resize(deflateBound(&z, static_cast<uLong>(length)) + 64);
      z.next_in = const_cast<unsigned char*>(bytes.data() + begin);
      z.avail_in = static_cast<uInt>(length);
      std::size_t produced = 0;
      while (true) {
        z.next_out = reinterpret_cast<unsigned char*>(output.data() + produced);
        z.avail_out = static_cast<uInt>(output.size() - produced);
        int status = deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH);
        produced = output.size() - z.avail_out;
        if (status == Z_STREAM_ERROR) throw RuntimeError(target.string() + ": gzip compression failed");
        if (last ? status == Z_STREAM_END : (z.avail_in == 0 && z.avail_out != 0)) break;
        output.resize(output.size() * 2);  // not reached with deflateBound's size; kept for safety
      }
      output.resize(produced);
      crcs[static_cast<std::size_t>(k)] = crc32(0, bytes.data() + begin, static_cast<uInt>(length));
    });
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t length = std::min(kBlock, bytes.size() - (first + k) * kBlock);
      out.write(compressed[k].data(), compressed[k].size());
      crc = crc32_combine(crc, crcs[k], static_cast<z_off_t>(length));
    }
  }
  const std::uint64_t size = bytes.size();
  unsigned char trailer[8];
  for (int i = 0; i < 4; ++i) {
    trailer[i] = static_cast<unsigned char>(crc >> (8 * i));
    trailer[4 + i] = static_cast<unsigned char>(size >> (8 * i));  // ISIZE: the size modulo 2^32
  }
  out.write(trailer, sizeof trailer);
}

void writeData(OutputFile& out, std::span<const float> data, bool gzip, const fs::path& target) {
  std::vector<float> swapped;
  if constexpr (std::endian::native == std::endian::big) {  // NRRD files are written little-endian
    swapped.assign(data.begin(), data.end());
    swapBytes(swapped);
    data = swapped;
  }
  std::span<const unsigned char> bytes(reinterpret_cast<const unsigned char*>(data.data()), data.size_bytes());
  if (gzip) {
    writeGzip(out, bytes, target);
  } else {
    out.write(bytes.data(), bytes.size());
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------

NrrdHeader readNrrdHeader(const fs::path& path) {
  FilePtr file = openForReading(path, path, "");
  return parseHeader(path, file.get()).header;
}

NrrdImage readNrrd(const fs::path& path) {
  FilePtr header_file = openForReading(path, path, "");
  ParsedHeader parsed = parseHeader(path, header_file.get());
  FilePtr data_file;
  std::FILE* file = header_file.get();
  if (!parsed.attached) {
    data_file = openForReading(parsed.data_path, path, "data file");
    file = data_file.get();
  }
  skipLines(file, parsed.line_skip, path, parsed);

  if (parsed.encoding == Encoding::Raw) checkRawLength(file, path, parsed);  // before allocating

  NrrdImage image;
  image.components = parsed.header.components;
  image.sizes = parsed.header.sizes;
  image.origin = parsed.header.origin;
  image.directions = parsed.header.directions;
  image.data.resize(parsed.header.valueCount());  // sizes were checked against the limits
  std::span<float> values(image.data);
  switch (parsed.encoding) {
    case Encoding::Raw: readRaw(file, std::as_writable_bytes(values), path, parsed); break;
    case Encoding::Gzip: readGzip(file, std::as_writable_bytes(values), path, parsed); break;
    case Encoding::Ascii: readAscii(file, values, path, parsed); break;
  }
  if (parsed.encoding != Encoding::Ascii && parsed.big_endian != (std::endian::native == std::endian::big)) {
    swapBytes(values);
  }
  std::size_t bad = firstNonFinite(values);
  if (bad != values.size()) {
    fail(path, "data", dataSource(parsed) + describeSample(parsed.header, bad, values[bad]) +
                           " (fields must hold finite values)");
  }
  return image;
}

void stageNrrd(AtomicFileSet& files, const fs::path& path, const NrrdHeader& header, std::span<const float> data,
               const NrrdWriteOptions& options) {
  checkWritable(path, header, data);
  std::string data_file;
  if (options.detached) {
    fs::path data_target = detachedDataPath(path, options.gzip);
    data_file = data_target.filename().string();
    OutputFile out(files.stage(data_target), data_target);
    writeData(out, data, options.gzip, data_target);
    out.close();
  }
  std::string text = headerText(header, options, data_file);
  OutputFile out(files.stage(path), path);
  out.write(text.data(), text.size());
  if (!options.detached) {
    out.write("\n", 1);  // the blank line that ends an attached header
    writeData(out, data, options.gzip, path);
  }
  out.close();
}

void writeNrrd(const fs::path& path, const NrrdImage& image, const NrrdWriteOptions& options) {
  AtomicFileSet files;
  stageNrrd(files, path, image.header(), image.data, options);
  files.commit();
}

}  // namespace eik
