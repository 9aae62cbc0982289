#include "core/nrrd_header.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <map>
#include <system_error>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "core/paths.h"
#include "core/text.h"

namespace eik::nrrd {
namespace fs = std::filesystem;

void fail(const fs::path& file, std::string_view field, const std::string& what) {
  throw InputError(file.string(), std::string(field), what);
}

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

namespace {

// ---------------------------------------------------------------------------------------------
// Lines and words

std::vector<std::string_view> splitWords(std::string_view text) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && isSpace(text[i])) ++i;
    std::size_t start = i;
    while (i < text.size() && !isSpace(text[i])) ++i;
    if (i > start) words.push_back(text.substr(start, i - start));
  }
  return words;
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

// "expected N values for dimension N, got M": a per-axis field with the wrong number of values.
std::string countMismatch(long long dimension, std::size_t got) {
  return "expected " + std::to_string(dimension) + " values for dimension " + std::to_string(dimension) + ", got " +
         std::to_string(got);
}

// ---------------------------------------------------------------------------------------------
// The field lines

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

struct FieldLine {
  std::string value;
  int line = 0;
};

// The fields of a header by canonical name, collected first: teem requires an order, we do not.
struct HeaderFields {
  fs::path path;
  std::map<std::string, FieldLine, std::less<>> lines;
  bool blank_line = false;  // the header ends with a blank line (attached data may follow)
  std::string generation;   // the key eikonal_generation:=G (core/nrrd.h)

  const std::string* find(std::string_view name) const {
    auto it = lines.find(name);
    return it == lines.end() ? nullptr : &it->second.value;
  }
  const std::string& require(std::string_view name) const {
    const std::string* value = find(name);
    if (!value) fail(path, name, "missing (a required NRRD field)");
    return *value;
  }
};

void readMagic(const fs::path& path, std::FILE* file) {
  std::string line;
  if (!readLine(file, line, path, 1)) fail(path, "magic", "file is empty (expected 'NRRD0004')");
  if (line.size() != 8 || line.compare(0, 7, "NRRD000") != 0 || line[7] < '1' || line[7] > '5') {
    fail(path, "magic", "expected 'NRRD0001' to 'NRRD0005', got " + inQuotes(line) + " (not a NRRD file?)");
  }
}

// The lines after the magic, up to the blank line or the end of the file.
HeaderFields readFields(const fs::path& path, std::FILE* file) {
  HeaderFields fields;
  fields.path = path;
  std::string line;
  int line_number = 1;
  while (readLine(file, line, path, ++line_number)) {
    if (line.empty()) {
      fields.blank_line = true;
      break;
    }
    if (line.front() == '#') continue;
    std::size_t colon = line.find(':');
    if (colon == std::string::npos) {
      fail(path, "header",
           "line " + std::to_string(line_number) + ": " + inQuotes(line) +
               " is neither a field ('name: value'), a key ('key:=value') nor a comment ('#')");
    }
    if (colon + 1 < line.size() && line[colon + 1] == '=') {  // key:=value; ours is the generation
      if (std::string_view(line).substr(0, colon) == "eikonal_generation") fields.generation = line.substr(colon + 2);
      continue;
    }
    std::string name = canonicalFieldName(std::string_view(line).substr(0, colon));
    std::string value(trim(std::string_view(line).substr(colon + 1)));
    if (fields.lines.count(name)) {
      fail(path, name, "given twice (lines " + std::to_string(fields.lines[name].line) + " and " +
                           std::to_string(line_number) + ")");
    }
    if (name == "data file" && (value.rfind("LIST", 0) == 0 || value.find('%') != std::string::npos)) {
      fail(path, name, "multi-file data (" + inQuotes(value) + ") is not supported; name one data file");
    }
    fields.lines[name] = {value, line_number};
  }
  return fields;
}

// ---------------------------------------------------------------------------------------------
// One function per field

// type: float32 only (docs/volume-format.md).
void parseType(const HeaderFields& fields) {
  std::string type = lower(fields.require("type"));
  if (type != "float") {
    fail(fields.path, "type", inQuotes(type) + " is not supported: volume fields must be 32-bit floats ('type: float')");
  }
}

