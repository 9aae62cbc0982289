#include "core/volume.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/nrrd.h"
#include "core/testing.h"

namespace eik {
namespace {

// Write options of an encoding (gzip or raw, attached or detached).
VolumeWriteOptions encoding(bool gzip, bool detached) {
  VolumeWriteOptions options;
  options.gzip = gzip;
  options.detached = detached;
  return options;
}
namespace fs = std::filesystem;
using nlohmann::json;

using test_support::inputErrorOf;
using test_support::readFile;
using test_support::TempDir;
using test_support::writeFile;

Volume sampleVolume() {
  Volume volume;
  volume.grid.dims = {8, 6, 4};
  volume.grid.bounds_min = {-1.0, -0.75, 0.1};
  volume.grid.bounds_max = {1.0, 0.75, 0.9};
  std::mt19937 random(7);
  std::uniform_real_distribution<float> uniform(-2.0f, 2.0f);
  for (auto [name, components] : {std::pair<const char*, int>{"ior", 1}, {"sigma_a", 3}, {"scatter", 2},
                                  {"opaque", 4}, {"custom_mask", 1}}) {
    Field& field = volume.addField(name, components);
    for (float& v : field.data) v = uniform(random);
  }
  volume.metadata["light"] = {{"type", "directional"}, {"direction", {0, -1, 0}}};
  volume.metadata["bake_stats"] = {{"patches", 12345}, {"seconds", 1.5}};
  volume.metadata["format"] = "not-ours";  // reserved: must not overwrite the manifest's own key
  return volume;
}

void expectSameVolume(const Volume& a, const Volume& b) {
  EXPECT_EQ(a.grid, b.grid);
  ASSERT_EQ(a.fields.size(), b.fields.size());
  for (const auto& [name, field] : a.fields) {
    const Field* other = b.find(name);
    ASSERT_NE(other, nullptr) << name;
    EXPECT_EQ(field.components, other->components) << name;
    ASSERT_EQ(field.data.size(), other->data.size()) << name;
    EXPECT_EQ(std::memcmp(field.data.data(), other->data.data(), field.data.size() * sizeof(float)), 0) << name;
  }
}

// Writes the sample volume as DIR/scene.vol.json and returns the manifest's JSON for editing.
json writeSample(const TempDir& dir, const VolumeWriteOptions& options = {}) {
  writeVolume(sampleVolume(), dir / "scene.vol.json", options);
  return json::parse(readFile(dir / "scene.vol.json"));
}

void rewriteManifest(const TempDir& dir, const json& manifest) { writeFile(dir / "scene.vol.json", manifest.dump(2)); }

// The file the manifest names for a field ("scene.<generation>.sigma_a.nrrd").
fs::path fieldPath(const fs::path& manifest, const std::string& name) {
  return manifest.parent_path() / json::parse(readFile(manifest)).at("fields").at(name).at("file").get<std::string>();
}
fs::path fieldPath(const TempDir& dir, const std::string& name) { return fieldPath(dir / "scene.vol.json", name); }

std::string manifestError(const TempDir& dir) {
  return inputErrorOf([&] { readVolume(dir / "scene.vol.json"); });
}

// ---------------------------------------------------------------------------------------------

TEST(Volume, KnownFieldsTable) {
  EXPECT_EQ(knownFields().size(), 11u);
  EXPECT_EQ(knownFieldComponents("ior"), 1);
  EXPECT_EQ(knownFieldComponents("ior_grad"), 3);
  EXPECT_EQ(knownFieldComponents("sigma_a"), 3);
  EXPECT_EQ(knownFieldComponents("emission"), 3);
  EXPECT_EQ(knownFieldComponents("scatter"), 2);
  EXPECT_EQ(knownFieldComponents("opaque"), 4);
  EXPECT_EQ(knownFieldComponents("reflect"), 4);
  EXPECT_EQ(knownFieldComponents("dispersion"), 1);
  EXPECT_EQ(knownFieldComponents("irradiance"), 3);
  EXPECT_EQ(knownFieldComponents("light_dir"), 3);
  EXPECT_EQ(knownFieldComponents("interfaces"), 0);  // one per slot: checked by interfaceTable
  EXPECT_EQ(knownFieldComponents("something_else"), 0);
}

TEST(Volume, AddFindRequire) {
  Volume volume;
  volume.grid.dims = {4, 3, 2};
  Field& ior = volume.addField("ior", 1);
  EXPECT_EQ(ior.data.size(), 24u);
  EXPECT_TRUE(std::all_of(ior.data.begin(), ior.data.end(), [](float v) { return v == 0.0f; }));
  EXPECT_EQ(volume.addField("sigma_a", 3).data.size(), 72u);
  EXPECT_THROW(volume.addField("sigma_a", 1), RuntimeError);
  EXPECT_TRUE(volume.has("ior"));
  EXPECT_EQ(volume.find("emission"), nullptr);
  EXPECT_EQ(&volume.require("ior", 1), &volume.fields.at("ior"));
  EXPECT_EQ(&volume.require("sigma_a", 0), &volume.fields.at("sigma_a"));

  std::string missing = inputErrorOf([&] { volume.require("irradiance", 3, "scene.vol.json"); });
  EXPECT_CONTAINS(missing, "scene.vol.json: fields.irradiance: missing");
  EXPECT_CONTAINS(missing, "ior, sigma_a");
  std::string wrong = inputErrorOf([&] { volume.require("sigma_a", 4, "scene.vol.json"); });
  EXPECT_CONTAINS(wrong, "scene.vol.json: fields.sigma_a: has 3 components, expected 4");
}

class VolumeRoundTrip : public ::testing::TestWithParam<VolumeWriteOptions> {};

TEST_P(VolumeRoundTrip, IsBitExact) {
  TempDir dir;
  Volume volume = sampleVolume();
  writeVolume(volume, dir / "scene.vol.json", GetParam());
  Volume back = readVolume(dir / "scene.vol.json");
  expectSameVolume(volume, back);
  EXPECT_EQ(back.metadata.at("light"), volume.metadata.at("light"));
  EXPECT_EQ(back.metadata.at("bake_stats"), volume.metadata.at("bake_stats"));
  EXPECT_FALSE(back.metadata.contains("format"));
  EXPECT_FALSE(back.metadata.contains("fields"));

  // Every entry is a field file of this write's generation or the manifest: no temporaries.
  const std::string generation = json::parse(readFile(dir / "scene.vol.json")).at("generation");
  EXPECT_TRUE(isValidGeneration(generation) && generation.size() == 8) << generation;
  std::vector<std::string> expected = {"scene.vol.json"};
  for (const auto& [name, unused] : volume.fields) {
    const std::string stem = "scene." + generation + "." + name;
    if (GetParam().detached) {
      expected.push_back(stem + ".nhdr");
      expected.push_back(stem + (GetParam().gzip ? ".raw.gz" : ".raw"));
    } else {
      expected.push_back(stem + ".nrrd");
    }
    EXPECT_EQ(readNrrdHeader(fieldPath(dir, name)).generation, generation) << name;
  }
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(dir.entries(), expected);

  // Writing the read-back volume again reproduces the manifest, but for the new generation.
  std::string first = readFile(dir / "scene.vol.json");
  TempDir again;
  const std::string second_generation = writeVolume(back, again / "scene.vol.json", GetParam());
  EXPECT_NE(second_generation, generation);
  std::string second = readFile(again / "scene.vol.json");
  for (std::size_t at; (at = second.find(second_generation)) != std::string::npos;)
    second.replace(at, second_generation.size(), generation);
  EXPECT_EQ(second, first);
}

INSTANTIATE_TEST_SUITE_P(Encodings, VolumeRoundTrip,
                         ::testing::Values(encoding(true, false), encoding(false, false),
                                           encoding(true, true), encoding(false, true)),
                         [](const auto& info) {
                           return std::string(info.param.gzip ? "gzip" : "raw") +
                                  (info.param.detached ? "_detached" : "_attached");
                         });

// The samples of an attached NRRD: its bytes after the blank line that ends the header.
std::string samplesOf(const fs::path& nrrd) {
  const std::string text = readFile(nrrd);
  return text.substr(text.find("\n\n") + 2);
}

// VolumeWriteOptions::unchanged_fields: a field read from a file and written back unchanged has its
// encoded samples copied from that file (byte for byte, under a header of the new generation) and
// reads back the same; the copy is taken from the file, not from the data (shown by changing the
// data in memory against the contract); a raw write of a gzip source and a source that is gone
// are written from the data as before.
TEST(VolumeWrite, UnchangedFieldsAreCopiedFromTheFilesTheyWereReadFrom) {
  TempDir dir;
  writeSample(dir);
  Volume read = readVolume(dir / "scene.vol.json");
  ASSERT_EQ(read.field_files.size(), read.fields.size());
  for (const auto& [name, file] : read.field_files) EXPECT_EQ(file, fieldPath(dir, name)) << name;
  Field& baked = read.addField("irradiance", 3);
  for (std::size_t i = 0; i < baked.data.size(); ++i) baked.data[i] = 0.25f * static_cast<float>(i % 7);

  VolumeWriteOptions copy;
  copy.unchanged_fields = read.field_files;
  const std::string generation = writeVolume(read, dir / "baked.vol.json", copy);
  for (const auto& [name, file] : read.field_files) {
    const fs::path written = fieldPath(dir / "baked.vol.json", name);
    EXPECT_EQ(samplesOf(written), samplesOf(file)) << name;
    EXPECT_NE(readFile(written).find("eikonal_generation:=" + generation), std::string::npos) << name;
  }
  expectSameVolume(read, readVolume(dir / "baked.vol.json"));

  // Against the contract: the data changed in memory, the file's samples are what is written.
  Volume changed = read;
  changed.fields.at("ior").data[0] += 1.0f;
  writeVolume(changed, dir / "copied.vol.json", copy);
  EXPECT_EQ(readVolume(dir / "copied.vol.json").fields.at("ior").data, read.fields.at("ior").data);

  // Written from the data: a raw write (the sources are gzip), and a source that is gone.
  VolumeWriteOptions raw = copy;
  raw.gzip = false;
  writeVolume(changed, dir / "raw.vol.json", raw);
  EXPECT_NE(readFile(fieldPath(dir / "raw.vol.json", "ior")).find("encoding: raw"), std::string::npos);
  EXPECT_EQ(readVolume(dir / "raw.vol.json").fields.at("ior").data, changed.fields.at("ior").data);
  VolumeWriteOptions gone = copy;
  gone.unchanged_fields["ior"] = dir / "no-such-file.nrrd";
  writeVolume(changed, dir / "gone.vol.json", gone);
  EXPECT_EQ(readVolume(dir / "gone.vol.json").fields.at("ior").data, changed.fields.at("ior").data);
}

// Fields left unread (VolumeReadOptions::leave_unread) are checked but not read, and carried into a
// volume written from the one read: their files copied where the encoding allows, read and written
// otherwise.
TEST(VolumeRead, FieldsLeftUnreadAreCarriedIntoTheVolumeWritten) {
  TempDir dir;
  writeSample(dir);
  const Volume whole = readVolume(dir / "scene.vol.json");
  VolumeReadOptions options;
  options.leave_unread = {"sigma_a", "opaque"};
  const Volume lean = readVolume(dir / "scene.vol.json", options);
  EXPECT_FALSE(lean.has("sigma_a"));
  EXPECT_FALSE(lean.has("opaque"));
  EXPECT_TRUE(lean.has("ior"));
  EXPECT_EQ(lean.unread_fields, (std::map<std::string, int>{{"opaque", 4}, {"sigma_a", 3}}));
  EXPECT_EQ(lean.field_files.at("sigma_a"), fieldPath(dir, "sigma_a"));

  writeVolume(lean, dir / "carried.vol.json");  // gzip, as the sources: copied
  expectSameVolume(whole, readVolume(dir / "carried.vol.json"));
  EXPECT_EQ(samplesOf(fieldPath(dir / "carried.vol.json", "sigma_a")), samplesOf(fieldPath(dir, "sigma_a")));
  VolumeWriteOptions raw;
  raw.gzip = false;
  writeVolume(lean, dir / "raw.vol.json", raw);  // another encoding: read now, then written
  EXPECT_NE(readFile(fieldPath(dir / "raw.vol.json", "sigma_a")).find("encoding: raw"), std::string::npos);
  expectSameVolume(whole, readVolume(dir / "raw.vol.json"));
  // Nothing to carry it from: refused, and nothing written.
  Volume orphan = lean;
  orphan.field_files.erase("opaque");
  EXPECT_THROW(writeVolume(orphan, dir / "orphan.vol.json"), RuntimeError);
  EXPECT_FALSE(fs::exists(dir / "orphan.vol.json"));
  // An unread field's file is still checked: gone, the read fails naming it.
  fs::remove(fieldPath(dir, "opaque"));
  try {
    readVolume(dir / "scene.vol.json", options);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("opaque"), std::string::npos) << e.what();
  }
}

TEST(Volume, ManifestLayout) {
  TempDir dir;
  json manifest = writeSample(dir);
  EXPECT_EQ(manifest.at("format"), "eikonal-volume");
  EXPECT_EQ(manifest.at("version"), 1);
  EXPECT_EQ(manifest.at("dims"), json({8, 6, 4}));
  EXPECT_EQ(manifest.at("bounds_min"), json({-1.0, -0.75, 0.1}));
  EXPECT_EQ(manifest.at("bounds_max"), json({1.0, 0.75, 0.9}));
  const std::string g = manifest.at("generation");
  EXPECT_EQ(manifest.at("fields").at("ior"), json({{"file", "scene." + g + ".ior.nrrd"}, {"components", 1}}));
  EXPECT_EQ(manifest.at("fields").at("sigma_a"), json({{"file", "scene." + g + ".sigma_a.nrrd"}, {"components", 3}}));
  EXPECT_EQ(manifest.at("light").at("type"), "directional");
  std::string text = readFile(dir / "scene.vol.json");
  EXPECT_EQ(text.rfind("{\n  \"format\": \"eikonal-volume\",\n  \"version\": 1,\n  \"generation\": \"" + g + "\",", 0), 0u)
      << text;

  // The NRRD sits on the grid: origin = centre of voxel 0, directions = diag(voxel size).
  NrrdHeader header = readNrrdHeader(fieldPath(dir, "sigma_a"));
  EXPECT_EQ(header.components, 3);
  EXPECT_EQ(header.sizes, glm::ivec3(8, 6, 4));
  EXPECT_DOUBLE_EQ(header.origin.x, -1.0 + 0.125);
  EXPECT_DOUBLE_EQ(header.origin.y, -0.75 + 0.125);
  EXPECT_DOUBLE_EQ(header.origin.z, 0.1 + 0.1);
  EXPECT_DOUBLE_EQ(header.directions[0][0], 0.25);
  EXPECT_DOUBLE_EQ(header.directions[1][1], 0.25);
  EXPECT_DOUBLE_EQ(header.directions[2][2], 0.2);
  EXPECT_EQ(header.directions[0][1], 0.0);
}

TEST(Volume, HeaderOnlyReadSkipsTheData) {
  TempDir dir;
  writeSample(dir);
  Volume volume = readVolumeHeader(dir / "scene.vol.json");
  EXPECT_EQ(volume.grid.dims, glm::ivec3(8, 6, 4));
  ASSERT_TRUE(volume.has("opaque"));
  EXPECT_EQ(volume.fields.at("opaque").components, 4);
  EXPECT_TRUE(volume.fields.at("opaque").data.empty());
  EXPECT_EQ(volume.metadata.at("bake_stats").at("patches"), 12345);
}

TEST(Volume, ManifestNameWithoutVolJson) {
  TempDir dir;
  writeVolume(sampleVolume(), dir / "plain.json");
  EXPECT_TRUE(fs::exists(fieldPath(dir / "plain.json", "ior")));
  expectSameVolume(sampleVolume(), readVolume(dir / "plain.json"));
}

// ---------------------------------------------------------------------------------------------
// Malformed manifests: every error names the manifest and the field.

TEST(VolumeMalformed, MissingFieldFile) {
  TempDir dir;
  writeSample(dir);
  const fs::path sigma_a = fieldPath(dir, "sigma_a");
  fs::remove(sigma_a);
  std::string message = manifestError(dir);
  EXPECT_CONTAINS(message, (dir / "scene.vol.json").string() + ": fields.sigma_a.file: ");
  EXPECT_CONTAINS(message, sigma_a.string() + ": not found");
  EXPECT_THROW(readVolumeHeader(dir / "scene.vol.json"), InputError);
}

// A field name the writer would refuse (it becomes part of a file name) is refused when read, before
// a program works on the volume: `../evil` was read, baked, then refused at write time.
TEST(VolumeMalformed, FieldNamesThatAreNotNamesAreRefusedOnRead) {
  TempDir dir;
  json manifest = writeSample(dir);
  for (const char* bad : {"../evil", "a/b", "", "x.y"}) {
    json m = manifest;
    m["fields"][bad] = m["fields"]["ior"];
    rewriteManifest(dir, m);
    EXPECT_CONTAINS(manifestError(dir), (dir / "scene.vol.json").string() + ": fields." + bad + ": a field name may hold only");
  }
  EXPECT_TRUE(isValidFieldName("ior_grad"));
  EXPECT_TRUE(isValidFieldName("Sigma-2"));
  EXPECT_FALSE(isValidFieldName(".."));
}

TEST(VolumeMalformed, MissingDims) {
  TempDir dir;
  json manifest = writeSample(dir);
  manifest.erase("dims");
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), (dir / "scene.vol.json").string() + ": dims: missing");
}

