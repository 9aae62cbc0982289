// libFuzzer harness: SCENE.json (core/scene.h readScene), as `lightsim --scene` and `viewer` read it.
#include "core/scene.h"
#include "fuzz/fuzz_input.h"

EIKONAL_FUZZ_FILE_READER("SCENE.json", eik::readScene)
