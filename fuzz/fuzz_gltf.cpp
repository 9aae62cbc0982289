// libFuzzer harness: the glTF 2.0 reader (voxelize/gltf_loader.h) on binary .glb input (the JSON
// chunk and the binary buffer in one file), as `voxelize scene.glb` reads it.
#include "fuzz/fuzz_input.h"
#include "voxelize/gltf_loader.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  eik::fuzz::limitMemory();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The first byte picks the container: odd bytes are read as .gltf (JSON), even as .glb.
  const bool json = size > 0 && (data[0] & 1);
  const std::filesystem::path path =
      eik::fuzz::inputFile(json ? "scene.gltf" : "scene.glb", size > 0 ? data + 1 : data, size > 0 ? size - 1 : 0);
  return eik::fuzz::readOrRefuse([&] { eik::loadGltf(path); });
}
