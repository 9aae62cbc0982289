// Images in and out: renders as EXR (linear, untone-mapped half float, OpenEXR) or PNG (tone-mapped
// 8-bit sRGB, libpng), environment maps in (OpenEXR, PNG, Radiance .hdr through stb_image). Writes
// are atomic.
#pragma once

#include <filesystem>
#include <vector>

#include "core/tonemap.h"

namespace eik {

// Linear RGBA float pixels, rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  int channels = 4;
  std::vector<float> pixels;

  float* at(int x, int y) { return pixels.data() + (static_cast<std::size_t>(y) * width + x) * channels; }
  const float* at(int x, int y) const { return pixels.data() + (static_cast<std::size_t>(y) * width + x) * channels; }
};

struct ImageWriteOptions {
  float exposure_ev = 0.0f;        // PNG only
  ToneMapper tonemap = ToneMapper::Aces;  // PNG only
};

// By extension: .exr writes linear half-float RGB(A) as rendered (one channel as Y), zip-compressed;
// .png writes tone-mapped sRGB 8-bit RGB. InputError for any other extension, RuntimeError when
// writing fails.
void writeImage(const std::filesystem::path& path, const Image& image, const ImageWriteOptions& options = {});

// The largest image readImage accepts, per axis (an environment map must fit GL_MAX_TEXTURE_SIZE,
// 16384 on llvmpipe).
constexpr int kMaxImageAxis = 16384;

// Reads .exr, .hdr or .png, with the reader the extension names and no other, as linear float
// RGB(A) (8/16-bit PNGs are taken as sRGB and linearised, unless a gAMA chunk of 1 says linear;
// an OpenEXR file's R, G, B (A) channels, else Y (A), else its first four; a .hdr's RGBE as RGB). InputError naming the file when it
// cannot be read, when its header claims more than kMaxImageAxis pixels an axis or more memory
// than the machine has (core/limits.h), both checked before a pixel is allocated, when its OpenEXR
// header or PNG chunks fail the walks of core/image_headers.h (before their libraries read them),
// or when a pixel is not finite.
Image readImage(const std::filesystem::path& path);

}  // namespace eik
