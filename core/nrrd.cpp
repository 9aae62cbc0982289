#include "core/nrrd.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/gzip_stream.h"
#include "core/limits.h"
#include "core/nrrd_header.h"
#include "core/text.h"

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

using nrrd::Encoding;
using nrrd::fail;
using nrrd::inQuotes;
using nrrd::ParsedHeader;

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

// For gzip and ASCII data the file length bounds what the data can hold, before anything is
// allocated: deflate expands at most 1032:1, and an ASCII value takes at least two characters
// (a digit and a separator). A header that declares more (a 250-byte file claiming 1024³ values)
// is refused at once instead of allocating and zero-filling gigabytes first.
void checkEncodedLength(std::FILE* file, const fs::path& path, const ParsedHeader& parsed) {
  off_t here = ftello(file);
  if (here < 0 || fseeko(file, 0, SEEK_END) != 0) return;  // not seekable: the readers check as they read
  off_t end = ftello(file);
  fseeko(file, here, SEEK_SET);
  const std::uint64_t available =
      end - here > parsed.byte_skip ? static_cast<std::uint64_t>(end - here - parsed.byte_skip) : 0;
  const std::uint64_t values = parsed.header.valueCount();
  if (parsed.encoding == Encoding::Gzip) {
    constexpr std::uint64_t kMaxDeflateRatio = 1032;
    const std::uint64_t expected = values * sizeof(float);
    if (expected / kMaxDeflateRatio > available + 64)
      fail(path, "data", dataSource(parsed) + "truncated: sizes need " + std::to_string(expected) +
                             " bytes of float32 data; a gzip stream of " + std::to_string(available) +
                             " bytes holds at most " + std::to_string(available * kMaxDeflateRatio));
  } else if (parsed.encoding == Encoding::Ascii) {
    if (values > available / 2 + 1)
      fail(path, "data", dataSource(parsed) + "truncated: sizes call for " + std::to_string(values) + " values, " +
                             std::to_string(available) + " bytes of text hold at most " +
                             std::to_string(available / 2 + 1));
  }
}

