// libFuzzer harness: the OBJ reader (voxelize/obj_loader.h), as `voxelize mesh.obj` reads a mesh.
#include "voxelize/obj_loader.h"
#include "fuzz/fuzz_input.h"

EIKONAL_FUZZ_FILE_READER("mesh.obj", eik::loadObj)
