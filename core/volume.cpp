// Volumes on disk (docs/volume-format.md): a JSON manifest `NAME.vol.json` and one NRRD per field beside it,
// `NAME.FIELD.nrrd` (or `NAME.FIELD.nhdr` + `NAME.FIELD.raw.gz` when detached), written atomically.
#include "core/volume.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <mutex>
#include <random>
#include <sstream>
#include <system_error>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/json_input.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "core/paths.h"
#include "core/nrrd.h"

namespace eik {
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kFormat = "eikonal-volume";
constexpr int kVersion = 1;
// Manifest keys writeVolume owns; metadata cannot overwrite them.
constexpr std::string_view kReservedKeys[] = {"format", "version", "generation", "dims",     "bounds_min",
                                             "bounds_max", "fields",  "receivers"};

bool isReserved(std::string_view key) {
  for (std::string_view reserved : kReservedKeys) {
    if (key == reserved) return true;
  }
  return false;
}

std::string formatTriple(const glm::dvec3& v) {
  char text[96];
  std::snprintf(text, sizeof text, "%.9g %.9g %.9g", v.x, v.y, v.z);
  return text;
}

std::string formatTriple(const glm::ivec3& v) {
  return std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z);
}

// "NAME" for "DIR/NAME.vol.json" (or "DIR/NAME.json", or any other "DIR/NAME").
std::string manifestStem(const fs::path& manifest) {
  std::string name = manifest.filename().string();
  for (std::string_view suffix : {std::string_view(".vol.json"), std::string_view(".json")}) {
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      return name.substr(0, name.size() - suffix.size());
    }
  }
  return name;
}


// ---------------------------------------------------------------------------------------------
// Generations (docs/volume-format.md "Writing")

// The manifest a write replaces: its generation and the files it names that belong to this stem
// (plain names in its folder starting with "STEM."; with a detached header's data files).
struct PreviousWrite {
  std::string generation;
  std::vector<fs::path> files;
};

