// How the glTF loader reports (gltf_loader.h): errors are InputErrors naming the file and the glTF
// field ("scene.gltf: accessors[2]: ..."), warnings are collected as "FILE: what".
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/error.h"

namespace eik {

struct GltfDiagnostics {
  std::string file;
  std::vector<std::string>* warnings = nullptr;  // where warn() appends

  [[noreturn]] void fail(const std::string& field, const std::string& what) const { throw InputError(file, field, what); }
  void warn(const std::string& what) const { warnings->push_back(file + ": " + what); }
};

// Numbers and array elements in messages: "12", "nodes[3]".
inline std::string str(std::size_t v) { return std::to_string(v); }
inline std::string str(int v) { return std::to_string(v); }
inline std::string indexed(const char* array, std::size_t i) { return std::string(array) + "[" + str(i) + "]"; }

}  // namespace eik
