// libFuzzer harness: the NRRD reader (core/nrrd.h) on one file, header and attached data (raw,
// gzip or ASCII), as `voxelize`, `lightsim` and `viewer` read a volume's fields.
#include "core/nrrd.h"
#include "fuzz/fuzz_input.h"

EIKONAL_FUZZ_FILE_READER("field.nrrd", eik::readNrrd)
