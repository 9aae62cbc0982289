// ShaderLibrary: finds shaders under shaders/ by relative path ("viewer/raymarch.frag"), expands
// `#include "common/x.glsl"` (recursively, each file once, cycles reported), injects `#define`s
// right after `#version` (llvmpipe executes branches on uniforms, so variants are built with
// defines, docs/architecture.md) and inserts `#line` directives so compiler errors name the file and line.
//
// Search order for each file:
//   1. directories given in ShaderLibraryOptions::directories (in order);
//   2. EIKONAL_SHADER_DIR (a ':'-separated list of directories);
//   3. the source tree's shaders/ (path compiled in), if it exists;
//   4. the copy embedded in the binary (cmake/EikonalShaders.cmake), so an installed program runs
//      from any directory.
// EIKONAL_SHADERS_EMBEDDED_ONLY=1 skips 2 and 3. Files are read at each call: editing a shader on
// disk and building the program again picks up the change (hot reload).
//
// Include paths are relative to the shaders root; a path starting with "./" or "../" is relative
// to the including file. Includes are expanded textually before the GLSL preprocessor runs, so an
// #include inside #if 0 is still read (harmless: each file is included once).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gl/program.h"
#include "gl/shader_source.h"

namespace eik::gl {

// NAME → VALUE, emitted in order as `#define NAME VALUE` (VALUE may be empty).
using ShaderDefines = std::vector<std::pair<std::string, std::string>>;

struct ShaderLibraryOptions {
  std::vector<std::filesystem::path> directories;  // searched first
  bool environment = true;                         // EIKONAL_SHADER_DIR
  bool sourceTree = true;                          // <source>/shaders
  bool embedded = true;                            // the copy in the binary
};

class ShaderLibrary {
 public:
  ShaderLibrary();
  explicit ShaderLibrary(ShaderLibraryOptions options);

  // The text of one file, and where it came from ("/abs/path/shaders/x.glsl" or "embedded:x.glsl").
  // RuntimeError naming the file and every place searched when it is nowhere.
  std::string read(std::string_view path) const;
  std::string locate(std::string_view path) const;
  bool exists(std::string_view path) const;

  // One stage, includes expanded, `defines` (then `prelude`, verbatim GLSL such as a
  // VolumeTextureLayout's defines) after #version. A file without #version gets "#version 330 core".
  ShaderSource source(std::string_view path, const ShaderDefines& defines = {}, std::string_view prelude = {}) const;

  // Compiles and links `vertexPath` + `fragmentPath` (stages from the file names), with the same
  // defines and prelude for both.
  Program program(std::string_view vertexPath, std::string_view fragmentPath, const ShaderDefines& defines = {},
                  std::string_view prelude = {}, const ProgramOptions& options = {}) const;
  Program program(std::string_view vertexPath, std::string_view geometryPath, std::string_view fragmentPath,
                  const ShaderDefines& defines, std::string_view prelude = {},
                  const ProgramOptions& options = {}) const;

  // The directories searched, in order (the embedded copy is not listed), for --help/diagnostics.
  const std::vector<std::filesystem::path>& directories() const { return directories_; }
  bool usesEmbedded() const { return embedded_; }

  // Every file of the embedded copy (relative paths), e.g. for tests and `--list-shaders`.
  static std::vector<std::string> embeddedFiles();
  // The source tree's shaders/ as compiled in.
  static std::filesystem::path sourceTreeDirectory();

 private:
  struct Found {
    std::string text;
    std::string origin;
  };
  std::optional<Found> find(const std::string& path) const;

  std::vector<std::filesystem::path> directories_;
  bool embedded_ = true;
};

}  // namespace eik::gl
