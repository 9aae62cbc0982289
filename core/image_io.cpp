#include "core/image_io.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_headers.h"
#include "core/limits.h"
#include "core/text.h"

namespace eik {
namespace {

std::string lowerExtension(const std::filesystem::path& path) { return lower(path.extension().string()); }

}  // namespace

void writeImage(const std::filesystem::path& path, const Image& image, const ImageWriteOptions& options) {
  const std::string ext = lowerExtension(path);
  const bool hdr = ext == ".exr" || ext == ".hdr";
  const bool ldr = ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff";
  if (!hdr && !ldr)
    throw InputError(path.string(), "", "unknown image type '" + ext + "' (use .exr for linear HDR or .png)");
  if (image.width <= 0 || image.height <= 0 || image.channels < 1 || image.channels > 4 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * image.channels)
    throw RuntimeError("writeImage: inconsistent image for " + path.string());

  // Write to a temporary beside the target and rename: never a half-written image.
  AtomicFileSet files;
  const std::filesystem::path temporary = files.stage(path);
  const int channels = std::min(image.channels, hdr ? 4 : 3);
  OIIO::ImageSpec spec(image.width, image.height, channels, hdr ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8);
  std::vector<float> out(static_cast<std::size_t>(image.width) * image.height * channels);
  for (std::size_t p = 0; p < static_cast<std::size_t>(image.width) * image.height; ++p) {
    const float* in = image.pixels.data() + p * image.channels;
    float* o = out.data() + p * channels;
    if (hdr) {
      for (int c = 0; c < channels; ++c) o[c] = in[c];
    } else {
      glm::vec3 rgb(in[0], image.channels > 1 ? in[1] : in[0], image.channels > 2 ? in[2] : in[0]);
      if (image.channels < 3) rgb = glm::vec3(in[0]);
      glm::vec3 d = toDisplay(rgb, options.exposure_ev, options.tonemap);
      for (int c = 0; c < channels; ++c) o[c] = d[c];
    }
  }
  auto writer = OIIO::ImageOutput::create(path.filename().string());
  if (!writer) throw RuntimeError(path.string() + ": OpenImageIO cannot write '" + ext + "' files");
  if (ext == ".exr") spec.attribute("compression", "zip");
  if (!writer->open(temporary.string(), spec) ||
      !writer->write_image(OIIO::TypeDesc::FLOAT, out.data()) || !writer->close())
    throw RuntimeError(path.string() + ": cannot write image: " + writer->geterror());
  files.commit();
}

Image readImage(const std::filesystem::path& path) {
  // The reader is the one the extension names, and only that one: OpenImageIO's own open() tries
  // every other format's reader on a file its extension's reader refuses (about 1 ms an input, and
  // attack surface in readers no user asked for: TIFF, DICOM, ...). The three formats read are
  // the three fuzz_image covers.
  const std::string ext = lowerExtension(path);
  const char* format = ext == ".exr" ? "openexr" : ext == ".hdr" ? "hdr" : ext == ".png" ? "png" : nullptr;
  if (!format) throw InputError(path.string(), "", "unknown image type '" + ext + "' (read: .exr, .hdr, .png)");
  // Before the format's library allocates what the file declares.
  if (ext == ".exr") checkExrHeaders(path, kMaxImageAxis);
  if (ext == ".png") checkPngChunks(path);
  auto in = OIIO::ImageInput::create(format);
  if (!in) throw RuntimeError(std::string("OpenImageIO has no ") + format + " reader: " + OIIO::geterror());
  OIIO::ImageSpec opened;
  if (!in->open(path.string(), opened)) {
    const std::string why = in->geterror();
    throw InputError(path.string(), "", "cannot read image as " + ext.substr(1) + ": " + (why.empty() ? "not a valid " + ext.substr(1) + " file" : why));
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw InputError(path.string(), "", "image has no pixels");
  // Before a pixel is allocated: the size a header claims (a 60-byte .hdr may claim 32768²).
  if (spec.width > kMaxImageAxis || spec.height > kMaxImageAxis)
    throw InputError(path.string(), "size",
                     std::to_string(spec.width) + "x" + std::to_string(spec.height) + " is larger than " +
                         std::to_string(kMaxImageAxis) + " pixels an axis");
  if (spec.depth > 1) throw InputError(path.string(), "size", "a 3D image (depth " + std::to_string(spec.depth) + ") is no map");
  // The file's own pixels (all its channels, as stored), the float pixels and as much again for
  // what is made of them (an environment's mipmaps, a converted copy), a row of all channels.
  const int channels = std::min(spec.nchannels, 4);
  const std::uint64_t pixel_count = static_cast<std::uint64_t>(spec.width) * static_cast<std::uint64_t>(spec.height);
  const std::uint64_t pixel_bytes = spec.pixel_bytes(/*native=*/true);
  checkMemoryLimit(path.string(), "size",
                   pixel_count * pixel_bytes + 2ull * pixel_count * channels * sizeof(float) +
                       static_cast<std::uint64_t>(spec.width) * static_cast<std::uint64_t>(spec.nchannels) * sizeof(float));
  // Read as stored and convert here: OpenImageIO's own conversion in read_image allocates a 64 MB
  // buffer per call whatever the image's size (costly under the sanitizers, where the fuzzing runs).
  std::vector<unsigned char> stored(pixel_count * pixel_bytes);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UNKNOWN, stored.data()))
    throw InputError(path.string(), "", "cannot read image data: " + in->geterror());
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = channels;
  image.pixels.resize(pixel_count * channels);
  // A pixel's channels as stored: one format for all, or (OpenEXR) one for each channel.
  std::vector<std::size_t> offset(spec.nchannels + 1, 0);
  for (int c = 0; c < spec.nchannels; ++c) offset[c + 1] = offset[c] + spec.channelformat(c).size();
  std::vector<float> row(static_cast<std::size_t>(spec.width) * spec.nchannels);
  for (int y = 0; y < spec.height; ++y) {
    const unsigned char* src = stored.data() + static_cast<std::size_t>(y) * spec.width * pixel_bytes;
    if (spec.channelformats.empty()) {
      OIIO::convert_pixel_values(spec.format, src, OIIO::TypeDesc::FLOAT, row.data(), spec.width * spec.nchannels);
    } else {
      for (int x = 0; x < spec.width; ++x)
        for (int c = 0; c < channels; ++c)
          OIIO::convert_pixel_values(spec.channelformat(c), src + x * pixel_bytes + offset[c], OIIO::TypeDesc::FLOAT,
                                     &row[static_cast<std::size_t>(x) * spec.nchannels + c], 1);
    }
    float* dst = image.pixels.data() + static_cast<std::size_t>(y) * spec.width * channels;
    for (int x = 0; x < spec.width; ++x)
      for (int c = 0; c < channels; ++c) dst[x * channels + c] = row[static_cast<std::size_t>(x) * spec.nchannels + c];
  }
  // 8/16-bit integer images are display-encoded sRGB: linearise the colour channels.
  const bool integer = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  const std::string colorspace = spec.get_string_attribute("oiio:ColorSpace", integer ? "sRGB" : "Linear");
  if (integer && colorspace != "Linear") {
    const int colour = std::min(image.channels, 3);
    for (std::size_t p = 0; p < image.pixels.size() / image.channels; ++p)
      for (int c = 0; c < colour; ++c) {
        float& v = image.pixels[p * image.channels + c];
        v = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
      }
  }
  for (float v : image.pixels)
    if (!std::isfinite(v)) throw InputError(path.string(), "pixels", "contains NaN or infinite values");
  return image;
}

}  // namespace eik
