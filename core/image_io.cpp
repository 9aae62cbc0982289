#include "core/image_io.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <png.h>
#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_headers.h"
#include "core/limits.h"
#include "core/text.h"

namespace eik {
namespace {

std::string lowerExtension(const std::filesystem::path& path) { return lower(path.extension().string()); }

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

File openFile(const std::filesystem::path& path, const char* mode) {
  File f(std::fopen(path.c_str(), mode));
  if (!f) throw InputError(path.string(), "", std::string("cannot open: ") + std::strerror(errno));
  return f;
}

// Pixels as a format's reader decoded them: the file's own channels (up to 4) as floats, rows top to
// bottom, and whether they are display-encoded integers (sRGB unless the file says linear).
struct Decoded {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;
  bool display_encoded = false;
};

// Before a pixel is allocated: the size a header claims (a 60-byte .hdr may claim 32768²), and the
// memory of the file's pixels as stored (`stored_bytes` a pixel, all its channels), the float pixels
// and as much again for what is made of them (an environment's mipmaps, a converted copy), and a
// row of all channels.
void checkImageSize(const std::filesystem::path& path, std::int64_t width, std::int64_t height, int channels,
                    std::uint64_t stored_bytes, int stored_channels) {
  if (width <= 0 || height <= 0 || channels <= 0) throw InputError(path.string(), "", "image has no pixels");
  if (width > kMaxImageAxis || height > kMaxImageAxis)
    throw InputError(path.string(), "size",
                     std::to_string(width) + "x" + std::to_string(height) + " is larger than " +
                         std::to_string(kMaxImageAxis) + " pixels an axis");
  const std::uint64_t pixel_count = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
  checkMemoryLimit(path.string(), "size",
                   pixel_count * stored_bytes + 2ull * pixel_count * static_cast<std::uint64_t>(channels) * sizeof(float) +
                       static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(stored_channels) * sizeof(float));
}

// ---------------------------------------------------------------------------------------------
// OpenEXR: any compression, scanlines or tiles, the first part; R, G, B (and A) by name, else Y
// (and A), else the first four channels in the file's (alphabetical) order.

Decoded readExr(const std::filesystem::path& path) {
  // Before OpenEXR allocates what the header declares (core/image_headers.h).
  checkExrHeaders(path, kMaxImageAxis);
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const Imath::Box2i window = header.dataWindow();
    const std::int64_t width = static_cast<std::int64_t>(window.max.x) - window.min.x + 1;
    const std::int64_t height = static_cast<std::int64_t>(window.max.y) - window.min.y + 1;
    std::vector<std::string> all;
    std::uint64_t stored_bytes = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      all.emplace_back(it.name());
      stored_bytes += it.channel().type == Imf::HALF ? 2 : 4;
    }
    auto has = [&](const char* name) { return header.channels().findChannel(name) != nullptr; };
    std::vector<std::string> picked;
    if (has("R") && has("G") && has("B")) picked = {"R", "G", "B"};
    else if (has("Y")) picked = {"Y"};
    if (!picked.empty() && has("A")) picked.emplace_back("A");
    if (picked.empty()) picked.assign(all.begin(), all.begin() + std::min<std::ptrdiff_t>(4, static_cast<std::ptrdiff_t>(all.size())));
    const int channels = static_cast<int>(picked.size());
    checkImageSize(path, width, height, channels, stored_bytes, static_cast<int>(all.size()));
    for (const std::string& name : picked) {
      const Imf::Channel* c = header.channels().findChannel(name);
      if (c->xSampling != 1 || c->ySampling != 1)
        throw InputError(path.string(), name, "subsampled channels are not read");
    }
    Decoded d;
    d.width = static_cast<int>(width);
    d.height = static_cast<int>(height);
    d.channels = channels;
    d.pixels.assign(static_cast<std::size_t>(width * height) * static_cast<std::size_t>(channels), 0.0f);
    Imf::FrameBuffer frame;
    const std::size_t x_stride = sizeof(float) * static_cast<std::size_t>(channels);
    for (int c = 0; c < channels; ++c)
      frame.insert(picked[static_cast<std::size_t>(c)],
                   Imf::Slice::Make(Imf::FLOAT, d.pixels.data() + c, window, x_stride, x_stride * static_cast<std::size_t>(width)));
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return d;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path.string(), "", std::string("cannot read image as exr: ") + e.what());
  }
}

