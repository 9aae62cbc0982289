// libFuzzer harness: a volume manifest (core/volume.h readVolume) beside a valid 2³ field file it may
// name ("ior.nrrd"), as every program reads a VOLUME.vol.json.
#include <exception>
#include <string>

#include "core/nrrd.h"

#include "core/volume.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  eik::fuzz::limitMemory();
  // A field file for the manifests of the corpus to name.
  eik::NrrdImage image;
  image.sizes = {2, 2, 2};
  image.data.assign(8, 1.0f);
  try {
    eik::writeNrrd(eik::fuzz::workDirectory() / "ior.nrrd", image);
  } catch (const std::exception&) {
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = eik::fuzz::inputFile("volume.vol.json", data, size);
  return eik::fuzz::readOrRefuse([&] { eik::readVolume(path); });
}
