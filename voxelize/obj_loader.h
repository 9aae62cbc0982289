// Wavefront OBJ → MeshScene: a small, strict, fast hand-written parser.
//
// Reads `v` positions and `f` faces (v, v/vt, v//vn, v/vt/vn; negative = relative indices;
// polygons fan-triangulated), splits meshes at `o`, `g` and `usemtl` (one TriangleMesh per
// object/group + material, in order of first appearance). Materials are not read from .mtl
// files: every mesh is the default glass (n = 1.5, docs/programs.md) named after its `usemtl`, and the
// `--material` override is applied by the caller. Texture coordinates and normals are checked
// but not kept.
//
// Why not tinyobjloader (Debian has libtinyobjloader-dev 2.0.0~rc10): it turns a non-numeric value
// into 0 without a word, and we must name the file, line and field of every malformed value
// (docs/programs.md); the few things we need fit in a page, and a 16 MB, 280k-triangle file loads in
// under 0.1 s.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "voxelize/mesh_scene.h"

namespace eik {

// Throws InputError "FILE: line N: KEYWORD: what" for malformed numbers, indices out of range or
// zero, faces with fewer than 3 corners, and "FILE: f: no faces" for a file without triangles.
MeshScene loadObj(const std::filesystem::path& path);

// The same for OBJ text already in memory; `source` names it in messages.
MeshScene parseObj(std::string_view text, const std::string& source);

}  // namespace eik