PreviousWrite previousWrite(const fs::path& manifest, const std::string& stem) {
  PreviousWrite previous;
  std::error_code ec;
  const auto size = fs::file_size(manifest, ec);
  if (ec || size > (std::uintmax_t{16} << 20)) return previous;  // none, or not a manifest of ours
  try {
    std::ifstream in(manifest, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    const nlohmann::json root = parseJsonInput(text.str(), manifest.string());
    if (!root.is_object()) return previous;
    if (auto g = root.find("generation"); g != root.end() && g->is_string()) previous.generation = g->get<std::string>();
    std::vector<std::string> names;
    if (auto fields = root.find("fields"); fields != root.end() && fields->is_object())
      for (const auto& [unused, spec] : fields->items())
        if (spec.is_object() && spec.contains("file") && spec["file"].is_string()) names.push_back(spec["file"]);
    if (auto receivers = root.find("receivers"); receivers != root.end() && receivers->is_array())
      for (const auto& spec : *receivers)
        if (spec.is_object() && spec.contains("file") && spec["file"].is_string()) names.push_back(spec["file"]);
    const fs::path dir = manifest.parent_path();
    for (const std::string& name : names) {
      if (name.find('/') != std::string::npos || name.rfind(stem + ".", 0) != 0) continue;
      previous.files.push_back(dir / name);
      if (fs::path(name).extension() == ".nhdr") {
        previous.files.push_back(detachedDataPath(dir / name, false));
        previous.files.push_back(detachedDataPath(dir / name, true));
      }
    }
  } catch (const std::exception&) {
    // Not a manifest we can read: nothing of it is removed.
  }
  return previous;
}

// A generation for a new write: random, and not the one being replaced.
std::string newGeneration(const std::string& previous) {
  static std::mt19937_64 random = [] {
    std::random_device device;
    return std::mt19937_64((static_cast<std::uint64_t>(device()) << 32) ^ device() ^
                           static_cast<std::uint64_t>(::getpid()));
  }();
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  for (;;) {
    char text[9];
    std::snprintf(text, sizeof text, "%08x", static_cast<unsigned>(random() & 0xffffffffu));
    if (previous != text) return text;
  }
}

// Does `name` belong to a generation of `stem` other than `generation`:
// "STEM.<8 hex>.<field or receiver-NAME>.<nrrd|nhdr|raw|raw.gz>"?
bool isOtherGenerationFile(const std::string& name, const std::string& stem, const std::string& generation) {
  if (name.size() < stem.size() + 11 || name.compare(0, stem.size() + 1, stem + ".") != 0) return false;
  const std::string g = name.substr(stem.size() + 1, 8);
  if (!isValidGeneration(g) || g == generation || name[stem.size() + 9] != '.') return false;
  std::string rest = name.substr(stem.size() + 10);
  for (std::string_view extension : {".raw.gz", ".nrrd", ".nhdr", ".raw"}) {
    if (rest.size() > extension.size() && rest.compare(rest.size() - extension.size(), extension.size(), extension) == 0) {
      return isValidFieldName(rest.substr(0, rest.size() - extension.size()));
    }
  }
  return false;
}

// After the switch to `generation`: removes what the previous manifest named and no longer is,
// the files of any other generation of this stem (a write killed before its switch leaves its
// files under their final names, unnamed by any manifest), and such writes' temporaries.
void removeSupersededFiles(const fs::path& dir, const std::string& stem, const std::string& generation,
                           const std::vector<fs::path>& previous, const std::vector<fs::path>& written) {
  std::error_code ec;
  for (const fs::path& file : previous) {
    if (std::find(written.begin(), written.end(), file) != written.end() || !fs::exists(file, ec)) continue;
    testSignalPoint();
    fs::remove(file, ec);
  }
  const fs::path folder = dir.empty() ? fs::path(".") : dir;
  std::vector<fs::path> others;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
    if (isOtherGenerationFile(it->path().filename().string(), stem, generation)) others.push_back(it->path());
  for (const fs::path& file : others) {
    testSignalPoint();
    fs::remove(file, ec);
  }
  removeStaleTemporaries(folder, [&](const std::string& name) { return isOtherGenerationFile(name, stem, generation); });
}

NrrdHeader nrrdHeaderFor(const GridSpec& grid, int components) {
  NrrdHeader header;
  header.components = components;
  header.sizes = grid.dims;
  glm::dvec3 h = grid.voxelSize();
  header.origin = grid.bounds_min + 0.5 * h;  // NRRD space origin = centre of voxel 0 (core/grid.h)
  header.directions = glm::dmat3(h.x, 0, 0, 0, h.y, 0, 0, 0, h.z);
  return header;
}

// ---------------------------------------------------------------------------------------------
// Manifest parsing

class ManifestReader {
 public:
  explicit ManifestReader(const fs::path& manifest) : manifest_(manifest), name_(manifest.string()) {}

  Volume read(bool with_data, const std::vector<std::string>& leave_unread = {}) {
    nlohmann::json root = parse();
    Volume volume;
    checkFormat(root);
    readGeneration(root);
    volume.grid.dims = dims(root);
    volume.grid.bounds_min = numberTriple(root, "bounds_min");
    volume.grid.bounds_max = numberTriple(root, "bounds_max");
    for (int a = 0; a < 3; ++a) {
      if (!(volume.grid.bounds_min[a] < volume.grid.bounds_max[a])) {
        throw InputError(name_, "bounds_max",
                         "must be greater than bounds_min on every axis (" + std::string(1, "xyz"[a]) + ": " +
                             formatTriple(volume.grid.bounds_min) + " vs " + formatTriple(volume.grid.bounds_max) +
                             ")");
      }
    }

    auto fields = root.find("fields");
    if (fields == root.end()) throw InputError(name_, "fields", "missing (the table of field files)");
    if (!fields->is_object()) throw InputError(name_, "fields", "expected an object {\"NAME\": {\"file\": ...}}");

    // Headers first: every field is validated, and the total checked against memory, before any data is read.
    struct Entry {
      std::string name;
      fs::path file;
      NrrdHeader header;
    };
    std::vector<Entry> entries;
    std::uint64_t total_bytes = 0;
    for (const auto& [name, spec] : fields->items()) {
      // The writer's rule, checked when reading: a name that cannot be written back (a path such
      // as "../evil") is refused before anything is baked from it.
      if (!isValidFieldName(name))
        throw InputError(name_, "fields." + name, "a field name may hold only letters, digits, '_' and '-'");
      Entry entry{name, fieldFile(name, spec), {}};
      entry.header = fieldHeader(name, spec, entry.file, volume.grid);
      checkGeneration("fields." + name, entry.file, entry.header);
      total_bytes += fieldBytes(entry.header.sizes, entry.header.components);
      entries.push_back(std::move(entry));
    }
    checkMemoryLimit(name_, "fields", total_bytes);

    // The fields' data, one file a thread (each file's gzip stream decompresses on its own); the
    // first failing field in manifest order is the one reported.
    auto unread = [&](const std::string& field) {
      return std::find(leave_unread.begin(), leave_unread.end(), field) != leave_unread.end();
    };
    std::vector<std::vector<float>> data(with_data ? entries.size() : 0);
    std::vector<std::exception_ptr> errors(data.size());
    parallelFor(
        0, static_cast<std::int64_t>(data.size()),
        [&](std::int64_t i) {
          const std::size_t k = static_cast<std::size_t>(i);
          if (unread(entries[k].name)) return;
          try {
            data[k] = readNrrd(entries[k].file).data;
          } catch (...) {
            errors[k] = std::current_exception();
          }
        },
        1);
    for (std::size_t k = 0; k < entries.size(); ++k) {
      if (with_data && unread(entries[k].name)) {
        volume.unread_fields[entries[k].name] = entries[k].header.components;
        volume.field_files[entries[k].name] = entries[k].file;
        continue;
      }
      Field& field = volume.fields[entries[k].name];
      field.components = entries[k].header.components;
      if (!with_data) continue;
      if (errors[k]) {
        try {
          std::rethrow_exception(errors[k]);
        } catch (const InputError& e) {
          throw InputError(name_ + ": fields." + entries[k].name + ": " + e.what());
        }
      }
      field.data = std::move(data[k]);
      volume.field_files[entries[k].name] = entries[k].file;
    }

    readReceivers(root, volume, with_data);

    for (const auto& [key, value] : root.items()) {
      if (!isReserved(key)) volume.metadata[key] = value;
    }
    return volume;
  }

  // The "receivers" table and, with data, each map's NRRD.
  void readReceivers(const nlohmann::json& root, Volume& volume, bool with_data) {
    auto receivers = root.find("receivers");
    if (receivers == root.end()) return;
    if (!receivers->is_array()) throw InputError(name_, "receivers", "expected an array");
    for (std::size_t i = 0; i < receivers->size(); ++i) {
      const std::string key = "receivers[" + std::to_string(i) + "]";
      std::string file;
      ReceiverMap map = receiverFromJson((*receivers)[i], name_, key, file);
      const fs::path path = resolveInsideFolder(manifest_, key + ".file", file);
      std::error_code ec;
      if (!fs::is_regular_file(path, ec)) throw InputError(name_, key + ".file", path.string() + ": not found");
      NrrdHeader header;
      try {
        header = readNrrdHeader(path);
      } catch (const InputError& e) {
        throw InputError(name_ + ": " + key + ": " + e.what());
      }
      checkReceiverHeader(map, header, name_, key, path.string());
      map.components = header.components;
      checkGeneration(key, path, header);
      if (with_data) {
        checkMemoryLimit(name_, key, fieldBytes(header.sizes, header.components));
        try {
          map.irradiance = readNrrd(path).data;
        } catch (const InputError& e) {
          throw InputError(name_ + ": " + key + ": " + e.what());
        }
      }
      volume.receivers.push_back(std::move(map));
    }
  }

 private:
  // "generation": the write this manifest belongs to (writeVolume). Optional: hand-written and
  // older manifests have none, and their files are then not checked.
  void readGeneration(const nlohmann::json& root) {
    auto generation = root.find("generation");
    if (generation == root.end()) return;
    if (!generation->is_string() || !isValidGeneration(generation->get<std::string>()))
      throw InputError(name_, "generation", "expected 1 to 32 lowercase hex digits, got " + generation->dump().substr(0, 40));
    generation_ = generation->get<std::string>();
  }

  // Every file of a manifest with a generation must carry the same one: anything else is a set
  // mixed by an interrupted or concurrent write of other tools (ours never leave one).
  void checkGeneration(const std::string& key, const fs::path& file, const NrrdHeader& header) const {
    if (generation_.empty() || header.generation == generation_) return;
    throw InputError(name_, key,
                     file.filename().string() + " belongs to " +
                         (header.generation.empty()                   ? std::string("no generation")
                          : isValidGeneration(header.generation) ? "generation " + header.generation
                                                                 : std::string("a malformed generation")) +
                         ", the manifest to generation " + generation_ +
                         " (files of different writes mixed; write the volume again)");
  }

  nlohmann::json parse() {
    std::error_code ec;
    if (fs::is_directory(manifest_, ec)) throw InputError(name_, "", "is a directory, not a volume manifest");
    std::ifstream in(manifest_, std::ios::binary);
    if (!in) throw InputError(name_, "", std::string("cannot open: ") + std::strerror(errno));
    std::ostringstream text;
    text << in.rdbuf();
    nlohmann::json root = parseJsonInput(text.str(), name_);
    if (!root.is_object()) throw InputError(name_, "JSON", "expected an object at the top level");
    return root;
  }

  void checkFormat(const nlohmann::json& root) {
    auto format = root.find("format");
    if (format == root.end()) {
      throw InputError(name_, "format", "missing (expected \"" + std::string(kFormat) + "\")");
    }
    if (!format->is_string() || format->get<std::string>() != kFormat) {
      throw InputError(name_, "format", format->dump() + " is not \"" + std::string(kFormat) + "\"");
    }
    auto version = root.find("version");
    if (version != root.end()) {
      if (!version->is_number_integer()) throw InputError(name_, "version", version->dump() + " is not an integer");
      long long v = version->get<long long>();
      if (v < 1 || v > kVersion) {
        throw InputError(name_, "version",
                         std::to_string(v) + " is not supported (this program reads version " +
                             std::to_string(kVersion) + ")");
      }
    }
  }

  const nlohmann::json& requireTriple(const nlohmann::json& root, const char* key) {
    auto it = root.find(key);
    if (it == root.end()) throw InputError(name_, key, "missing (expected an array of 3 numbers)");
    if (!it->is_array() || it->size() != 3) {
      throw InputError(name_, key, it->dump() + " is not an array of 3 numbers");
    }
    return *it;
  }

  glm::ivec3 dims(const nlohmann::json& root) {
    const nlohmann::json& array = requireTriple(root, "dims");
    glm::ivec3 dims;
    for (int a = 0; a < 3; ++a) {
      const nlohmann::json& item = array[static_cast<std::size_t>(a)];
      if (!item.is_number_integer()) throw InputError(name_, "dims", item.dump() + " is not an integer");
      long long value = item.get<long long>();
      if (value <= 0) throw InputError(name_, "dims", std::to_string(value) + " is not positive");
      if (value > kMaxVolumeAxis) {
        throw InputError(name_, "dims",
                         std::to_string(value) + " voxels along " + "xyz"[a] + " exceeds the limit of " +
                             std::to_string(kMaxVolumeAxis) + " voxels per axis");
      }
      dims[a] = static_cast<int>(value);
    }
    return dims;
  }

  glm::dvec3 numberTriple(const nlohmann::json& root, const char* key) {
    const nlohmann::json& array = requireTriple(root, key);
    glm::dvec3 result;
    for (int a = 0; a < 3; ++a) {
      const nlohmann::json& item = array[static_cast<std::size_t>(a)];
      if (!item.is_number()) throw InputError(name_, key, item.dump() + " is not a number");
      result[a] = item.get<double>();
      if (!std::isfinite(result[a])) throw InputError(name_, key, item.dump() + " is not finite");
    }
    return result;
  }

  fs::path fieldFile(const std::string& name, const nlohmann::json& spec) {
    const std::string key = "fields." + name;
    if (!spec.is_object()) throw InputError(name_, key, "expected an object {\"file\": ..., \"components\": N}");
    auto file = spec.find("file");
    if (file == spec.end()) throw InputError(name_, key + ".file", "missing (the field's NRRD file)");
    if (!file->is_string() || file->get<std::string>().empty()) {
      throw InputError(name_, key + ".file", file->dump() + " is not a file name");
    }
    // relative to the manifest, and inside its folder (core/paths.h)
    const fs::path path = resolveInsideFolder(manifest_, key + ".file", file->get<std::string>());
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw InputError(name_, key + ".file", path.string() + ": not found");
    return path;
  }

  NrrdHeader fieldHeader(const std::string& name, const nlohmann::json& spec, const fs::path& file,
                         const GridSpec& grid) {
    const std::string key = "fields." + name;
    const int known = knownFieldComponents(name);
    int declared = 0;
    auto components = spec.find("components");
    if (components != spec.end()) {
      if (!components->is_number_integer()) {
        throw InputError(name_, key + ".components", components->dump() + " is not an integer");
      }
      long long value = components->get<long long>();
      if (value < 1 || value > 4) {
        throw InputError(name_, key + ".components", std::to_string(value) + " is not in 1..4");
      }
      declared = static_cast<int>(value);
      if (known != 0 && declared != known) {
        throw InputError(name_, key + ".components",
                         std::to_string(declared) + ", but the '" + name + "' field has " + std::to_string(known) +
                             " components (docs/volume-format.md)");
      }
    }

    NrrdHeader header;
    try {
      header = readNrrdHeader(file);
    } catch (const InputError& e) {
      throw InputError(name_ + ": " + key + ": " + e.what());
    }
    const std::string nrrd = file.string();
    if (declared != 0 && header.components != declared) {
      throw InputError(name_, key + ".components",
                       std::to_string(declared) + ", but " + nrrd + " has " + std::to_string(header.components) +
                           " components");
    }
    if (known != 0 && header.components != known) {
      throw InputError(name_, key,
                       nrrd + " has " + std::to_string(header.components) + " components, but the '" + name +
                           "' field has " + std::to_string(known) + " (docs/volume-format.md)");
    }
    if (header.sizes != grid.dims) {
      throw InputError(name_, key,
                       nrrd + ": sizes " + formatTriple(header.sizes) + " do not match the manifest's dims " +
                           formatTriple(grid.dims));
    }
    checkGeometry(key, nrrd, header, grid);
    return header;
  }

  // The NRRD must sit where the manifest says (relative tolerance 1e-4): origin = bounds_min + h/2,
  // directions = diag(h).
  void checkGeometry(const std::string& key, const std::string& nrrd, const NrrdHeader& header,
                     const GridSpec& grid) {
    const NrrdHeader expected = nrrdHeaderFor(grid, header.components);
    const glm::dvec3 h = grid.voxelSize();
    const double h_max = std::max(h.x, std::max(h.y, h.z));
    constexpr double kTolerance = 1e-4;
    for (int a = 0; a < 3; ++a) {
      double scale = std::max(std::abs(expected.origin[a]), h[a]);
      if (std::abs(header.origin[a] - expected.origin[a]) > kTolerance * scale) {
        throw InputError(name_, key,
                         nrrd + ": space origin " + formatTriple(header.origin) +
                             " does not match the manifest's bounds_min + half a voxel " +
                             formatTriple(expected.origin));
      }
      for (int b = 0; b < 3; ++b) {
        double tolerance = kTolerance * (a == b ? h[a] : h_max);
        if (std::abs(header.directions[a][b] - expected.directions[a][b]) > tolerance) {
          throw InputError(name_, key,
                           nrrd + ": space directions (axis " + std::to_string(a) + ": " +
                               formatTriple(header.directions[a]) + ") do not match the manifest's voxel size " +
                               formatTriple(h) + " (an axis-aligned grid from bounds_min to bounds_max)");
        }
      }
    }
  }

  fs::path manifest_;
  std::string name_;
  std::string generation_;
};

}  // namespace