TEST(VolumeMalformed, BadDims) {
  TempDir dir;
  json manifest = writeSample(dir);
  for (json dims : {json({8, 6}), json({8, 6, 0}), json({8, 6, "4"}), json({8, 6, 2000}), json("8x6x4")}) {
    manifest["dims"] = dims;
    rewriteManifest(dir, manifest);
    EXPECT_CONTAINS(manifestError(dir), (dir / "scene.vol.json").string() + ": dims: ");
  }
}

TEST(VolumeMalformed, FieldWithWrongComponentCount) {
  TempDir dir;
  json manifest = writeSample(dir);
  manifest["fields"]["sigma_a"]["components"] = 1;  // sigma_a is RGB
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: fields.sigma_a.components: 1, but the 'sigma_a' field has 3");

  manifest = writeSample(dir);
  manifest["fields"]["custom_mask"]["components"] = 2;  // the NRRD holds 1
  rewriteManifest(dir, manifest);
  std::string message = manifestError(dir);
  EXPECT_CONTAINS(message, "scene.vol.json: fields.custom_mask.components: 2, but ");
  EXPECT_CONTAINS(message, fieldPath(dir, "custom_mask").filename().string() + " has 1 components");

  // A known field whose NRRD has the wrong count, with no count in the manifest.
  manifest = writeSample(dir);
  manifest["fields"]["ior"] = {{"file", manifest["fields"]["sigma_a"]["file"]}};
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: fields.ior: ");
}

