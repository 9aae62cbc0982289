// NRRD ("Nearly Raw Raster Data", teem format spec https://teem.sourceforge.net/nrrd/format.html)
// reader and writer for the field files of a volume (docs/volume-format.md).
//
// Scope: float32 samples on a 3D grid with 1–4 interleaved components (the component axis first,
// x fastest, then y, then z). Written as NRRD0004 with `space: right-anterior-superior` (our world
// x, y, z are R, A, S, so 3D Slicer shows world coordinates unchanged), `space directions`,
// `space origin` (the centre of voxel 0), `kinds`, little-endian, raw or gzip — the fields ITK's
// NrrdIO (3D Slicer), ParaView's vtkNrrdReader and pynrrd need. Read: attached (.nrrd) and
// detached (.nhdr + `data file`) headers, raw / gzip / ascii encodings, either endianness, RAS,
// LPS and LAS spaces (converted to RAS), `spacings` when there are no `space directions`,
// `line skip` and `byte skip`. Every malformed input raises InputError naming the file and the
// header field ("x.ior.nrrd: sizes: expected 4 values for dimension 4, got 3").
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace eik {

class AtomicFileSet;

// Shape and placement of an image, without its samples.
struct NrrdHeader {
  int components = 1;                 // values per voxel, 1–4 (the NRRD's first axis when 4D)
  glm::ivec3 sizes{0};                // voxels along x, y, z
  glm::dvec3 origin{0.0};             // world position of the centre of voxel (0,0,0)
  glm::dmat3 directions{1.0};         // column a = world step from voxel i to i+1 along axis a
  // The key `eikonal_generation:=G`: the write of a volume this file belongs to (its manifest names
  // the same G; docs/volume-format.md "Writing"). Empty when the file has no such key.
  std::string generation;

  std::size_t voxelCount() const;
  std::size_t valueCount() const { return voxelCount() * static_cast<std::size_t>(components); }
};

// A whole image: `components` floats per voxel, interleaved, x fastest.
struct NrrdImage {
  int components = 1;
  glm::ivec3 sizes{0};
  glm::dvec3 origin{0.0};
  glm::dmat3 directions{1.0};
  std::vector<float> data;

  NrrdHeader header() const { return {components, sizes, origin, directions, {}}; }
  std::size_t voxelCount() const { return header().voxelCount(); }
};

struct NrrdWriteOptions {
  bool gzip = true;        // `encoding: gzip` (zlib, fastest level) or `raw`
  bool detached = false;   // header at the path given, data in `STEM.raw` / `STEM.raw.gz` beside it
};

// Reads an attached or detached NRRD. Throws InputError naming the file and the field for anything
// malformed or unsupported, for sizes over the limits (checked before allocating, core/limits.h)
// and for NaN/Inf samples.
NrrdImage readNrrd(const std::filesystem::path& path);

// Reads and validates only the header (including limits and, for detached headers, that the data
// file exists); the samples are not read.
NrrdHeader readNrrdHeader(const std::filesystem::path& path);

// Writes `image` atomically (temporary files, then rename). For a detached write the header goes to
// `path` (normally NAME.nhdr) and the data to NAME.raw(.gz) beside it, where NAME is `path` without
// a .nhdr/.nrrd extension. Throws RuntimeError for NaN/Inf samples, a data size that does not match
// the header, or an I/O failure.
void writeNrrd(const std::filesystem::path& path, const NrrdImage& image, const NrrdWriteOptions& options = {});

// The same, but staged into `files` (the caller commits): the data file is staged before its
// header. `data` must hold header.valueCount() floats.
void stageNrrd(AtomicFileSet& files, const std::filesystem::path& path, const NrrdHeader& header,
               std::span<const float> data, const NrrdWriteOptions& options = {});

// stageNrrd for data that is exactly what the attached NRRD `source` holds (read from it and not
// changed since): the header is written as stageNrrd writes it and the encoded samples are copied
// from `source` byte for byte, not encoded again. Only when `source` is attached, has no line or
// byte skip, holds the header's sizes and components in this machine's byte order, and is encoded
// as `options` asks (gzip or raw, attached); otherwise, or when it cannot be opened or parsed,
// nothing is staged and false is returned (the caller then stages the data itself).
bool stageNrrdCopy(AtomicFileSet& files, const std::filesystem::path& path, const NrrdHeader& header,
                   const std::filesystem::path& source, const NrrdWriteOptions& options = {});

// Name of the data file a detached write of `path` produces ("NAME.raw" or "NAME.raw.gz").
std::filesystem::path detachedDataPath(const std::filesystem::path& path, bool gzip);

}  // namespace eik
