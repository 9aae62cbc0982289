// Shaders and programs (see program.h).
#include "gl/program.h"

#include <algorithm>

#include <glm/gtc/type_ptr.hpp>

#include "core/error.h"
#include "gl/debug.h"

namespace eik::gl {
namespace {

GLenum glStage(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::Vertex: return GL_VERTEX_SHADER;
    case ShaderStage::Geometry: return GL_GEOMETRY_SHADER;
    case ShaderStage::Fragment: return GL_FRAGMENT_SHADER;
  }
  return GL_VERTEX_SHADER;
}

std::string shaderLog(GLuint shader) {
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
  glGetShaderInfoLog(shader, length, nullptr, log.data());
  log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
  while (!log.empty() && (log.back() == '\n' || log.back() == ' ')) log.pop_back();
  return log;
}

std::string programLog(GLuint program) {
  GLint length = 0;
  glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
  glGetProgramInfoLog(program, length, nullptr, log.data());
  log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
  while (!log.empty() && (log.back() == '\n' || log.back() == ' ')) log.pop_back();
  return log;
}

}  // namespace

Shader::Shader(ShaderStage stage, const ShaderSource& source) : stage_(stage), name_(source.name) {
  detail::requireContext("a shader");
  GLuint name = glCreateShader(glStage(stage));
  if (name == 0) throw RuntimeError(std::string("could not create a ") + stageName(stage) + " shader object");
  handle_ = GlHandle<detail::ShaderTraits>(name);
  const char* text = source.text.c_str();
  GLint length = static_cast<GLint>(source.text.size());
  glShaderSource(name, 1, &text, &length);
  glCompileShader(name);
  GLint ok = GL_FALSE;
  glGetShaderiv(name, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    // A failed compile also sets no GL error, but some drivers emit debug messages: drop them.
    throw RuntimeError(std::string("could not compile ") + stageName(stage) + " shader " + source.name + ":\n" +
                       source.translateLog(shaderLog(name)));
  }
  checkErrors("Shader");
}

Program::Program(const ShaderSource& vertex, const ShaderSource& fragment, const ProgramOptions& options) {
  Shader vs(ShaderStage::Vertex, vertex);
  Shader fs(ShaderStage::Fragment, fragment);
  const Shader* shaders[] = {&vs, &fs};
  *this = link(shaders, vertex.name + " + " + fragment.name, options);
}

Program::Program(const ShaderSource& vertex, const ShaderSource& geometry, const ShaderSource& fragment,
                 const ProgramOptions& options) {
  Shader vs(ShaderStage::Vertex, vertex);
  Shader gs(ShaderStage::Geometry, geometry);
  Shader fs(ShaderStage::Fragment, fragment);
  const Shader* shaders[] = {&vs, &gs, &fs};
  *this = link(shaders, vertex.name + " + " + geometry.name + " + " + fragment.name, options);
}

Program Program::link(std::span<const Shader* const> shaders, std::string name, const ProgramOptions& options) {
  detail::requireContext("a program");
  Program program;
  program.name_ = std::move(name);
  GLuint id = glCreateProgram();
  if (id == 0) throw RuntimeError("could not create a program object for " + program.name_);
  program.handle_ = GlHandle<detail::ProgramTraits>(id);
  for (const Shader* shader : shaders) glAttachShader(id, shader->id());
  if (!options.feedbackVaryings.empty()) {
    std::vector<const char*> names;
    for (const std::string& varying : options.feedbackVaryings) names.push_back(varying.c_str());
    glTransformFeedbackVaryings(id, static_cast<GLsizei>(names.size()), names.data(),
                                options.feedbackInterleaved ? GL_INTERLEAVED_ATTRIBS : GL_SEPARATE_ATTRIBS);
  }
  glLinkProgram(id);
  for (const Shader* shader : shaders) glDetachShader(id, shader->id());
  GLint ok = GL_FALSE;
  glGetProgramiv(id, GL_LINK_STATUS, &ok);
  if (!ok) throw RuntimeError("could not link program " + program.name_ + ":\n" + programLog(id));
  checkErrors("Program::link");
  return program;
}

