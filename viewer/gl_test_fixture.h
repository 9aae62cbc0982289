// Test-only: a gtest fixture that owns one GL context and the shader library for a whole suite
// (making a context per test would dominate the suite's time on llvmpipe).
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "gl/context.h"
#include "gl/shader_library.h"

namespace eik {

class GlSuiteTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    context_ = std::make_unique<gl::GlContext>();
    shaders_ = std::make_unique<gl::ShaderLibrary>();
  }
  static void TearDownTestSuite() {
    shaders_.reset();
    context_.reset();
  }
  static inline std::unique_ptr<gl::GlContext> context_;
  static inline std::unique_ptr<gl::ShaderLibrary> shaders_;
};

}  // namespace eik
