// gzip streams (RFC 1952, through zlib) for the data sections of NRRD files (nrrd.h): streamed
// decompression from a file into a buffer, and compression on all worker threads into one ordinary
// gzip member.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <span>
#include <string>

namespace eik {

// How reading a gzip stream ended.
enum class GzipReadStatus {
  Complete,        // `out` is filled and the stream ends there
  InitFailed,      // zlib could not be initialised
  ReadError,       // the file could not be read (GzipReadResult::detail: the system's message)
  Surplus,         // the stream holds more than `out` (GzipReadResult::surplus: bytes beyond it so far)
  EndsEarly,       // the compressed data ends before `out` is filled
  MissingTrailer,  // `out` is filled, but the stream's end marker and checksum are missing
  Corrupt,         // not deflate data (GzipReadResult::detail: zlib's message)
  SkipNotReached,  // the data ends within the bytes to skip
  Truncated,       // the stream ends properly, but before `out` is filled
};

struct GzipReadResult {
  GzipReadStatus status = GzipReadStatus::Complete;
  std::size_t filled = 0;     // bytes of `out` written
  std::uint64_t surplus = 0;  // Surplus: decompressed bytes beyond `out`
  std::string detail;         // ReadError, Corrupt: what went wrong
};

// Streams the gzip (or zlib) data from the current position of `file` into `out`: the first `skip`
// decompressed bytes are dropped (teem applies byte skip after decompression), concatenated members
// are followed, and missing or surplus data ends the read with the status that says which. Stops
// at the first problem.
GzipReadResult readGzipStream(std::FILE* file, std::span<std::byte> out, std::uint64_t skip);

// Receives compressed bytes, in order.
using GzipSink = std::function<void(const void* bytes, std::size_t size)>;

// Writes `bytes` as one gzip member compressed pigz-style on all worker threads: the data is cut
// into blocks deflated independently (raw deflate, each primed with the 32 KiB before it as
// dictionary, ended by a sync flush so the bit streams concatenate), then written in order between a
// gzip header and the combined CRC-32 trailer. Any gzip reader (teem/ITK, VTK, pynrrd) sees one
// ordinary stream, and the output depends on neither the thread count nor the time (MTIME = 0).
// Throws RuntimeError "NAME: zlib init failed" or "NAME: gzip compression failed".
void writeGzipStream(std::span<const unsigned char> bytes, const GzipSink& write, const std::string& name);

}  // namespace eik