// Linear half-float R, G, B (and A), zip-compressed; a one-channel image as Y.
void writeExr(const std::filesystem::path& target, const std::filesystem::path& temporary, const Image& image) {
  const int channels = std::min(image.channels, 4);
  static const char* const kNames[4][4] = {{"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (int c = 0; c < channels; ++c) header.channels().insert(kNames[channels - 1][c], Imf::Channel(Imf::HALF));
    // OpenEXR writes a channel from a slice of its own type: the pixels rounded to half here.
    const std::size_t count = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
    std::vector<Imath::half> halves(count * static_cast<std::size_t>(channels));
    for (std::size_t p = 0; p < count; ++p)
      for (int c = 0; c < channels; ++c)
        halves[p * static_cast<std::size_t>(channels) + static_cast<std::size_t>(c)] =
            Imath::half(image.pixels[p * static_cast<std::size_t>(image.channels) + static_cast<std::size_t>(c)]);
    Imf::OutputFile file(temporary.c_str(), header);
    Imf::FrameBuffer frame;
    const std::size_t x_stride = sizeof(Imath::half) * static_cast<std::size_t>(channels);
    for (int c = 0; c < channels; ++c)
      frame.insert(kNames[channels - 1][c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(halves.data() + c), x_stride,
                                                       x_stride * static_cast<std::size_t>(image.width)));
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw RuntimeError(target.string() + ": cannot write image: " + e.what());
  }
}

// ---------------------------------------------------------------------------------------------
// PNG through libpng: palette, grey and tRNS expanded, 16-bit kept. libpng reports errors by
// longjmp, so each call into it sits in a function of its own with a setjmp and nothing to
// destroy between the two; the error's text is kept and thrown from outside.

struct PngError {
  char message[256] = {};
};

void pngError(png_structp png, png_const_charp message) {
  auto* error = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(error->message, sizeof(error->message), "%s", message);
  png_longjmp(png, 1);
}

void pngWarning(png_structp, png_const_charp) {}

class PngReader {
 public:
  explicit PngReader(std::FILE* file) {
    png_ = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error_, pngError, pngWarning);
    if (png_) info_ = png_create_info_struct(png_);
    file_ = file;
  }
  ~PngReader() { png_destroy_read_struct(&png_, info_ ? &info_ : nullptr, nullptr); }
  PngReader(const PngReader&) = delete;
  PngReader& operator=(const PngReader&) = delete;

  const char* error() const { return error_.message[0] ? error_.message : "out of memory"; }

  // Reads the header and sets the expansions; false on an error (error()).
  bool readHeader() {
    if (!png_ || !info_) return false;
    if (setjmp(png_jmpbuf(png_))) return false;
    png_init_io(png_, file_);
    png_read_info(png_, info_);
    const int color_type = png_get_color_type(png_, info_);
    const int depth = png_get_bit_depth(png_, info_);
    if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png_);
    if (color_type == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png_);
    if (png_get_valid(png_, info_, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png_);
    if (depth == 16) png_set_swap(png_);  // to the machine's (little-endian) uint16
    png_set_interlace_handling(png_);
    png_read_update_info(png_, info_);
    width_ = png_get_image_width(png_, info_);
    height_ = png_get_image_height(png_, info_);
    channels_ = png_get_channels(png_, info_);
    depth_ = png_get_bit_depth(png_, info_);
    row_bytes_ = png_get_rowbytes(png_, info_);
    // Linear only where the file says so: a gAMA of 1 and no sRGB chunk.
    double gamma = 0.0;
    linear_ = !png_get_valid(png_, info_, PNG_INFO_sRGB) && png_get_gAMA(png_, info_, &gamma) && std::fabs(gamma - 1.0) < 1e-3;
    return true;
  }

  // Reads every row into `rows` (height × rowBytes()); false on an error.
  bool readRows(unsigned char* rows) {
    row_pointers_.resize(height_);
    for (png_uint_32 y = 0; y < height_; ++y) row_pointers_[y] = rows + static_cast<std::size_t>(y) * row_bytes_;
    if (setjmp(png_jmpbuf(png_))) return false;
    png_read_image(png_, row_pointers_.data());
    png_read_end(png_, nullptr);
    return true;
  }

  png_uint_32 width() const { return width_; }
  png_uint_32 height() const { return height_; }
  int channels() const { return channels_; }
  int depth() const { return depth_; }
  std::size_t rowBytes() const { return row_bytes_; }
  bool linear() const { return linear_; }

 private:
  PngError error_;
  png_structp png_ = nullptr;
  png_infop info_ = nullptr;
  std::FILE* file_ = nullptr;
  png_uint_32 width_ = 0, height_ = 0;
  int channels_ = 0, depth_ = 8;
  std::size_t row_bytes_ = 0;
  bool linear_ = false;
  std::vector<png_bytep> row_pointers_;
};