// A gzip data section (core/gzip_stream.h), with the messages of the other encodings.
void readGzip(std::FILE* file, std::span<std::byte> out, const fs::path& path, const ParsedHeader& parsed) {
  const GzipReadResult read = readGzipStream(file, out, static_cast<std::uint64_t>(parsed.byte_skip));
  switch (read.status) {
    case GzipReadStatus::Complete:
      return;
    case GzipReadStatus::InitFailed:
      throw RuntimeError(path.string() + ": data: zlib init failed");
    case GzipReadStatus::ReadError:
      fail(path, "data", dataSource(parsed) + "read error: " + read.detail);
    case GzipReadStatus::Surplus:
      fail(path, "data", tooMuchMessage(parsed, out.size(), read.surplus, true));
    case GzipReadStatus::EndsEarly:
      fail(path, "data", truncatedMessage(parsed, out.size(), read.filled) + " (the gzip stream ends early)");
    case GzipReadStatus::MissingTrailer:
      fail(path, "data", dataSource(parsed) + "truncated gzip stream (its end marker and checksum are missing)");
    case GzipReadStatus::Corrupt:
      fail(path, "data", dataSource(parsed) + "corrupt gzip data (" + read.detail + ")");
    case GzipReadStatus::SkipNotReached:
      fail(path, "byte skip", dataSource(parsed) + "the data ends within the " + std::to_string(parsed.byte_skip) +
                                  " bytes to skip");
    case GzipReadStatus::Truncated:
      fail(path, "data", truncatedMessage(parsed, out.size(), read.filled));
  }
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
  auto separator = [](char c) { return isSpace(c) || c == ','; };
  while (true) {
    while (i < text.size() && separator(text[i])) ++i;
    if (i == text.size()) break;
    std::size_t start = i;
    while (i < text.size() && !separator(text[i])) ++i;
    std::string_view word(text.data() + start, i - start);
    double value = 0;
    if (!nrrd::parseNumber(word, value)) fail(path, "data", dataSource(parsed) + inQuotes(word) + " is not a number");
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
// The first value `bad` says is bad (from its IEEE 754 bits), or values.size(): blocks of values
// are tested without a branch (vectorised; fields are tens of millions of values, read and
// written by every program), the first bad block value by value.
template <typename Bad>
std::size_t firstBad(std::span<const float> values, Bad bad) {
  constexpr std::size_t kBlock = 1024;
  for (std::size_t begin = 0; begin < values.size(); begin += kBlock) {
    const std::size_t end = std::min(values.size(), begin + kBlock);
    unsigned any = 0;
    for (std::size_t i = begin; i < end; ++i) any |= bad(std::bit_cast<std::uint32_t>(values[i])) ? 1u : 0u;
    if (any == 0) continue;
    for (std::size_t i = begin; i < end; ++i)
      if (bad(std::bit_cast<std::uint32_t>(values[i]))) return i;
  }
  return values.size();
}

// An exponent of all ones: infinity or NaN.
std::size_t firstNonFinite(std::span<const float> values) {
  return firstBad(values, [](std::uint32_t bits) { return (bits & 0x7F800000u) == 0x7F800000u; });
}

// Index of the first subnormal value (0 < |v| < FLT_MIN: exponent 0, mantissa not), or
// values.size(). Fields never hold them (the writer flushes them to 0); in a file they are the
// sign of bytes read in the wrong order (n = 1.5 byte-swapped reads as 4.6·10⁻⁴¹).
std::size_t firstSubnormal(std::span<const float> values) {
  return firstBad(values, [](std::uint32_t bits) { return ((bits & 0x7F800000u) == 0u) & ((bits & 0x007FFFFFu) != 0u); });
}

// "voxel (x, y, z)" and " component c" of a value index.
std::string sampleLocation(const NrrdHeader& header, std::size_t index) {
  std::size_t components = static_cast<std::size_t>(header.components);
  std::size_t voxel = index / components;
  std::size_t sx = static_cast<std::size_t>(header.sizes.x), sy = static_cast<std::size_t>(header.sizes.y);
  std::string where = "voxel (" + std::to_string(voxel % sx) + ", " + std::to_string((voxel / sx) % sy) + ", " +
                      std::to_string(voxel / (sx * sy)) + ")";
  if (components > 1) where += " component " + std::to_string(index % components);
  return where;
}

std::string describeSample(const NrrdHeader& header, std::size_t index, float value) {
  return std::string(std::isnan(value) ? "NaN" : (value > 0 ? "+Inf" : "-Inf")) + " at " + sampleLocation(header, index);
}

// ---------------------------------------------------------------------------------------------
// Writing

std::string formatNumber(double value) {
  char text[32];
  auto [end, ec] = std::to_chars(text, text + sizeof text, value);  // shortest exact round trip
  return ec == std::errc() ? std::string(text, end) : std::string("nan");
}

std::string formatVector(const glm::dvec3& v) {
  return "(" + formatNumber(v.x) + "," + formatNumber(v.y) + "," + formatNumber(v.z) + ")";
}

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
  text += "# Eikonal volume field (float32, x fastest; docs/volume-format.md)\n";
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
  if (!header.generation.empty()) text += "eikonal_generation:=" + header.generation + "\n";
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

void writeData(OutputFile& out, std::span<const float> data, bool gzip, const fs::path& target) {
  std::vector<float> flushed;
  if (firstSubnormal(data) != data.size()) {  // below FLT_MIN: written as 0, so readers can refuse them
    flushed.assign(data.begin(), data.end());
    for (float& v : flushed)
      if (std::fpclassify(v) == FP_SUBNORMAL) v = 0.0f;
    data = flushed;
  }
  std::vector<float> swapped;
  if constexpr (std::endian::native == std::endian::big) {  // NRRD files are written little-endian
    swapped.assign(data.begin(), data.end());
    swapBytes(swapped);
    data = swapped;
  }
  std::span<const unsigned char> bytes(reinterpret_cast<const unsigned char*>(data.data()), data.size_bytes());
  if (gzip) {
    writeGzipStream(bytes, [&out](const void* data, std::size_t size) { out.write(data, size); }, target.string());
  } else {
    out.write(bytes.data(), bytes.size());
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------

NrrdHeader readNrrdHeader(const fs::path& path) {
  FilePtr file = openForReading(path, path, "");
  return nrrd::parseHeader(path, file.get()).header;
}

NrrdImage readNrrd(const fs::path& path) {
  FilePtr header_file = openForReading(path, path, "");
  ParsedHeader parsed = nrrd::parseHeader(path, header_file.get());
  FilePtr data_file;
  std::FILE* file = header_file.get();
  if (!parsed.attached) {
    data_file = openForReading(parsed.data_path, path, "data file");
    file = data_file.get();
  }
  skipLines(file, parsed.line_skip, path, parsed);

  if (parsed.encoding == Encoding::Raw) checkRawLength(file, path, parsed);  // before allocating
  else checkEncodedLength(file, path, parsed);

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
  bad = firstSubnormal(values);
  if (bad != values.size()) {
    char value[32];
    std::snprintf(value, sizeof value, "%.2g", static_cast<double>(values[bad]));
    fail(path, "data", dataSource(parsed) + "subnormal value " + value + " at " + sampleLocation(parsed.header, bad) +
                           (parsed.encoding == Encoding::Ascii
                                ? " (fields hold no magnitudes below 1.2e-38)"
                                : " (fields hold no magnitudes below 1.2e-38: is the header's 'endian' right? "
                                  "floats read in the wrong byte order look like this)"));
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

bool stageNrrdCopy(AtomicFileSet& files, const fs::path& path, const NrrdHeader& header, const fs::path& source,
                   const NrrdWriteOptions& options) {
  if (options.detached) return false;
  FilePtr in(std::fopen(source.c_str(), "rb"));
  if (!in) return false;
  ParsedHeader parsed;
  try {
    parsed = nrrd::parseHeader(source, in.get());  // leaves `in` at the samples of an attached file
  } catch (const InputError&) {
    return false;
  }
  const Encoding wanted = options.gzip ? Encoding::Gzip : Encoding::Raw;
  if (!parsed.attached || parsed.line_skip != 0 || parsed.byte_skip != 0 || parsed.encoding != wanted ||
      parsed.big_endian != (std::endian::native == std::endian::big) || parsed.header.sizes != header.sizes ||
      parsed.header.components != header.components)
    return false;
  const std::string text = headerText(header, options, "");
  OutputFile out(files.stage(path), path);
  out.write(text.data(), text.size());
  out.write("\n", 1);  // the blank line that ends an attached header
  std::vector<char> buffer(std::size_t{1} << 20);
  for (;;) {
    const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), in.get());
    out.write(buffer.data(), n);
    if (n < buffer.size()) {
      if (std::ferror(in.get())) throw RuntimeError(source.string() + ": read failed: " + std::strerror(errno));
      break;
    }
  }
  out.close();
  return true;
}

void writeNrrd(const fs::path& path, const NrrdImage& image, const NrrdWriteOptions& options) {
  AtomicFileSet files;
  stageNrrd(files, path, image.header(), image.data, options);
  files.commit();
}

}  // namespace eik