bool isValidGeneration(const std::string& generation) {
  if (generation.empty() || generation.size() > 32) return false;
  for (char c : generation)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

bool isValidFieldName(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------

const std::vector<FieldSpec>& knownFields() {
  static const std::vector<FieldSpec> fields = {
      {"ior", 1, "refractive index n (pre-smoothed, or sharp with an interfaces field)"},
      {"ior_grad", 3, "gradient of n in 1/world-unit (central differences of the smoothed n)"},
      {"sigma_a", 3, "RGB absorption (attenuation) coefficient"},
      {"emission", 3, "RGB emitted radiance L_e"},
      {"scatter", 2, "albedo (scatter strength) and Henyey-Greenstein g"},
      {"opaque", 4, "RGB diffuse albedo of an opaque embedding/receiver, and its indicator"},
      {"reflect", 4, "RGB reflection tint and weight at boundaries"},
      {"dispersion", 1, "Cauchy B (um^2): n(lambda) = n + B (1/lambda^2 - 1/lambda_d^2)"},
      {"irradiance", 3, "baked RGB irradiance (from lightsim)"},
      {"light_dir", 3, "baked unit local light direction (from lightsim)"},
      {"interfaces", 0, "signed distance to the surface of each interface slot (negative inside), one per slot"},
  };
  return fields;
}

int knownFieldComponents(std::string_view name) {
  for (const FieldSpec& spec : knownFields()) {
    if (spec.name == name) return spec.components;
  }
  return 0;
}

Field& Volume::addField(const std::string& name, int components) {
  if (components < 1 || components > 4) {
    throw RuntimeError("fields." + name + ": " + std::to_string(components) + " components (expected 1 to 4)");
  }
  int known = knownFieldComponents(name);
  if (known != 0 && known != components) {
    throw RuntimeError("fields." + name + ": " + std::to_string(components) + " components, but the '" + name +
                       "' field has " + std::to_string(known) + " (docs/volume-format.md)");
  }
  Field& field = fields[name];
  field.components = components;
  field.data.assign(grid.count() * static_cast<std::size_t>(components), 0.0f);
  return field;
}

const Field* Volume::find(const std::string& name) const {
  auto it = fields.find(name);
  return it == fields.end() ? nullptr : &it->second;
}

const Field& Volume::require(const std::string& name, int components, const std::string& source) const {
  const Field* field = find(name);
  if (!field) {
    std::string present;
    for (const auto& [other, unused] : fields) present += (present.empty() ? "" : ", ") + other;
    throw InputError(source, "fields." + name,
                     "missing (the volume has " + (present.empty() ? std::string("no fields") : present) + ")");
  }
  if (components > 0 && field->components != components) {
    throw InputError(source, "fields." + name,
                     "has " + std::to_string(field->components) + " components, expected " +
                         std::to_string(components));
  }
  return *field;
}

Volume readVolume(const fs::path& manifest) { return ManifestReader(manifest).read(true); }

Volume readVolume(const fs::path& manifest, const VolumeReadOptions& options) {
  return ManifestReader(manifest).read(true, options.leave_unread);
}

Volume readVolumeHeader(const fs::path& manifest) { return ManifestReader(manifest).read(false); }

std::string writeVolume(const Volume& volume, const fs::path& manifest, const VolumeWriteOptions& options) {
  const std::string name = manifest.string();
  const GridSpec& grid = volume.grid;
  for (int a = 0; a < 3; ++a) {
    if (grid.dims[a] < 1 || grid.dims[a] > kMaxVolumeAxis) {
      throw RuntimeError(name + ": dims: " + formatTriple(grid.dims) + " (each must be 1 to " +
                         std::to_string(kMaxVolumeAxis) + ")");
    }
    if (!(grid.bounds_min[a] < grid.bounds_max[a]) || !std::isfinite(grid.bounds_min[a]) ||
        !std::isfinite(grid.bounds_max[a])) {
      throw RuntimeError(name + ": bounds: " + formatTriple(grid.bounds_min) + " to " +
                         formatTriple(grid.bounds_max) + " is not a finite box with bounds_min < bounds_max");
    }
  }
  if (!volume.metadata.is_null() && !volume.metadata.is_object()) {
    throw RuntimeError(name + ": metadata must be a JSON object");
  }

  const std::string stem = manifestStem(manifest);
  const fs::path dir = manifest.parent_path();
  // What the manifest being replaced names, read before it is replaced (removed after the switch).
  const PreviousWrite previous = previousWrite(manifest, stem);
  const std::string generation = newGeneration(previous.generation);
  AtomicFileSet files;  // removes every temporary if anything below throws
  std::vector<fs::path> written;
  const std::string prefix = stem + "." + generation + ".";
  const char* extension = options.detached ? ".nhdr" : ".nrrd";
  auto stage = [&](const fs::path& file, NrrdHeader header, std::span<const float> data) {
    header.generation = generation;
    stageNrrd(files, file, header, data, {options.gzip, options.detached});
    written.push_back(file);
    if (options.detached) written.push_back(detachedDataPath(file, options.gzip));
  };

  std::map<std::string, nlohmann::ordered_json> entries;  // by name: the manifest's table in name order
  for (const auto& [field_name, field] : volume.fields) {
    if (!isValidFieldName(field_name)) {
      throw RuntimeError(name + ": fields." + field_name + ": a field name may hold only letters, digits, '_' and '-'");
    }
    int known = knownFieldComponents(field_name);
    if (known != 0 && known != field.components) {
      throw RuntimeError(name + ": fields." + field_name + ": " + std::to_string(field.components) +
                         " components, but the '" + field_name + "' field has " + std::to_string(known) +
                         " (docs/volume-format.md)");
    }
    const fs::path file = dir / (prefix + field_name + extension);
    NrrdHeader header = nrrdHeaderFor(grid, field.components);
    const auto unchanged = options.unchanged_fields.find(field_name);
    header.generation = generation;
    if (unchanged != options.unchanged_fields.end() && field.data.size() == header.valueCount() &&
        stageNrrdCopy(files, file, header, unchanged->second, {options.gzip, options.detached})) {
      written.push_back(file);
    } else {
      stage(file, header, field.data);
    }
    entries[field_name] = {{"file", file.filename().string()}, {"components", field.components}};
  }
  // Fields left unread (readVolume's leave_unread): their files copied as they are, or, where the
  // copy cannot be made (another encoding), read now and written.
  for (const auto& [field_name, components] : volume.unread_fields) {
    if (volume.fields.count(field_name)) continue;  // read or made since: written above
    const auto source = volume.field_files.find(field_name);
    if (source == volume.field_files.end())
      throw RuntimeError(name + ": fields." + field_name + ": left unread, and no file to carry it from");
    const fs::path file = dir / (prefix + field_name + extension);
    NrrdHeader header = nrrdHeaderFor(grid, components);
    header.generation = generation;
    if (stageNrrdCopy(files, file, header, source->second, {options.gzip, options.detached})) {
      written.push_back(file);
    } else {
      const std::vector<float> data = readNrrd(source->second).data;
      if (data.size() != header.valueCount())
        throw RuntimeError(name + ": fields." + field_name + ": " + source->second.string() + " no longer holds the field read");
      stage(file, header, data);
    }
    entries[field_name] = {{"file", file.filename().string()}, {"components", components}};
  }
  nlohmann::ordered_json table = nlohmann::ordered_json::object();
  for (auto& [field_name, entry] : entries) table[field_name] = std::move(entry);

  nlohmann::ordered_json receivers = nlohmann::ordered_json::array();
  for (const ReceiverMap& map : volume.receivers) {
    if (!isValidFieldName(map.name))
      throw RuntimeError(name + ": receivers." + map.name + ": a receiver name may hold only letters, digits, '_' and '-'");
    if ((map.components != 1 && map.components != 3) ||
        map.irradiance.size() != map.texelCount() * static_cast<std::size_t>(map.components))
      throw RuntimeError(name + ": receivers." + map.name + ": " + std::to_string(map.irradiance.size()) +
                         " values for " + std::to_string(map.texelCount()) + " texels of " +
                         std::to_string(map.components) + " components");
    const fs::path file = dir / (prefix + "receiver-" + map.name + extension);
    stage(file, map.nrrdHeader(), map.irradiance);
    receivers.push_back(nlohmann::ordered_json::parse(map.toJson(file.filename().string()).dump()));
  }

  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  json["format"] = kFormat;
  json["version"] = kVersion;
  json["generation"] = generation;
  json["dims"] = {grid.dims.x, grid.dims.y, grid.dims.z};
  json["bounds_min"] = {grid.bounds_min.x, grid.bounds_min.y, grid.bounds_min.z};
  json["bounds_max"] = {grid.bounds_max.x, grid.bounds_max.y, grid.bounds_max.z};
  json["fields"] = std::move(table);
  if (!receivers.empty()) json["receivers"] = std::move(receivers);
  if (volume.metadata.is_object()) {
    for (const auto& [key, value] : volume.metadata.items()) {
      if (!isReserved(key)) json[key] = nlohmann::ordered_json::parse(value.dump());
    }
  }
  // Staged last, so renamed into place after every file it names: the switch to generation G.
  files.write(manifest, json.dump(2) + "\n");
  files.commit();
  removeSupersededFiles(dir, stem, generation, previous.files, written);
  return generation;
}

}  // namespace eik
