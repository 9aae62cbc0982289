// Shaders and programs (RAII). Compile and link errors throw RuntimeError with the GL log, its
// source-string numbers translated to "file:line" (ShaderSource::translateLog). Uniform setters
// look locations up by name once and cache them; a name the linker removed (or never saw) is
// ignored, as GL does with location -1. Setters work whether or not the program is in use: they
// restore the previously used program (handle.h conventions).
#pragma once

#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "gl/handle.h"
#include "gl/shader_source.h"

namespace eik::gl {

namespace detail {
struct ShaderTraits {
  static void destroy(GLuint name) { glDeleteShader(name); }
};
struct ProgramTraits {
  // A program deleted while it is current stays in use, only flagged for deletion, until another
  // one is made current; code that saved it as "the current program" and restores it afterwards
  // (Program::set, ScopedPassState) would then restore a name that no longer exists
  // (GL_INVALID_VALUE in glUseProgram). So a program in use is unbound before it is deleted.
  static void destroy(GLuint name) {
    GLint current = 0;
    glGetIntegerv(GL_CURRENT_PROGRAM, &current);
    if (static_cast<GLuint>(current) == name) glUseProgram(0);
    glDeleteProgram(name);
  }
};
}  // namespace detail

class Shader {
 public:
  Shader() = default;
  // Compiles; RuntimeError "could not compile fragment shader test/x.frag:\ncommon/y.glsl:4:3: error: ...".
  Shader(ShaderStage stage, const ShaderSource& source);
  GLuint id() const { return handle_.get(); }
  ShaderStage stage() const { return stage_; }
  const std::string& name() const { return name_; }

 private:
  GlHandle<detail::ShaderTraits> handle_;
  ShaderStage stage_ = ShaderStage::Vertex;
  std::string name_;
};

struct ProgramOptions {
  // Transform feedback outputs (glTransformFeedbackVaryings before linking).
  std::vector<std::string> feedbackVaryings;
  bool feedbackInterleaved = true;
};

class Program {
 public:
  Program() = default;
  // Compiles each stage and links them.
  Program(const ShaderSource& vertex, const ShaderSource& fragment, const ProgramOptions& options = {});
  Program(const ShaderSource& vertex, const ShaderSource& geometry, const ShaderSource& fragment,
          const ProgramOptions& options = {});
  // Links compiled shaders; `name` is used in error messages.
  static Program link(std::span<const Shader* const> shaders, std::string name, const ProgramOptions& options = {});

  void use() const;

  // Location of a uniform (cached), -1 when the program has no such active uniform.
  GLint uniformLocation(std::string_view name) const;
  bool hasUniform(std::string_view name) const { return uniformLocation(name) >= 0; }

  void set(std::string_view name, float value) const;
  void set(std::string_view name, int value) const;
  void set(std::string_view name, unsigned value) const;
  void set(std::string_view name, bool value) const;
  void set(std::string_view name, const glm::vec2& value) const;
  void set(std::string_view name, const glm::vec3& value) const;
  void set(std::string_view name, const glm::vec4& value) const;
  void set(std::string_view name, const glm::ivec2& value) const;
  void set(std::string_view name, const glm::ivec3& value) const;
  void set(std::string_view name, const glm::ivec4& value) const;
  void set(std::string_view name, const glm::mat3& value) const;
  void set(std::string_view name, const glm::mat4& value) const;
  void set(std::string_view name, std::span<const float> values) const;  // float array
  void set(std::string_view name, std::span<const glm::vec3> values) const;
  void set(std::string_view name, std::span<const glm::vec4> values) const;
  // A sampler uniform reads texture unit `unit`.
  void setSampler(std::string_view name, int unit) const { set(name, unit); }
  // Binds uniform block `blockName` to binding point `binding` (no-op when the block is absent).
  void setUniformBlock(std::string_view blockName, GLuint binding) const;

  GLuint id() const { return handle_.get(); }
  explicit operator bool() const { return bool(handle_); }
  const std::string& name() const { return name_; }

 private:
  template <class Fn>
  void withProgram(std::string_view name, Fn&& fn) const;

  GlHandle<detail::ProgramTraits> handle_;
  std::string name_;
  mutable std::map<std::string, GLint, std::less<>> locations_;
};

}  // namespace eik::gl