TEST(VolumeMalformed, DimsDisagreeWithNrrdSizes) {
  TempDir dir;
  json manifest = writeSample(dir);
  manifest["dims"] = {8, 6, 5};
  rewriteManifest(dir, manifest);
  std::string message = manifestError(dir);
  EXPECT_CONTAINS(message, (dir / "scene.vol.json").string() + ": fields.");
  EXPECT_CONTAINS(message, ".nrrd: sizes 8 6 4 do not match the manifest's dims 8 6 5");
}

TEST(VolumeMalformed, BoundsDisagreeWithNrrdGeometry) {
  TempDir dir;
  json manifest = writeSample(dir);
  manifest["bounds_max"] = {1.0, 0.75, 1.0};  // voxel size along z changes
  rewriteManifest(dir, manifest);
  std::string message = manifestError(dir);
  EXPECT_CONTAINS(message, "scene.vol.json: fields.");
  EXPECT_CONTAINS(message, "match the manifest's");

  manifest["bounds_min"] = {-1.0, -0.75, 0.2};  // same voxel size, shifted: the origin disagrees
  manifest["bounds_max"] = {1.0, 0.75, 1.0};
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), "space origin");

  manifest["bounds_min"] = {-1.0 + 1e-9, -0.75, 0.1};  // within the 1e-4 relative tolerance
  manifest["bounds_max"] = {1.0, 0.75, 0.9};
  rewriteManifest(dir, manifest);
  EXPECT_NO_THROW(readVolume(dir / "scene.vol.json"));

  manifest["bounds_max"] = {1.0, 0.75, 0.1};
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: bounds_max: must be greater than bounds_min");
}