// dimension: 3 (scalar) or 4 (component axis first).
int parseDimension(const HeaderFields& fields) {
  long long dimension = 0;
  if (!parseInteger(trim(fields.require("dimension")), dimension)) {
    fail(fields.path, "dimension", inQuotes(fields.require("dimension")) + " is not an integer");
  }
  if (dimension != 3 && dimension != 4) {
    fail(fields.path, "dimension",
         std::to_string(dimension) + " is not supported (expected 3, or 4 with the component axis first)");
  }
  return static_cast<int>(dimension);
}

// sizes: the component count (4D) and the grid, checked against the limits before anything is read.
void parseSizes(const HeaderFields& fields, ParsedHeader& parsed) {
  const fs::path& path = fields.path;
  const long long dimension = parsed.dimension;
  const int first_spatial = parsed.dimension - 3;
  std::vector<std::string_view> size_words = splitWords(fields.require("sizes"));
  if (static_cast<long long>(size_words.size()) != dimension) {
    fail(path, "sizes", countMismatch(dimension, size_words.size()));
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
}

// encoding: raw, gzip or ascii.
Encoding parseEncoding(const HeaderFields& fields) {
  std::string encoding = lower(fields.require("encoding"));
  if (encoding == "raw") return Encoding::Raw;
  if (encoding == "gzip" || encoding == "gz") return Encoding::Gzip;
  if (encoding == "ascii" || encoding == "text" || encoding == "txt") return Encoding::Ascii;
  if (encoding == "hex" || encoding == "bzip2" || encoding == "bz2" || encoding == "zrl") {
    fail(fields.path, "encoding", inQuotes(encoding) + " is not supported (use raw or gzip)");
  }
  fail(fields.path, "encoding", inQuotes(encoding) + " is not a NRRD encoding (expected raw or gzip)");
}

// endian: little or big (true), required unless the encoding is ascii.
bool parseEndian(const HeaderFields& fields, Encoding encoding) {
  if (encoding == Encoding::Ascii) return false;
  std::string endian = lower(fields.require("endian"));
  if (endian == "little") return false;
  if (endian == "big") return true;
  fail(fields.path, "endian", inQuotes(endian) + " is neither 'little' nor 'big'");
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

// kinds (optional): the component axis first, then three spatial axes.
void checkKinds(const HeaderFields& fields, const ParsedHeader& parsed) {
  const std::string* kinds_text = fields.find("kinds");
  if (!kinds_text) return;
  const fs::path& path = fields.path;
  const int first_spatial = parsed.dimension - 3;
  std::vector<std::string_view> kinds = splitWords(*kinds_text);
  if (static_cast<int>(kinds.size()) != parsed.dimension) {
    fail(path, "kinds", countMismatch(parsed.dimension, kinds.size()));
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

// space, or space dimension (3 only): the sign flips to RAS that apply to directions and origin.
glm::dvec3 parseSpace(const HeaderFields& fields) {
  const fs::path& path = fields.path;
  glm::dvec3 flip{1, 1, 1};
  const std::string* space = fields.find("space");
  const std::string* space_dimension = fields.find("space dimension");
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
  return flip;
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
    if (isSpace(text[i])) {
      ++i;
      continue;
    }
    std::size_t start = i;
    if (text[i] == '(') {
      std::size_t close = text.find(')', i);
      if (close == std::string_view::npos) fail(path, field, "unbalanced '(' in " + inQuotes(text));
      i = close + 1;
    } else {
      while (i < text.size() && !isSpace(text[i])) ++i;
    }
    items.push_back(text.substr(start, i - start));
  }
  return items;
}

// space directions, or else spacings; without either, unit steps along x, y, z. The axes must span
// the space.
glm::dmat3 parseSpaceDirections(const HeaderFields& fields, int dimension, const glm::dvec3& flip) {
  const fs::path& path = fields.path;
  const int first_spatial = dimension - 3;
  glm::dmat3 directions(1.0);
  if (const std::string* text = fields.find("space directions")) {
    std::vector<std::string_view> items = splitVectorList(*text, path, "space directions");
    if (static_cast<int>(items.size()) != dimension) {
      fail(path, "space directions", countMismatch(dimension, items.size()));
    }
    for (int a = 0; a < dimension; ++a) {
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
  } else if (const std::string* text = fields.find("spacings")) {
    std::vector<std::string_view> items = splitWords(*text);
    if (static_cast<int>(items.size()) != dimension) {
      fail(path, "spacings", countMismatch(dimension, items.size()));
    }
    for (int a = first_spatial; a < dimension; ++a) {
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
  return directions;
}

// space origin, or else axis mins (with centers); without either, the origin.
glm::dvec3 parseSpaceOrigin(const HeaderFields& fields, int dimension, const glm::dmat3& directions,
                            const glm::dvec3& flip) {
  const fs::path& path = fields.path;
  const int first_spatial = dimension - 3;
  glm::dvec3 origin(0.0);
  if (const std::string* text = fields.find("space origin")) {
    origin = parseVector(*text, path, "space origin") * flip;
  } else if (const std::string* text = fields.find("axis mins")) {
    // Without a space origin, teem places axis sample 0 at "axis min" (cell-centred: half a step in).
    std::vector<std::string_view> items = splitWords(*text);
    if (static_cast<int>(items.size()) != dimension) {
      fail(path, "axis mins", "expected " + std::to_string(dimension) + " values, got " +
                                  std::to_string(items.size()));
    }
    std::vector<std::string_view> centers;
    if (const std::string* centers_text = fields.find("centers")) centers = splitWords(*centers_text);
    for (int a = first_spatial; a < dimension; ++a) {
      double min = 0;
      std::string_view item = items[static_cast<std::size_t>(a)];
      if (!parseNumber(item, min) || !std::isfinite(min)) fail(path, "axis mins", inQuotes(item) + " is not a finite number");
      bool cell = static_cast<int>(centers.size()) == dimension &&
                  lower(centers[static_cast<std::size_t>(a)]) == "cell";
      int s = a - first_spatial;
      origin[s] = min + (cell ? 0.5 * directions[s][s] : 0.0);
    }
  }
  return origin;
}

// data file, or the data after the blank line that ends an attached header.
void parseDataFile(const HeaderFields& fields, ParsedHeader& parsed) {
  const fs::path& path = fields.path;
  if (const std::string* data_file = fields.find("data file")) {
    const fs::path data_path = resolveInsideFolder(path, "data file", *data_file);
    std::error_code ec;
    if (!fs::is_regular_file(data_path, ec)) fail(path, "data file", data_path.string() + ": not found");
    parsed.data_path = data_path;
    parsed.attached = false;
  } else if (fields.blank_line) {
    parsed.data_path = path;
    parsed.attached = true;  // the file is positioned at the first byte after the blank line
  } else if (path.extension() == ".nhdr") {
    fail(path, "data file", "missing (a detached header must name its data file)");
  } else {
    fail(path, "data", "missing: the header is neither followed by a blank line and data nor names a 'data file'");
  }
}

// line skip / byte skip: an offset >= 0 (0 when absent).
long long parseSkip(const HeaderFields& fields, std::string_view name) {
  long long skip = 0;
  const std::string* text = fields.find(name);
  if (!text) return skip;
  if (!parseInteger(trim(*text), skip)) fail(fields.path, name, inQuotes(*text) + " is not an integer");
  if (skip == -1) {
    fail(fields.path, name, "-1 (data at the end of the file) is not supported; give the offset");
  }
  if (skip < 0) fail(fields.path, name, std::to_string(skip) + " is negative");
  return skip;
}

}  // namespace

ParsedHeader parseHeader(const fs::path& path, std::FILE* file) {
  readMagic(path, file);
  const HeaderFields fields = readFields(path, file);
  ParsedHeader parsed;
  parseType(fields);
  parsed.dimension = parseDimension(fields);
  parseSizes(fields, parsed);
  parsed.encoding = parseEncoding(fields);
  parsed.big_endian = parseEndian(fields, parsed.encoding);
  checkKinds(fields, parsed);
  // Orientation: space + space directions + space origin, or spacings (+ axis mins).
  const glm::dvec3 flip = parseSpace(fields);
  parsed.header.directions = parseSpaceDirections(fields, parsed.dimension, flip);
  parsed.header.origin = parseSpaceOrigin(fields, parsed.dimension, parsed.header.directions, flip);
  parseDataFile(fields, parsed);
  parsed.header.generation = fields.generation;
  parsed.line_skip = parseSkip(fields, "line skip");
  parsed.byte_skip = parseSkip(fields, "byte skip");
  return parsed;
}

}  // namespace eik::nrrd
