#include "core/image_io.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
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
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) throw InputError(path.string(), "", "cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw InputError(path.string(), "", "image has no pixels");
  // Before a pixel is allocated: the size a header claims (a 60-byte .hdr may claim 32768²).
  if (spec.width > kMaxImageAxis || spec.height > kMaxImageAxis)
    throw InputError(path.string(), "size",
                     std::to_string(spec.width) + "x" + std::to_string(spec.height) + " is larger than " +
                         std::to_string(kMaxImageAxis) + " pixels an axis");
  // The float pixels, and as much again for what is made of them (an environment's mipmaps, a
  // converted copy).
  checkMemoryLimit(path.string(), "size",
                   2ull * static_cast<std::uint64_t>(spec.width) * static_cast<std::uint64_t>(spec.height) *
                       static_cast<std::uint64_t>(std::min(spec.nchannels, 4)) * sizeof(float));
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = std::min(spec.nchannels, 4);
  image.pixels.resize(static_cast<std::size_t>(image.width) * image.height * image.channels);
  if (!in->read_image(0, 0, 0, image.channels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
    throw InputError(path.string(), "", "cannot read image data: " + in->geterror());
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