Decoded readPng(const std::filesystem::path& path) {
  // Before libpng allocates what the chunks declare (core/image_headers.h).
  checkPngChunks(path);
  File file = openFile(path, "rb");
  PngReader reader(file.get());
  if (!reader.readHeader()) throw InputError(path.string(), "", std::string("cannot read image as png: ") + reader.error());
  const int channels = std::min(reader.channels(), 4);
  const int sample_bytes = reader.depth() == 16 ? 2 : 1;
  checkImageSize(path, reader.width(), reader.height(), channels,
                 static_cast<std::uint64_t>(reader.channels()) * static_cast<std::uint64_t>(sample_bytes), reader.channels());
  std::vector<unsigned char> stored(reader.rowBytes() * reader.height());
  if (!reader.readRows(stored.data()))
    throw InputError(path.string(), "", std::string("cannot read image data: ") + reader.error());
  Decoded d;
  d.width = static_cast<int>(reader.width());
  d.height = static_cast<int>(reader.height());
  d.channels = channels;
  d.display_encoded = !reader.linear();
  d.pixels.resize(static_cast<std::size_t>(d.width) * d.height * channels);
  const float scale = sample_bytes == 2 ? 1.0f / 65535.0f : 1.0f / 255.0f;
  for (int y = 0; y < d.height; ++y) {
    const unsigned char* row = stored.data() + static_cast<std::size_t>(y) * reader.rowBytes();
    float* out = d.pixels.data() + static_cast<std::size_t>(y) * d.width * channels;
    for (int x = 0; x < d.width; ++x)
      for (int c = 0; c < channels; ++c) {
        const std::size_t i = static_cast<std::size_t>(x) * reader.channels() + static_cast<std::size_t>(c);
        std::uint16_t v = row[i];
        if (sample_bytes == 2) std::memcpy(&v, row + 2 * i, 2);
        out[static_cast<std::size_t>(x) * channels + c] = static_cast<float>(v) * scale;
      }
  }
  return d;
}

// 8-bit RGB (the display values of the first three channels).
void writePng(const std::filesystem::path& target, const std::filesystem::path& temporary, int width, int height,
              const std::vector<unsigned char>& rgb) {
  png_image image;
  std::memset(&image, 0, sizeof(image));
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = PNG_FORMAT_RGB;
  if (!png_image_write_to_file(&image, temporary.c_str(), 0, rgb.data(), 0, nullptr))
    throw RuntimeError(target.string() + ": cannot write image: " + image.message);
}

// ---------------------------------------------------------------------------------------------
// Radiance .hdr (RGBE, flat or run-length encoded) through stb_image, which is told nothing but
// that format: a file that is not Radiance is refused before its loader runs. Past the end of its
// input stb_image reads zeros, and a run-length scanline cut short then loops for ever on runs of
// length 0 (found by fuzz_image). So it reads through callbacks that feed it up to 64 KiB of 0xFF
// bytes past the end — runs of 127, which end a scanline's loop or fail its length check (a
// scanline of 16384 needs 1 KiB of them; the next one is then read flat, a loop of fixed length) —
// and then the end (more would keep a header's loop over its lines going); the file is refused as
// cut short once it has asked for them.

struct HdrSource {
  std::FILE* file = nullptr;
  bool read_past_end = false;
  std::size_t filler_left = 0;

  // stb_image's callbacks, each pass from the file's start.
  const stbi_io_callbacks* rewind() {
    std::rewind(file);
    read_past_end = false;
    filler_left = std::size_t{1} << 16;
    static const stbi_io_callbacks callbacks = {
        [](void* user, char* data, int size) {
          auto* source = static_cast<HdrSource*>(user);
          const std::size_t n = std::fread(data, 1, static_cast<std::size_t>(size), source->file);
          if (n > 0 || size <= 0) return static_cast<int>(n);
          source->read_past_end = true;
          const std::size_t filler = std::min(static_cast<std::size_t>(size), source->filler_left);
          std::memset(data, 0xff, filler);
          source->filler_left -= filler;
          return static_cast<int>(filler);
        },
        [](void* user, int n) { std::fseek(static_cast<HdrSource*>(user)->file, n, SEEK_CUR); },
        // At the end once the file is (stb_image then stops reading a header line there).
        [](void* user) { return std::feof(static_cast<HdrSource*>(user)->file) ? 1 : 0; }};
    return &callbacks;
  }
};

