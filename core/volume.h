// A material volume: named float fields on one grid, stored on disk as a JSON manifest
// (`*.vol.json`) naming one NRRD file per field (docs/volume-format.md, thesis §6.1 textures T1–T8).
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/grid.h"
#include "core/receiver_map.h"

namespace eik {

// The fields docs/volume-format.md defines, with their component counts. Other names are allowed
// (written and read like any field) but programs only interpret these.
struct FieldSpec {
  std::string_view name;
  int components;  // 0: 1 to 4 (interfaces: one per slot, checked against its table by interfaceTable)
  std::string_view meaning;
};
const std::vector<FieldSpec>& knownFields();
// Component count of a known field, or 0 for an unknown name or a field of 1 to 4 (interfaces).
int knownFieldComponents(std::string_view name);

// One field: `components` floats per voxel, interleaved, voxels x fastest.
struct Field {
  int components = 1;
  std::vector<float> data;

  float* voxel(std::size_t index) { return data.data() + index * static_cast<std::size_t>(components); }
  const float* voxel(std::size_t index) const {
    return data.data() + index * static_cast<std::size_t>(components);
  }
};

struct Volume {
  GridSpec grid;
  std::map<std::string, Field> fields;
  // Receiver maps baked onto planes (core/receiver_map.h), written beside the fields.
  std::vector<ReceiverMap> receivers;
  // Further manifest entries carried through unchanged: "light", "bake_stats", "materials",
  // "source", ... (everything but the reserved keys written by writeVolume).
  nlohmann::json metadata = nlohmann::json::object();
  // The NRRD file each field was read from (readVolume), for VolumeWriteOptions::unchanged_fields.
  std::map<std::string, std::filesystem::path> field_files;
  // Fields left in their files (VolumeReadOptions::leave_unread): name → components. They are not
  // in `fields`; their files are in `field_files`, and writeVolume carries them into the volume it
  // writes (copied, or read then, when the copy cannot be made).
  std::map<std::string, int> unread_fields;

  // Adds (or replaces) a zero-filled field.
  Field& addField(const std::string& name, int components);
  bool has(const std::string& name) const { return fields.count(name) != 0; }
  const Field* find(const std::string& name) const;
  // The field, or an InputError naming `source` (the manifest) and the field.
  const Field& require(const std::string& name, int components, const std::string& source = "volume") const;
};

struct VolumeWriteOptions {
  bool gzip = true;         // NRRD encoding: gzip (default) or raw
  bool detached = false;    // .nhdr + .raw(.gz) instead of attached .nrrd
  // Fields whose data is exactly that of the NRRD file given (Volume::field_files of a volume read
  // and not changed since): its encoded samples are copied (stageNrrdCopy), not encoded again; a
  // file that is gone or encoded otherwise is written from the data as usual. `lightsim` passes the
  // input's fields it does not bake.
  std::map<std::string, std::filesystem::path> unchanged_fields;
};

// Reads a manifest and every field it names. Throws InputError (exit 2) naming the file and the
// field for anything malformed (docs/volume-format.md, issue "Foundation" §3).
Volume readVolume(const std::filesystem::path& manifest);

struct VolumeReadOptions {
  // Fields whose headers are read and checked but not their data (Volume::unread_fields): what a
  // program will not look at, e.g. lightsim's CPU twin the n and ∇n of sharp constant-n materials
  // (at 132³ 37 MB not inflated, nor held, nor zeroed by the kernel first).
  std::vector<std::string> leave_unread;
};
Volume readVolume(const std::filesystem::path& manifest, const VolumeReadOptions& options);

// A field or receiver name the format allows: letters, digits, '_' and '-' (it becomes part of a
// file name). Readers refuse other names, the writer never writes them.
bool isValidFieldName(const std::string& name);
// The generation of a write: 8 lowercase hex digits (writeVolume); readers accept 1 to 32.
bool isValidGeneration(const std::string& generation);
// Reads only the manifest and the headers (grid, field table); no voxel data.
Volume readVolumeHeader(const std::filesystem::path& manifest);

// Writes `OUT.vol.json` and one NRRD per field and receiver beside it, all or nothing
// (docs/volume-format.md "Writing"): every write is a new generation G (8 hex digits); its files are
// `OUT.G.FIELD.nrrd` and `OUT.G.receiver-NAME.nrrd`, each carrying `eikonal_generation:=G`, and
// the manifest, which names G, is renamed into place last: that rename is the switch from the old
// volume to the new. The files of other generations of OUT (the previous write's, or those an
// interrupted write left) are removed after it. Returns G.
std::string writeVolume(const Volume& volume, const std::filesystem::path& manifest,
                        const VolumeWriteOptions& options = {});

}  // namespace eik
