// libFuzzer harness: a whole volume, its manifest and its files mutated together (core/volume.h
// readVolume): the input is up to three parts separated by a line "--8<--", written as
// volume.vol.json, a.nrrd and r.nrrd (a field file and a receiver map the manifest may name),
// so generations, receiver entries and the NRRDs they name are fuzzed against each other.
#include <string_view>

#include "core/volume.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  eik::fuzz::limitMemory();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr std::string_view kSeparator = "\n--8<--\n";
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const char* names[3] = {"volume.vol.json", "a.nrrd", "r.nrrd"};
  std::size_t begin = 0;
  for (int part = 0; part < 3; ++part) {
    std::size_t end = part < 2 ? input.find(kSeparator, begin) : std::string_view::npos;
    if (end == std::string_view::npos) end = input.size();
    const std::string_view bytes = begin <= input.size() ? input.substr(begin, end - begin) : std::string_view();
    eik::fuzz::inputFile(names[part], reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    begin = end + kSeparator.size();
  }
  const std::filesystem::path manifest = eik::fuzz::workDirectory() / names[0];
  return eik::fuzz::readOrRefuse([&] { eik::readVolume(manifest); });
}