TEST(VolumeMalformed, JsonSyntaxAndStructure) {
  TempDir dir;
  writeSample(dir);
  writeFile(dir / "scene.vol.json", "{\n  \"format\": \"eikonal-volume\",\n  \"dims\": [8, 6, 4\n}\n");
  std::string message = manifestError(dir);
  EXPECT_CONTAINS(message, (dir / "scene.vol.json").string() + ": JSON: ");
  EXPECT_CONTAINS(message, "line 4");

  writeFile(dir / "scene.vol.json", "[1, 2, 3]");
  EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: JSON: expected an object");

  json manifest = writeSample(dir);
  manifest["format"] = "something-else";
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: format: ");

  manifest = writeSample(dir);
  manifest["version"] = 2;
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: version: 2 is not supported");

  manifest = writeSample(dir);
  manifest.erase("fields");
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: fields: missing");

  manifest = writeSample(dir);
  manifest["fields"]["ior"].erase("file");
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: fields.ior.file: missing");

  manifest = writeSample(dir);
  manifest["bounds_min"] = {0, "a", 0};
  rewriteManifest(dir, manifest);
  EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: bounds_min: ");

  std::string absent = inputErrorOf([&] { readVolume(dir / "absent.vol.json"); });
  EXPECT_CONTAINS(absent, (dir / "absent.vol.json").string() + ": cannot open");
}