Decoded readHdr(const std::filesystem::path& path) {
  File file = openFile(path, "rb");
  HdrSource source{file.get()};
  if (!stbi_is_hdr_from_callbacks(source.rewind(), &source))
    throw InputError(path.string(), "", "cannot read image as hdr: not a Radiance .hdr file");
  int width = 0, height = 0, comp = 0;
  if (!stbi_info_from_callbacks(source.rewind(), &source, &width, &height, &comp))
    throw InputError(path.string(), "", std::string("cannot read image as hdr: ") +
                                            (source.read_past_end ? "the file ends inside its header" : stbi_failure_reason()));
  checkImageSize(path, width, height, 3, 4, 3);
  std::unique_ptr<float, void (*)(void*)> pixels(stbi_loadf_from_callbacks(source.rewind(), &source, &width, &height, &comp, 3),
                                                 stbi_image_free);
  if (source.read_past_end) throw InputError(path.string(), "", "cannot read image data: the file ends inside the pixels");
  if (!pixels) throw InputError(path.string(), "", std::string("cannot read image data: ") + stbi_failure_reason());
  Decoded d;
  d.width = width;
  d.height = height;
  d.channels = 3;
  d.pixels.assign(pixels.get(), pixels.get() + static_cast<std::size_t>(width) * height * 3);
  return d;
}

}  // namespace

void writeImage(const std::filesystem::path& path, const Image& image, const ImageWriteOptions& options) {
  const std::string ext = lowerExtension(path);
  if (ext != ".exr" && ext != ".png")
    throw InputError(path.string(), "", "unknown image type '" + ext + "' (use .exr for linear HDR or .png)");
  if (image.width <= 0 || image.height <= 0 || image.channels < 1 || image.channels > 4 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * image.channels)
    throw RuntimeError("writeImage: inconsistent image for " + path.string());

  // Write to a temporary beside the target and rename: never a half-written image.
  AtomicFileSet files;
  const std::filesystem::path temporary = files.stage(path);
  if (ext == ".exr") {
    writeExr(path, temporary, image);
  } else {
    const std::size_t count = static_cast<std::size_t>(image.width) * image.height;
    std::vector<unsigned char> rgb(count * 3);
    for (std::size_t p = 0; p < count; ++p) {
      const float* in = image.pixels.data() + p * image.channels;
      const glm::vec3 linear = image.channels < 3 ? glm::vec3(in[0]) : glm::vec3(in[0], in[1], in[2]);
      const glm::vec3 display = toDisplay(linear, options.exposure_ev, options.tonemap);
      for (int c = 0; c < 3; ++c)
        rgb[p * 3 + static_cast<std::size_t>(c)] = static_cast<unsigned char>(std::lround(std::clamp(display[c], 0.0f, 1.0f) * 255.0f));
    }
    writePng(path, temporary, image.width, image.height, rgb);
  }
  files.commit();
}

Image readImage(const std::filesystem::path& path) {
  // The reader is the one the extension names, and only that one (the three formats fuzz_image
  // covers): a PNG named .exr is refused, not read by whichever reader accepts it.
  const std::string ext = lowerExtension(path);
  if (ext != ".exr" && ext != ".hdr" && ext != ".png")
    throw InputError(path.string(), "", "unknown image type '" + ext + "' (read: .exr, .hdr, .png)");
  Decoded d = ext == ".exr" ? readExr(path) : ext == ".png" ? readPng(path) : readHdr(path);
  Image image;
  image.width = d.width;
  image.height = d.height;
  image.channels = d.channels;
  image.pixels = std::move(d.pixels);
  // 8/16-bit integer images are display-encoded sRGB: linearise the colour channels (not alpha).
  if (d.display_encoded) {
    const int colour = image.channels == 2 || image.channels == 4 ? image.channels - 1 : image.channels;
    for (std::size_t p = 0; p < image.pixels.size() / static_cast<std::size_t>(image.channels); ++p)
      for (int c = 0; c < colour; ++c) {
        float& v = image.pixels[p * static_cast<std::size_t>(image.channels) + static_cast<std::size_t>(c)];
        v = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);  // IEC 61966-2-1
      }
  }
  for (float v : image.pixels)
    if (!std::isfinite(v)) throw InputError(path.string(), "pixels", "contains NaN or infinite values");
  return image;
}

}  // namespace eik
