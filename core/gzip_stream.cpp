#include "core/gzip_stream.h"

#include <libdeflate.h>
#include <sys/stat.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"

namespace eik {
namespace {

struct InflateStream {
  z_stream z{};
  bool ready = false;
  ~InflateStream() {
    if (ready) inflateEnd(&z);
  }
};

struct DeflateStream {
  z_stream z{};
  bool ready = false;
  ~DeflateStream() {
    if (ready) deflateEnd(&z);
  }
};

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

// The fast path: the rest of `file` read whole and decompressed by libdeflate, member after member,
// several times faster than zlib's streaming inflate (the 128³ sphere's interfaces field, 37 MB
// from 1.5 MB: 8 ms against 0.2 s). True only where the stream is gzip, fills `out` exactly and
// ends with the file; anywhere else (a byte skip, a zlib stream, a pipe, an error of any kind) the
// file is put back where it was and false returned, so that the streaming reader below reads it
// and says precisely what is wrong.
bool readWholeGzip(std::FILE* file, std::span<std::byte> out) {
  const long start = std::ftell(file);
  struct stat info {};
  if (start < 0 || fstat(fileno(file), &info) != 0 || !S_ISREG(info.st_mode) || info.st_size <= start) return false;
  std::vector<unsigned char> input(static_cast<std::size_t>(info.st_size - start));
  const std::size_t got = std::fread(input.data(), 1, input.size(), file);
  const std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> decompressor(libdeflate_alloc_decompressor());
  bool whole = got == input.size() && got >= 2 && input[0] == 0x1f && input[1] == 0x8b && decompressor != nullptr;
  std::size_t used = 0, filled = 0;
  while (whole && used < input.size()) {
    std::size_t member_in = 0, member_out = 0;
    whole = libdeflate_gzip_decompress_ex(decompressor.get(), input.data() + used, input.size() - used,
                                          out.data() + filled, out.size() - filled, &member_in,
                                          &member_out) == LIBDEFLATE_SUCCESS &&
            member_in > 0;
    used += member_in;
    filled += member_out;
  }
  if (whole && filled == out.size()) return true;
  std::clearerr(file);
  std::fseek(file, start, SEEK_SET);
  return false;
}

}  // namespace

GzipReadResult readGzipStream(std::FILE* file, std::span<std::byte> out, std::uint64_t skip) {
  GzipReadResult result;
  if (skip == 0 && readWholeGzip(file, out)) {
    result.filled = out.size();
    return result;
  }
  InflateStream stream;
  if (inflateInit2(&stream.z, 15 + 32) != Z_OK) {
    result.status = GzipReadStatus::InitFailed;
    return result;
  }
  stream.ready = true;
  z_stream& z = stream.z;
  auto end = [&](GzipReadStatus status, std::string detail = {}) {
    result.status = status;
    result.detail = std::move(detail);
    return result;
  };

  std::vector<unsigned char> input(std::size_t{1} << 20);
  std::vector<unsigned char> scratch(std::size_t{1} << 16);
  std::uint64_t skip_left = skip;
  std::size_t& filled = result.filled;
  std::uint64_t& extra = result.surplus;
  bool end_of_file = false;
  bool stream_ended = false;

  while (true) {
    if (z.avail_in == 0 && !end_of_file) {
      std::size_t n = std::fread(input.data(), 1, input.size(), file);
      if (n == 0) {
        if (std::ferror(file)) return end(GzipReadStatus::ReadError, std::strerror(errno));
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
      if (extra > 0) return end(GzipReadStatus::Surplus);
    }
    if (status == Z_STREAM_END) {
      stream_ended = true;
    } else if (status == Z_BUF_ERROR) {
      // No progress is possible: more input is needed, and there is none.
      if (z.avail_in == 0 && end_of_file) {
        return end(filled < out.size() ? GzipReadStatus::EndsEarly : GzipReadStatus::MissingTrailer);
      }
    } else if (status != Z_OK) {
      return end(GzipReadStatus::Corrupt, z.msg ? z.msg : "zlib error");
    }
  }
  if (skip_left > 0) return end(GzipReadStatus::SkipNotReached);
  if (filled < out.size()) return end(GzipReadStatus::Truncated);
  return result;
}

void writeGzipStream(std::span<const unsigned char> bytes, const GzipSink& write, const std::string& name) {
  constexpr std::size_t kBlock = std::size_t{4} << 20;
  constexpr std::size_t kWindow = 32768;
  const std::size_t blocks = std::max<std::size_t>(1, (bytes.size() + kBlock - 1) / kBlock);
  // ID1 ID2 CM=deflate FLG=0 MTIME=0 (reproducible output) XFL=4 (fastest) OS=3 (Unix)
  const unsigned char header[10] = {0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 4, 3};
  write(header, sizeof header);

  uLong crc = crc32(0, Z_NULL, 0);
  const std::size_t batch = 2 * static_cast<std::size_t>(workerThreads());
  // Each block's output, in a buffer left uninitialised: only the pages deflate writes are touched
  // (a std::string sized to deflateBound would zero the whole bound, about the block's own size,
  // when a float field compresses to a tenth of it).
  struct Output {
    std::unique_ptr<unsigned char[]> bytes;
    std::size_t capacity = 0, size = 0;
    void grow(std::size_t to) {
      std::unique_ptr<unsigned char[]> larger(new unsigned char[to]);
      if (size > 0) std::memcpy(larger.get(), bytes.get(), size);
      bytes = std::move(larger);
      capacity = to;
    }
  };
  std::vector<Output> compressed(batch);
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
        throw RuntimeError(name + ": zlib init failed");
      }
      stream.ready = true;
      z_stream& z = stream.z;
      if (block > 0) deflateSetDictionary(&z, bytes.data() + begin - kWindow, static_cast<uInt>(kWindow));
      Output& output = compressed[static_cast<std::size_t>(k)];
      output.size = 0;
      // Room for an eighth of the block to start with (a float field compresses to a tenth or
      // less), grown by doubling when deflate needs more: the buffers of a batch are then small
      // enough to share the allocator's 2 MiB pages (core/allocator.cpp), where buffers of
      // deflateBound's size, about the block's own, each touched a page of their own for a few
      // hundred KiB of output (the 128³ voxelize: six of them, 12 MB of fresh memory for 0.9 MB).
      const std::size_t start = std::min<std::size_t>(deflateBound(&z, static_cast<uLong>(length)) + 64, length / 8 + 65536);
      if (output.capacity < start) output.grow(start);
      z.next_in = const_cast<unsigned char*>(bytes.data() + begin);
      z.avail_in = static_cast<uInt>(length);
      while (true) {
        z.next_out = output.bytes.get() + output.size;
        z.avail_out = static_cast<uInt>(output.capacity - output.size);
        int status = deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH);
        output.size = output.capacity - z.avail_out;
        if (status == Z_STREAM_ERROR) throw RuntimeError(name + ": gzip compression failed");
        if (last ? status == Z_STREAM_END : (z.avail_in == 0 && z.avail_out != 0)) break;
        output.grow(output.capacity * 2);  // deflate filled the buffer: twice the room, the bytes so far kept
      }
      // libdeflate's CRC-32 (the same checksum, carry-less multiplication: several times zlib's speed).
      crcs[static_cast<std::size_t>(k)] = libdeflate_crc32(0, bytes.data() + begin, length);
    });
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t length = std::min(kBlock, bytes.size() - (first + k) * kBlock);
      write(compressed[k].bytes.get(), compressed[k].size);
      crc = crc32_combine(crc, crcs[k], static_cast<z_off_t>(length));
    }
  }
  const std::uint64_t size = bytes.size();
  unsigned char trailer[8];
  for (int i = 0; i < 4; ++i) {
    trailer[i] = static_cast<unsigned char>(crc >> (8 * i));
    trailer[4 + i] = static_cast<unsigned char>(size >> (8 * i));  // ISIZE: the size modulo 2^32
  }
  write(trailer, sizeof trailer);
}

}  // namespace eik