TEST(VolumeMalformed, NrrdErrorsNameTheManifestFieldAndFile) {
  TempDir dir;
  writeSample(dir, encoding(false, false));
  fs::path nrrd = fieldPath(dir, "scatter");
  std::string bytes = readFile(nrrd);
  writeFile(nrrd, bytes.substr(0, bytes.size() - 8));
  std::string message = manifestError(dir);
  EXPECT_CONTAINS(message, (dir / "scene.vol.json").string() + ": fields.scatter: " + nrrd.string() + ": data: truncated");
}

TEST(VolumeMalformed, WholeVolumeOverTheMemoryLimit) {
  TempDir dir;
  writeSample(dir);
  // The largest field (opaque, 4 × 192 floats) is 3072 bytes; all five together are 8448.
  ::setenv("EIKONAL_MEMORY_LIMIT_BYTES", "3100", 1);
  std::string message = manifestError(dir);
  ::unsetenv("EIKONAL_MEMORY_LIMIT_BYTES");
  EXPECT_CONTAINS(message, (dir / "scene.vol.json").string() + ": fields: needs ");
}

// ---------------------------------------------------------------------------------------------
// Atomic writes (docs/volume-format.md)

TEST(VolumeWrite, FailureMidWriteLeavesNoFiles) {
  TempDir dir;
  Volume volume = sampleVolume();
  // Fields are written in name order; a NaN in the last one fails after the others were staged.
  volume.fields.at("sigma_a").data[5] = std::numeric_limits<float>::quiet_NaN();
  try {
    writeVolume(volume, dir / "scene.vol.json");
    FAIL() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_CONTAINS(e.what(), ".sigma_a.nrrd: data: NaN");
  }
  EXPECT_TRUE(dir.entries().empty()) << ::testing::PrintToString(dir.entries());
}

