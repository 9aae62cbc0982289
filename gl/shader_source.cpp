// ShaderSource: compiler-log translation back to file names (see shader_source.h).
#include "gl/shader_source.h"

#include <regex>
#include <string>

#include "core/error.h"

namespace eik::gl {

ShaderSource ShaderSource::fromText(std::string name, std::string text) {
  ShaderSource source;
  source.files = {name};
  source.name = std::move(name);
  source.text = std::move(text);
  return source;
}

std::string ShaderSource::translateLog(std::string_view log) const {
  // One pattern per vendor format, tried on each line in turn; group 1 is the source-string
  // number, group 2 the line, group 3 (Mesa only) the column.
  static const std::regex mesa(R"(^(\d+):(\d+)\((\d+)\):)");
  static const std::regex nvidia(R"(^(\d+)\((\d+)\)\s*:)");
  static const std::regex amd(R"(^((?:ERROR|WARNING):\s*)(\d+):(\d+):)");
  auto fileName = [&](const std::string& number) {
    std::size_t index = std::stoul(number);
    return index < files.size() ? files[index] : "<source " + number + ">";
  };
  std::string out;
  std::size_t start = 0;
  while (start < log.size()) {
    std::size_t end = log.find('\n', start);
    std::string line(log.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    std::smatch m;
    if (std::regex_search(line, m, mesa)) {
      line = fileName(m[1]) + ":" + m[2].str() + ":" + m[3].str() + ":" + m.suffix().str();
    } else if (std::regex_search(line, m, nvidia)) {
      line = fileName(m[1]) + ":" + m[2].str() + ":" + m.suffix().str();
    } else if (std::regex_search(line, m, amd)) {
      line = m[1].str() + fileName(m[2]) + ":" + m[3].str() + ":" + m.suffix().str();
    }
    out += line;
    if (end == std::string_view::npos) break;
    out += '\n';
    start = end + 1;
  }
  return out;
}

ShaderStage stageFromPath(std::string_view path) {
  auto endsWith = [&](std::string_view suffix) {
    return path.size() >= suffix.size() && path.substr(path.size() - suffix.size()) == suffix;
  };
  if (endsWith(".vert")) return ShaderStage::Vertex;
  if (endsWith(".geom")) return ShaderStage::Geometry;
  if (endsWith(".frag")) return ShaderStage::Fragment;
  throw RuntimeError("shader " + std::string(path) + ": cannot tell the stage (expected .vert, .geom or .frag)");
}

const char* stageName(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::Vertex: return "vertex";
    case ShaderStage::Geometry: return "geometry";
    case ShaderStage::Fragment: return "fragment";
  }
  return "?";
}

}  // namespace eik::gl
