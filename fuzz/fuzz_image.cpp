// libFuzzer harness: image headers and pixels (core/image_io.h readImage) as Radiance .hdr, the
// environment maps the viewer reads (OpenImageIO parses; our checks run before any pixel).
#include "core/image_io.h"
#include "fuzz/fuzz_input.h"

EIKONAL_FUZZ_FILE_READER("environment.hdr", eik::readImage)