TEST(VolumeWrite, FailedRewriteKeepsTheOldVolume) {
  TempDir dir;
  writeSample(dir, encoding(true, true));
  std::vector<std::string> before = dir.entries();
  std::string manifest = readFile(dir / "scene.vol.json");
  const fs::path ior_data = detachedDataPath(fieldPath(dir, "ior"), true);
  std::string ior = readFile(ior_data);

  Volume volume = sampleVolume();
  volume.fields.at("ior").data.assign(volume.fields.at("ior").data.size(), 1.5f);
  volume.fields.at("sigma_a").data[0] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(writeVolume(volume, dir / "scene.vol.json", encoding(true, true)), RuntimeError);
  EXPECT_EQ(dir.entries(), before);
  EXPECT_EQ(readFile(dir / "scene.vol.json"), manifest);
  EXPECT_EQ(readFile(ior_data), ior);
}

TEST(VolumeWrite, UnwritableDestinationLeavesNoFiles) {
  TempDir dir;
  std::string message = inputErrorOf([&] { writeVolume(sampleVolume(), dir / "missing" / "scene.vol.json"); });
  EXPECT_CONTAINS(message, "does not exist");
  writeFile(dir / "file", "not a directory");
  EXPECT_ANY_THROW(writeVolume(sampleVolume(), dir / "file" / "scene.vol.json"));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"file"});
}

