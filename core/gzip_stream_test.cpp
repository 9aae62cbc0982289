// gzip streams: what writeGzipStream writes, readGzipStream (and zlib) read back bit for bit, and
// every way a stream can be wrong ends the read with its own status.
#include "core/gzip_stream.h"

#include <zlib.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace eik {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

std::string compressed(const std::string& bytes) {
  std::string out;
  writeGzipStream({reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()},
                  [&](const void* data, std::size_t size) { out.append(static_cast<const char*>(data), size); }, "test");
  return out;
}

GzipReadResult readFrom(std::FILE* file, std::size_t size, std::string& buffer, std::uint64_t skip) {
  buffer.assign(size, '\0');
  return readGzipStream(file, std::as_writable_bytes(std::span<char>(buffer)), skip);
}

// Reads `stream` into a buffer of `size` bytes after skipping `skip`, twice: from memory (a stream
// without a file descriptor: zlib's streaming reader alone) and from a temporary file (libdeflate's
// whole-stream path first, falling back to the streaming reader on anything unusual). Both must
// end the same way with the same bytes, whichever path took the file.
GzipReadResult read(const std::string& stream, std::size_t size, std::string* out = nullptr, std::uint64_t skip = 0) {
  FilePtr memory(fmemopen(const_cast<char*>(stream.data()), stream.size(), "rb"));
  std::string streamed, whole;
  const GzipReadResult result = readFrom(memory.get(), size, streamed, skip);
  FilePtr file(std::tmpfile());
  EXPECT_EQ(std::fwrite(stream.data(), 1, stream.size(), file.get()), stream.size());
  std::rewind(file.get());
  const GzipReadResult from_file = readFrom(file.get(), size, whole, skip);
  EXPECT_EQ(from_file.status, result.status);
  EXPECT_EQ(from_file.filled, result.filled);
  EXPECT_EQ(from_file.surplus, result.surplus);
  EXPECT_EQ(whole.substr(0, from_file.filled), streamed.substr(0, result.filled));
  if (out) *out = streamed;
  return result;
}

std::string randomBytes(std::size_t size) {
  std::mt19937 random(5);
  std::string bytes(size, '\0');
  for (std::size_t i = 0; i < size; ++i) bytes[i] = static_cast<char>(random() % 7);  // compressible
  return bytes;
}

TEST(GzipStream, RoundTripsAcrossBlocksAndZlibAgrees) {
  for (std::size_t size : {std::size_t{0}, std::size_t{1000}, (std::size_t{9} << 20) + 3}) {  // 0, 1, 3 blocks
    const std::string bytes = randomBytes(size);
    const std::string stream = compressed(bytes);
    std::string back;
    const GzipReadResult result = read(stream, size, &back);
    EXPECT_EQ(result.status, GzipReadStatus::Complete) << size;
    EXPECT_EQ(result.filled, size);
    EXPECT_EQ(back, bytes);
    // One ordinary gzip member, as zlib itself reads it.
    std::string inflated(size + 1, '\0');
    z_stream z{};
    ASSERT_EQ(inflateInit2(&z, 15 + 16), Z_OK);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(stream.data()));
    z.avail_in = static_cast<uInt>(stream.size());
    z.next_out = reinterpret_cast<Bytef*>(inflated.data());
    z.avail_out = static_cast<uInt>(inflated.size());
    EXPECT_EQ(inflate(&z, Z_FINISH), Z_STREAM_END);
    EXPECT_EQ(z.total_out, size);
    EXPECT_EQ(z.avail_in, 0u) << "one member";
    inflateEnd(&z);
    EXPECT_EQ(inflated.substr(0, size), bytes);
  }
}

// A block's output buffer starts at an eighth of the block and grows as deflate fills it: bytes
// that do not compress at all (stored, a little longer than they are) round-trip too.
TEST(GzipStream, RoundTripsWhatDoesNotCompress) {
  std::mt19937 random(11);
  std::string bytes((std::size_t{5} << 20) + 7, '\0');
  for (char& b : bytes) b = static_cast<char>(random());
  const std::string stream = compressed(bytes);
  EXPECT_GT(stream.size(), bytes.size());
  std::string back;
  const GzipReadResult result = read(stream, bytes.size(), &back);
  EXPECT_EQ(result.status, GzipReadStatus::Complete);
  EXPECT_EQ(back, bytes);
}

