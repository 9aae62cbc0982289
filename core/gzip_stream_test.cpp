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

// Reads `stream` into a buffer of `size` bytes after skipping `skip`.
GzipReadResult read(const std::string& stream, std::size_t size, std::string* out = nullptr, std::uint64_t skip = 0) {
  FilePtr file(fmemopen(const_cast<char*>(stream.data()), stream.size(), "rb"));
  std::string buffer(size, '\0');
  GzipReadResult result = readGzipStream(file.get(), std::as_writable_bytes(std::span<char>(buffer)), skip);
  if (out) *out = buffer;
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
