// The scoped GL state guards (scoped_state.h): each sets its state for the scope and leaves the
// context exactly as it found it, also when the scope ends by an exception.
#include "gl/scoped_state.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "gl/context.h"
#include "gl/framebuffer.h"

namespace eik::gl {
namespace {

class ScopedStateTest : public ::testing::Test {
 protected:
  GlContext context_{ContextOptions{.backend = glBackendFromEnvironment(GlBackend::OSMesa), .debug = true}};
};

GLint integer(GLenum name) {
  GLint value = -1;
  glGetIntegerv(name, &value);
  return value;
}

TEST_F(ScopedStateTest, BlendAddRestoresFactorsEquationAndEnable) {
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  glBlendEquation(GL_FUNC_SUBTRACT);
  ASSERT_FALSE(glIsEnabled(GL_BLEND));
  {
    ScopedBlendAdd blend;
    EXPECT_TRUE(glIsEnabled(GL_BLEND));
    EXPECT_EQ(integer(GL_BLEND_SRC_RGB), GL_ONE);
    EXPECT_EQ(integer(GL_BLEND_DST_ALPHA), GL_ONE);
    EXPECT_EQ(integer(GL_BLEND_EQUATION_RGB), GL_FUNC_ADD);
  }
  EXPECT_FALSE(glIsEnabled(GL_BLEND));
  EXPECT_EQ(integer(GL_BLEND_SRC_RGB), GL_SRC_ALPHA);
  EXPECT_EQ(integer(GL_BLEND_DST_RGB), GL_ONE_MINUS_SRC_ALPHA);
  EXPECT_EQ(integer(GL_BLEND_SRC_ALPHA), GL_ZERO);
  EXPECT_EQ(integer(GL_BLEND_EQUATION_ALPHA), GL_FUNC_SUBTRACT);
}

TEST_F(ScopedStateTest, DepthTestRestoresFunctionMaskAndEnable) {
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  {
    ScopedDepthTest depth(GL_LESS);
    EXPECT_TRUE(glIsEnabled(GL_DEPTH_TEST));
    EXPECT_EQ(integer(GL_DEPTH_FUNC), GL_LESS);
    GLboolean mask = GL_FALSE;
    glGetBooleanv(GL_DEPTH_WRITEMASK, &mask);
    EXPECT_EQ(mask, GL_TRUE);
  }
  EXPECT_FALSE(glIsEnabled(GL_DEPTH_TEST));
  EXPECT_EQ(integer(GL_DEPTH_FUNC), GL_GREATER);
  GLboolean mask = GL_TRUE;
  glGetBooleanv(GL_DEPTH_WRITEMASK, &mask);
  EXPECT_EQ(mask, GL_FALSE);
}

TEST_F(ScopedStateTest, DisableTurnsACapabilityBackOnOnlyIfItWasOn) {
  glEnable(GL_SCISSOR_TEST);
  { ScopedDisable off(GL_SCISSOR_TEST); EXPECT_FALSE(glIsEnabled(GL_SCISSOR_TEST)); }
  EXPECT_TRUE(glIsEnabled(GL_SCISSOR_TEST));
  glDisable(GL_SCISSOR_TEST);
  { ScopedDisable off(GL_SCISSOR_TEST); }
  EXPECT_FALSE(glIsEnabled(GL_SCISSOR_TEST));
}

TEST_F(ScopedStateTest, PassStateRestoresBindingsViewportAndTestsAfterAnException) {
  Framebuffer target({8, 8}, {TextureFormat::RGBA32F});
  target.bind();
  const GLint framebuffer = integer(GL_FRAMEBUFFER_BINDING);
  glViewport(1, 2, 3, 4);
  glActiveTexture(GL_TEXTURE3);
  glEnable(GL_CULL_FACE);
  try {
    ScopedPassState state;
    EXPECT_FALSE(glIsEnabled(GL_CULL_FACE));
    EXPECT_EQ(integer(GL_ACTIVE_TEXTURE), GL_TEXTURE0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, 8, 8);
    throw std::runtime_error("a pass fails half way");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(integer(GL_FRAMEBUFFER_BINDING), framebuffer);
  GLint viewport[4] = {0, 0, 0, 0};
  glGetIntegerv(GL_VIEWPORT, viewport);
  EXPECT_EQ(viewport[0], 1);
  EXPECT_EQ(viewport[3], 4);
  EXPECT_EQ(integer(GL_ACTIVE_TEXTURE), GL_TEXTURE3);
  EXPECT_TRUE(glIsEnabled(GL_CULL_FACE));
  glDisable(GL_CULL_FACE);
  glActiveTexture(GL_TEXTURE0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

TEST_F(ScopedStateTest, PassBindingsUnbindProgramVertexArrayAndFramebuffer) {
  Framebuffer target({8, 8}, {TextureFormat::RGBA32F});
  {
    ScopedPassBindings bindings;
    target.bind();
    EXPECT_NE(integer(GL_FRAMEBUFFER_BINDING), 0);
  }
  EXPECT_EQ(integer(GL_FRAMEBUFFER_BINDING), 0);
  EXPECT_EQ(integer(GL_CURRENT_PROGRAM), 0);
  EXPECT_EQ(integer(GL_VERTEX_ARRAY_BINDING), 0);
}

}  // namespace
}  // namespace eik::gl
