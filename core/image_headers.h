// Walks over an image file's headers before the format's own library reads them, refusing what
// would make that library allocate more than the file could hold.
//
// OpenEXR: a walk over the header(s) before OpenEXR itself reads them. OpenEXR 3.1 allocates an
// attribute's declared size before reading its value (any attribute of a type it does not know, its
// "opaque" attributes), and line-offset tables and tile buffers from the data window and tile size:
// a 100-byte file may claim gigabytes. Here every attribute's size must fit in the bytes the file
// has left, and the data window and tiles must fit the image size limit, or the file is refused
// naming the attribute (format: openexr.com, "OpenEXR File Layout").
#pragma once

#include <cstdint>
#include <filesystem>

namespace eik {

// InputError naming the file and the attribute for: no OpenEXR magic, a version other than 2, an
// attribute name or type over 255 bytes, an attribute whose size is negative or larger than the
// rest of the file, a value OpenEXR would read to another length than its declared size (a
// fixed-layout type of another size, a channel list, preview or string vector whose contents run
// past it or end before it: OpenEXR reads those by their contents, and its next attribute would
// not be the one walked here), an idmanifest, a header without its terminating zero byte, a
// dataWindow of zero or negative size or more than max_axis pixels an axis, and tiles of zero or
// more than max_axis pixels.
void checkExrHeaders(const std::filesystem::path& path, int max_axis);

// PNG: libpng (as Debian builds it) allocates a chunk's declared length before reading it (a
// 300-byte file declared 1.6 GB), and inflates compressed text and ICC profiles (zTXt, iTXt, iCCP)
// without a bound. InputError naming the file and the chunk for: no PNG signature, a chunk longer
// than 2³¹−1 bytes (the format's own limit) or than the bytes the file has left, and a compressed
// chunk that inflates to more than max_inflated_bytes (libpng's own default limit is 8 MB).
void checkPngChunks(const std::filesystem::path& path, std::uint64_t max_inflated_bytes = 8000000);

}  // namespace eik
