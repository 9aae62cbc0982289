// ShaderSource: the complete GLSL text of one shader stage as handed to the compiler, with the
// table that maps the source-string numbers of its #line directives back to file names, so that
// compiler logs can name the file and line of each error (gl/shader_library.h builds these).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace eik::gl {

enum class ShaderStage { Vertex, Geometry, Fragment };

struct ShaderSource {
  std::string name;                // the main file, e.g. "test/pattern.frag"
  std::string text;                // everything the compiler sees
  std::vector<std::string> files;  // files[n] is source-string n of the #line directives

  // Plain text with no includes: source string 0 is `name`.
  static ShaderSource fromText(std::string name, std::string text);

  // Rewrites the source-string references of a GL info log into file names:
  //   Mesa   "0:12(5): error: ..."      → "common/x.glsl:12:5: error: ..."
  //   NVIDIA "0(12) : error C1008: ..." → "common/x.glsl:12: error C1008: ..."
  //   AMD    "ERROR: 0:12: ..."         → "ERROR: common/x.glsl:12: ..."
  std::string translateLog(std::string_view log) const;
};

// From a file name: .vert → Vertex, .geom → Geometry, .frag → Fragment; RuntimeError otherwise.
ShaderStage stageFromPath(std::string_view path);
const char* stageName(ShaderStage stage);  // "vertex", "geometry", "fragment"

}  // namespace eik::gl