void Program::use() const {
  glUseProgram(id());
  checkErrors("Program::use");
}

GLint Program::uniformLocation(std::string_view name) const {
  auto it = locations_.find(name);
  if (it != locations_.end()) return it->second;
  std::string key(name);
  GLint location = glGetUniformLocation(id(), key.c_str());
  locations_.emplace(std::move(key), location);
  return location;
}

template <class Fn>
void Program::withProgram(std::string_view name, Fn&& fn) const {
  GLint location = uniformLocation(name);
  if (location < 0) return;
  GLint current = 0;
  glGetIntegerv(GL_CURRENT_PROGRAM, &current);
  if (static_cast<GLuint>(current) != id()) glUseProgram(id());
  fn(location);
  if (static_cast<GLuint>(current) != id()) glUseProgram(static_cast<GLuint>(current));
  checkErrors("Program::set");
}

void Program::set(std::string_view name, float value) const {
  withProgram(name, [&](GLint l) { glUniform1f(l, value); });
}
void Program::set(std::string_view name, int value) const {
  withProgram(name, [&](GLint l) { glUniform1i(l, value); });
}
void Program::set(std::string_view name, unsigned value) const {
  withProgram(name, [&](GLint l) { glUniform1ui(l, value); });
}
void Program::set(std::string_view name, bool value) const {
  withProgram(name, [&](GLint l) { glUniform1i(l, value ? 1 : 0); });
}
void Program::set(std::string_view name, const glm::vec2& value) const {
  withProgram(name, [&](GLint l) { glUniform2fv(l, 1, glm::value_ptr(value)); });
}
void Program::set(std::string_view name, const glm::vec3& value) const {
  withProgram(name, [&](GLint l) { glUniform3fv(l, 1, glm::value_ptr(value)); });
}
void Program::set(std::string_view name, const glm::vec4& value) const {
  withProgram(name, [&](GLint l) { glUniform4fv(l, 1, glm::value_ptr(value)); });
}
void Program::set(std::string_view name, const glm::ivec2& value) const {
  withProgram(name, [&](GLint l) { glUniform2iv(l, 1, glm::value_ptr(value)); });
}
void Program::set(std::string_view name, const glm::ivec3& value) const {
  withProgram(name, [&](GLint l) { glUniform3iv(l, 1, glm::value_ptr(value)); });
}
void Program::set(std::string_view name, const glm::ivec4& value) const {
  withProgram(name, [&](GLint l) { glUniform4iv(l, 1, glm::value_ptr(value)); });
}
void Program::set(std::string_view name, const glm::mat3& value) const {
  withProgram(name, [&](GLint l) { glUniformMatrix3fv(l, 1, GL_FALSE, glm::value_ptr(value)); });
}
void Program::set(std::string_view name, const glm::mat4& value) const {
  withProgram(name, [&](GLint l) { glUniformMatrix4fv(l, 1, GL_FALSE, glm::value_ptr(value)); });
}
void Program::set(std::string_view name, std::span<const float> values) const {
  withProgram(name, [&](GLint l) { glUniform1fv(l, static_cast<GLsizei>(values.size()), values.data()); });
}
void Program::set(std::string_view name, std::span<const glm::vec3> values) const {
  withProgram(name, [&](GLint l) {
    glUniform3fv(l, static_cast<GLsizei>(values.size()), values.empty() ? nullptr : &values[0].x);
  });
}
void Program::set(std::string_view name, std::span<const glm::vec4> values) const {
  withProgram(name, [&](GLint l) {
    glUniform4fv(l, static_cast<GLsizei>(values.size()), values.empty() ? nullptr : &values[0].x);
  });
}

void Program::setUniformBlock(std::string_view blockName, GLuint binding) const {
  std::string key(blockName);
  GLuint index = glGetUniformBlockIndex(id(), key.c_str());
  if (index == GL_INVALID_INDEX) return;
  glUniformBlockBinding(id(), index, binding);
  checkErrors("Program::setUniformBlock");
}

}  // namespace eik::gl