TEST(GzipStream, OutputDoesNotDependOnTheThreadCount) {
  const std::string bytes = randomBytes((std::size_t{9} << 20) + 3);
  ::setenv("EIKONAL_THREADS", "1", 1);
  const std::string one = compressed(bytes);
  ::setenv("EIKONAL_THREADS", "3", 1);
  const std::string three = compressed(bytes);
  ::unsetenv("EIKONAL_THREADS");
  EXPECT_EQ(one, three);
}

TEST(GzipStream, SkipsAndFollowsConcatenatedMembers) {
  const std::string a = randomBytes(5000), b = "tail of the second member";
  const std::string stream = compressed(a) + compressed(b);
  std::string back;
  EXPECT_EQ(read(stream, a.size() + b.size() - 100, &back, 100).status, GzipReadStatus::Complete);
  EXPECT_EQ(back, (a + b).substr(100));
  EXPECT_EQ(read(stream, 10, nullptr, a.size() + b.size()).status, GzipReadStatus::Truncated);
  EXPECT_EQ(read(stream, 0, nullptr, a.size() + b.size() + 1).status, GzipReadStatus::SkipNotReached);
  // Without a skip (libdeflate's path from a file): both members, then an empty third one.
  EXPECT_EQ(read(stream + compressed(""), a.size() + b.size(), &back).status, GzipReadStatus::Complete);
  EXPECT_EQ(back, a + b);
}

// A file read from where its header ended (as readNrrd hands it over), and the fast path's
// refusal puts it back there for the streaming reader.
TEST(GzipStream, ReadsFromTheFilesPositionAndFallsBackFromThere) {
  const std::string bytes = randomBytes(6000);
  const std::string header = "NRRD0004\nencoding: gzip\n\n";
  for (const bool corrupt : {false, true}) {
    std::string stream = compressed(bytes);
    if (corrupt) stream[stream.size() / 2] = static_cast<char>(stream[stream.size() / 2] ^ 0x55);
    FilePtr file(std::tmpfile());
    const std::string contents = header + stream;
    ASSERT_EQ(std::fwrite(contents.data(), 1, contents.size(), file.get()), contents.size());
    ASSERT_EQ(std::fseek(file.get(), static_cast<long>(header.size()), SEEK_SET), 0);
    std::string back;
    const GzipReadResult result = readFrom(file.get(), bytes.size(), back, 0);
    if (!corrupt) {
      EXPECT_EQ(result.status, GzipReadStatus::Complete);
      EXPECT_EQ(back, bytes);
    } else {
      EXPECT_NE(result.status, GzipReadStatus::Complete) << "a damaged stream is not read as whole";
    }
  }
}

TEST(GzipStream, EveryWayToBeWrong) {
  const std::string bytes = randomBytes(4000);
  const std::string stream = compressed(bytes);
  GzipReadResult r = read(stream, bytes.size() - 1);
  EXPECT_EQ(r.status, GzipReadStatus::Surplus);
  EXPECT_GT(r.surplus, 0u);
  r = read(stream, bytes.size() + 1);
  EXPECT_EQ(r.status, GzipReadStatus::Truncated);
  EXPECT_EQ(r.filled, bytes.size());
  r = read(stream.substr(0, stream.size() / 2), bytes.size());
  EXPECT_EQ(r.status, GzipReadStatus::EndsEarly);
  EXPECT_LT(r.filled, bytes.size());
  EXPECT_EQ(read(stream.substr(0, stream.size() - 4), bytes.size()).status, GzipReadStatus::MissingTrailer);
  std::string corrupt = stream;
  corrupt[3] = static_cast<char>(0xff);  // reserved flag bits
  r = read(corrupt, bytes.size());
  EXPECT_EQ(r.status, GzipReadStatus::Corrupt);
  EXPECT_FALSE(r.detail.empty());
}

}  // namespace
}  // namespace eik
