// libFuzzer harness: image headers and pixels (core/image_io.h readImage), the environment maps the
// viewer reads (OpenEXR, libpng or stb_image parse; our checks run before any pixel). The input's magic picks the
// name, and so the reader (readImage takes the extension's reader only): OpenEXR's "v/1\x01" → .exr,
// PNG's "\x89PNG" → .png, anything else → Radiance .hdr. The seeds hold all three.
#include <cstring>

#include "core/image_io.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // 16 MB: a header claiming more is refused by the same check as ever, and the pixels that are
  // decoded stay small (a 60-byte header may claim 500 MB of zero-filled pixels, which costs a
  // second an input under ASan and fuzzes nothing more).
  eik::fuzz::limitMemory("16777216");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto starts = [&](const char* magic, std::size_t n) { return size >= n && std::memcmp(data, magic, n) == 0; };
  const char* name = starts("v/1\x01", 4) ? "environment.exr" : starts("\x89PNG", 4) ? "environment.png" : "environment.hdr";
  const std::filesystem::path path = eik::fuzz::inputFile(name, data, size);
  return eik::fuzz::readOrRefuse([&] { eik::readImage(path); });
}
