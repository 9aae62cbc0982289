#include "voxelize/obj_loader.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>
#include <vector>

#include "core/error.h"
#include "core/text.h"

namespace eik {
namespace {

// Lines never hold '\n' (the text is split at it), so eik::isSpace and eik::trim see exactly the
// whitespace of an OBJ line: space, \t, \r, \f, \v.

// Splits off the next whitespace-separated token of `rest`.
std::string_view nextToken(std::string_view& rest) {
  while (!rest.empty() && isSpace(rest.front())) rest.remove_prefix(1);
  std::size_t n = 0;
  while (n < rest.size() && !isSpace(rest[n])) ++n;
  std::string_view token = rest.substr(0, n);
  rest.remove_prefix(n);
  return token;
}

// One mesh being collected: global (0-based) position indices, three per triangle.
struct ObjGroup {
  std::string object, group, material;
  std::vector<std::uint32_t> corners;
};

// A positive index beyond the positions read so far (a forward reference): checked at the end.
struct PendingIndex {
  std::int64_t index;
  std::size_t line;
  char kind;  // 'v', 't' (vt), 'n' (vn)
};

class ObjParser {
 public:
  explicit ObjParser(std::string source) : source_(std::move(source)) {}

  MeshScene parse(std::string_view text) {
    std::size_t line_number = 0;
    std::string joined;  // a logical line continued with '\'
    std::size_t pos = 0;
    while (pos < text.size()) {
      std::size_t end = text.find('\n', pos);
      if (end == std::string_view::npos) end = text.size();
      std::string_view line = text.substr(pos, end - pos);
      pos = end + 1;
      ++line_number;
      std::string_view trimmed = trim(line);
      if (!trimmed.empty() && trimmed.back() == '\\') {  // continuation
        if (joined.empty()) line_start_ = line_number;
        joined.append(trimmed.substr(0, trimmed.size() - 1));
        joined.push_back(' ');
        continue;
      }
      if (!joined.empty()) {
        joined.append(trimmed);
        parseLine(joined, line_start_);
        joined.clear();
      } else {
        parseLine(trimmed, line_number);
      }
    }
    if (!joined.empty()) parseLine(joined, line_start_);
    return finish();
  }

 private:
  [[noreturn]] void fail(std::size_t line, std::string_view keyword, const std::string& what) const {
    throw InputError(source_, "line " + std::to_string(line) + ": " + std::string(keyword), what);
  }

  double parseNumber(std::string_view token, std::size_t line, std::string_view keyword) const {
    std::string_view digits = token;
    if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
    double value = 0.0;
    auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc() || ptr != digits.data() + digits.size() || digits.empty())
      fail(line, keyword, "'" + std::string(token) + "' is not a number");
    if (!std::isfinite(value)) fail(line, keyword, "'" + std::string(token) + "' is not a finite number");
    return value;
  }

  std::int64_t parseIndex(std::string_view token, std::size_t line) const {
    std::string_view digits = token;
    if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
    std::int64_t value = 0;
    auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc() || ptr != digits.data() + digits.size() || digits.empty())
      fail(line, "f", "'" + std::string(token) + "' is not an index");
    return value;
  }

  // Resolves a 1-based (or negative, relative) OBJ index to 0-based; forward references are
  // remembered and checked at the end.
  std::int64_t resolve(std::int64_t index, std::int64_t count, char kind, std::size_t line) {
    const char* name = kind == 'v' ? "vertex" : kind == 't' ? "texture coordinate" : "normal";
    if (index == 0) fail(line, "f", std::string(name) + " index 0 is invalid (OBJ indices start at 1)");
    if (index < 0) {
      if (-index > count)
        fail(line, "f", std::string(name) + " index " + std::to_string(index) + " is out of range (only " +
                            std::to_string(count) + " defined so far)");
      return count + index;
    }
    if (index > count) pending_.push_back({index, line, kind});
    return index - 1;
  }

  void parseLine(std::string_view line, std::size_t number) {
    std::string_view rest = line;
    std::string_view keyword = nextToken(rest);
    if (keyword.empty() || keyword.front() == '#') return;
    if (keyword == "v") {
      glm::dvec3 p(0.0);
      int n = 0;
      for (std::string_view token = nextToken(rest); !token.empty(); token = nextToken(rest), ++n) {
        if (token.front() == '#') break;
        double value = parseNumber(token, number, keyword);
        if (n < 3) p[n] = value;
      }
      if (n < 3) fail(number, keyword, "needs 3 coordinates, found " + std::to_string(n));
      positions_.push_back(p);
    } else if (keyword == "vt" || keyword == "vn") {
      int n = 0;
      for (std::string_view token = nextToken(rest); !token.empty(); token = nextToken(rest), ++n) {
        if (token.front() == '#') break;
        parseNumber(token, number, keyword);
      }
      if (n < (keyword == "vn" ? 3 : 1))
        fail(number, keyword, "too few values (" + std::to_string(n) + ")");
      (keyword == "vt" ? texcoords_ : normals_)++;
    } else if (keyword == "f" || keyword == "fo") {
      parseFace(rest, number);
    } else if (keyword == "o") {
      object_ = std::string(trim(rest));
      group_.clear();
      current_ = -1;
    } else if (keyword == "g") {
      group_ = std::string(trim(rest));
      current_ = -1;
    } else if (keyword == "usemtl") {
      material_ = std::string(trim(rest));
      current_ = -1;
    } else if (keyword == "l" || keyword == "p") {
      warnOnce("'" + std::string(keyword) + "' (line and point elements) skipped: only faces are voxelised");
    } else if (keyword == "s" || keyword == "mtllib" || keyword == "vp" || keyword == "lod" ||
               keyword == "maplib" || keyword == "usemap" || keyword == "mg" || keyword == "shadow_obj" ||
               keyword == "trace_obj") {
      // Smoothing groups, material libraries, ...: nothing the voxeliser uses.
    } else {
      warnOnce("unknown keyword '" + std::string(keyword) + "' ignored (first on line " +
               std::to_string(number) + ")");
    }
  }