TEST(VolumeWrite, RejectsInconsistentVolumes) {
  TempDir dir;
  Volume volume = sampleVolume();
  volume.fields.at("ior").data.pop_back();
  EXPECT_THROW(writeVolume(volume, dir / "a.vol.json"), RuntimeError);
  volume = sampleVolume();
  volume.fields["sigma_a"].components = 1;
  EXPECT_THROW(writeVolume(volume, dir / "b.vol.json"), RuntimeError);
  volume = sampleVolume();
  volume.fields["../escape"] = volume.fields.at("ior");
  EXPECT_THROW(writeVolume(volume, dir / "c.vol.json"), RuntimeError);
  volume = sampleVolume();
  volume.grid.bounds_max.x = volume.grid.bounds_min.x;
  EXPECT_THROW(writeVolume(volume, dir / "d.vol.json"), RuntimeError);
  EXPECT_TRUE(dir.entries().empty());
}

// ---------------------------------------------------------------------------------------------
// Generations (docs/volume-format.md "Writing"): all or nothing across files

// A process id that no longer exists (a child that has exited and been reaped).
pid_t deadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

TEST(VolumeGeneration, ARewriteLeavesOnlyTheNewGenerationAndKeepsOtherFiles) {
  TempDir dir;
  // An old set under the names writers used before generations, named by its manifest.
  json manifest = writeSample(dir);
  for (auto& [name, spec] : manifest["fields"].items()) {
    const std::string legacy = "scene." + name + ".nrrd";
    fs::rename(dir / spec["file"].get<std::string>(), dir / legacy);
    spec["file"] = legacy;
  }
  manifest.erase("generation");
  rewriteManifest(dir, manifest);
  const Volume legacy = readVolume(dir / "scene.vol.json");  // no generation: not checked
  // Files that are not the volume's: another volume's, notes, look-alikes.
  writeFile(dir / "scene.notes.txt", "mine");
  writeFile(dir / "scenery.0badcafe.ior.nrrd", "not this stem");
  writeFile(dir / "scene.0badcafe.ior.nrrd.bak", "not a field file name");
  writeFile(dir / "other.vol.json", "{}");

  const std::string g1 = writeVolume(sampleVolume(), dir / "scene.vol.json");
  std::vector<std::string> expected = {"other.vol.json", "scene.0badcafe.ior.nrrd.bak", "scene.notes.txt", "scene.vol.json",
                                       "scenery.0badcafe.ior.nrrd"};
  for (const auto& [name, unused] : sampleVolume().fields) expected.push_back("scene." + g1 + "." + name + ".nrrd");
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(dir.entries(), expected);
  expectSameVolume(legacy, readVolume(dir / "scene.vol.json"));

  const std::string g2 = writeVolume(sampleVolume(), dir / "scene.vol.json", encoding(true, true));
  EXPECT_NE(g2, g1);
  for (const std::string& name : dir.entries()) EXPECT_EQ(name.find(g1), std::string::npos) << name;
  EXPECT_TRUE(fs::exists(dir / "scene.notes.txt"));
  expectSameVolume(sampleVolume(), readVolume(dir / "scene.vol.json"));
}

TEST(VolumeGeneration, WhatAKilledWriteLeftIsRemovedByTheNext) {
  TempDir dir;
  writeSample(dir);
  // A write killed before its switch: its files under final names, a temporary of its dead process.
  const std::string dead = std::to_string(deadPid());
  writeFile(dir / "scene.deadbeef.ior.nrrd", "renamed, never named by a manifest");
  writeFile(dir / "scene.deadbeef.receiver-ground.nrrd", "likewise");
  writeFile(dir / (".scene.deadbeef.sigma_a.nrrd.tmp-" + dead + "-0123456789abcdef"), "half written");
  // A live process's temporary (this one's parent: alive) is not touched.
  const std::string live = ".scene.feedf00d.ior.nrrd.tmp-" + std::to_string(::getppid()) + "-0123456789abcdef";
  writeFile(dir / live, "still being written");
  expectSameVolume(sampleVolume(), readVolume(dir / "scene.vol.json"));  // the set is not mixed by them

  const std::string g = writeVolume(sampleVolume(), dir / "scene.vol.json");
  for (const std::string& name : dir.entries()) {
    if (name == live || name == "scene.vol.json") continue;
    EXPECT_EQ(name.rfind("scene." + g + ".", 0), 0u) << name;
  }
  EXPECT_TRUE(fs::exists(dir / live));
}

TEST(VolumeGeneration, AFileOfAnotherWriteIsRefusedNamingTheFieldAndBothGenerations) {
  TempDir dir, other;
  json manifest = writeSample(dir);
  const std::string g = manifest["generation"];
  const std::string g_other = writeVolume(sampleVolume(), other / "scene.vol.json");
  // The sigma_a file replaced by the other write's (as a tool copying files one by one might).
  fs::copy_file(fieldPath(other / "scene.vol.json", "sigma_a"), fieldPath(dir, "sigma_a"),
                fs::copy_options::overwrite_existing);
  std::string message = manifestError(dir);
  EXPECT_CONTAINS(message, (dir / "scene.vol.json").string() + ": fields.sigma_a: ");
  EXPECT_CONTAINS(message, "belongs to generation " + g_other + ", the manifest to generation " + g);
  // A file without a generation, in a manifest with one.
  writeNrrd(fieldPath(dir, "sigma_a"), NrrdImage{3, {8, 6, 4}, {-0.875, -0.625, 0.2},
                                                   glm::dmat3(0.25, 0, 0, 0, 0.25, 0, 0, 0, 0.2),
                                                   std::vector<float>(8 * 6 * 4 * 3, 0.5f)});
  EXPECT_CONTAINS(manifestError(dir), "belongs to no generation, the manifest to generation " + g);
  // A malformed generation in the manifest.
  for (const json& bad : {json("XYZ"), json(""), json(12), json(std::string(33, 'a'))}) {
    manifest["generation"] = bad;
    rewriteManifest(dir, manifest);
    EXPECT_CONTAINS(manifestError(dir), "scene.vol.json: generation: expected 1 to 32 lowercase hex digits");
  }
}

}  // namespace
}  // namespace eik