  void parseFace(std::string_view rest, std::size_t number) {
    corners_.clear();
    for (std::string_view token = nextToken(rest); !token.empty(); token = nextToken(rest)) {
      if (token.front() == '#') break;
      // v, v/vt, v//vn, v/vt/vn
      std::string_view parts[3];
      int count = 0;
      std::string_view t = token;
      while (count < 3) {
        std::size_t slash = t.find('/');
        parts[count++] = t.substr(0, slash);
        if (slash == std::string_view::npos) break;
        t.remove_prefix(slash + 1);
        if (count == 3) fail(number, "f", "'" + std::string(token) + "' has too many '/'");
      }
      const auto v = resolve(parseIndex(parts[0], number), static_cast<std::int64_t>(positions_.size()), 'v',
                             number);
      if (count > 1 && !parts[1].empty())
        resolve(parseIndex(parts[1], number), texcoords_, 't', number);
      if (count > 2 && !parts[2].empty())
        resolve(parseIndex(parts[2], number), normals_, 'n', number);
      if (v > 0xffffffffLL) fail(number, "f", "vertex index too large");
      corners_.push_back(static_cast<std::uint32_t>(v));
    }
    if (corners_.size() < 3)
      fail(number, "f", "a face needs at least 3 corners, found " + std::to_string(corners_.size()));
    ObjGroup& group = currentGroup();
    for (std::size_t i = 1; i + 1 < corners_.size(); ++i) {  // fan triangulation
      group.corners.push_back(corners_[0]);
      group.corners.push_back(corners_[i]);
      group.corners.push_back(corners_[i + 1]);
    }
  }

  ObjGroup& currentGroup() {
    if (current_ < 0) {
      auto key = std::make_tuple(object_, group_, material_);
      auto it = group_index_.find(key);
      if (it == group_index_.end()) {
        it = group_index_.emplace(key, static_cast<int>(groups_.size())).first;
        groups_.push_back({object_, group_, material_, {}});
      }
      current_ = it->second;
    }
    return groups_[static_cast<std::size_t>(current_)];
  }

  void warnOnce(const std::string& message) {
    if (warned_.insert(message.substr(0, message.find(" (first"))).second)
      scene_.warnings.push_back(source_ + ": " + message);
  }

  MeshScene finish() {
    for (const PendingIndex& p : pending_) {
      const std::int64_t count = p.kind == 'v' ? static_cast<std::int64_t>(positions_.size())
                                 : p.kind == 't' ? texcoords_
                                                 : normals_;
      const char* name = p.kind == 'v' ? "vertex" : p.kind == 't' ? "texture coordinate" : "normal";
      if (p.index > count)
        fail(p.line, "f", std::string(name) + " index " + std::to_string(p.index) + " is out of range (the file defines " +
                              std::to_string(count) + ")");
    }
    std::string stem = std::filesystem::path(source_).stem().string();
    std::vector<std::uint32_t> local(positions_.size(), UINT32_MAX);
    std::map<std::string, int> name_uses;
    for (const ObjGroup& group : groups_) {
      if (group.corners.empty()) continue;
      TriangleMesh mesh;
      std::string base = group.object.empty() ? group.group
                         : group.group.empty() ? group.object
                                               : group.object + "/" + group.group;
      if (base.empty()) base = stem.empty() ? "obj" : stem;
      mesh.name = group.material.empty() ? base : base + " (" + group.material + ")";
      if (int uses = name_uses[mesh.name]++; uses > 0) mesh.name += " #" + std::to_string(uses + 1);
      if (!group.material.empty()) mesh.material.name = group.material;
      std::vector<std::uint32_t> used;
      for (std::uint32_t g : group.corners) {
        if (local[g] == UINT32_MAX) {
          local[g] = static_cast<std::uint32_t>(mesh.positions.size());
          mesh.positions.push_back(positions_[g]);
          used.push_back(g);
        }
      }
      mesh.triangles.reserve(group.corners.size() / 3);
      for (std::size_t i = 0; i < group.corners.size(); i += 3)
        mesh.triangles.emplace_back(local[group.corners[i]], local[group.corners[i + 1]],
                                    local[group.corners[i + 2]]);
      for (std::uint32_t g : used) local[g] = UINT32_MAX;
      scene_.meshes.push_back(std::move(mesh));
    }
    if (scene_.meshes.empty())
      throw InputError(source_, "f", positions_.empty() ? "empty mesh: no vertices and no faces"
                                                        : "empty mesh: " + std::to_string(positions_.size()) +
                                                              " vertices but no faces");
    return std::move(scene_);
  }

  std::string source_;
  MeshScene scene_;
  std::vector<glm::dvec3> positions_;
  std::int64_t texcoords_ = 0, normals_ = 0;
  std::vector<ObjGroup> groups_;
  std::map<std::tuple<std::string, std::string, std::string>, int> group_index_;
  std::string object_, group_, material_;
  int current_ = -1;
  std::vector<std::uint32_t> corners_;
  std::vector<PendingIndex> pending_;
  std::set<std::string> warned_;
  std::size_t line_start_ = 0;
};

}  // namespace

MeshScene parseObj(std::string_view text, const std::string& source) {
  return ObjParser(source).parse(text);
}

MeshScene loadObj(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "file", "cannot be opened");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw InputError(path.string(), "file", "read error");
  const std::string text = buffer.str();
  return parseObj(text, path.string());
}

}  // namespace eik
