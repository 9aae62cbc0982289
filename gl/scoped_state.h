// Scoped GL state: guards that set a piece of fixed-function state for one scope and restore what
// was there before on exit, also when the scope is left by an exception. They keep the gl/handle.h
// convention that no GL state leaks from one pass into the next (docs/architecture.md): a pass that
// needs blending or a depth test turns it on with a guard, never with a bare glEnable.
//
//   guard               for the scope                                 restored on exit
//   ScopedBlendAdd      GL_BLEND on, GL_FUNC_ADD, GL_ONE / GL_ONE     equations, factors, GL_BLEND
//   ScopedDepthTest     GL_DEPTH_TEST on with `func`, depth writes    func, write mask, GL_DEPTH_TEST
//   ScopedDisable       capability `cap` off                          `cap` on again if it was
//   ScopedPassBindings  (nothing)                                     program, vertex array and
//                                                                     framebuffer unbound (0) on exit
//   ScopedPassState     texture unit 0 active; blend, depth,          framebuffer, program, vertex
//                       scissor, stencil and cull tests off           array, viewport, unit 0's 2D
//                                                                     texture, active unit, the tests
//
// ScopedPassBindings guards a pass that owns its draw (lightsim's step passes): it leaves nothing
// bound that its owner might delete while the context is still current. ScopedPassState guards a
// pass that runs inside someone else's (the histogram pyramid's build, lightsim/histo_pyramid.h):
// the caller finds every binding and capability as it left it.
//
// Header only; every guard needs a current context for its whole life.
#pragma once

#include <optional>

#include "gl/gl.h"
#include "gl/handle.h"

namespace eik::gl {

// Blending on with GL_FUNC_ADD and GL_ONE, GL_ONE (additive scatter: sums in a float target).
class ScopedBlendAdd {
 public:
  ScopedBlendAdd() {
    enabled_ = glIsEnabled(GL_BLEND);
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &equationRgb_);
    glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &equationAlpha_);
    glGetIntegerv(GL_BLEND_SRC_RGB, &srcRgb_);
    glGetIntegerv(GL_BLEND_DST_RGB, &dstRgb_);
    glGetIntegerv(GL_BLEND_SRC_ALPHA, &srcAlpha_);
    glGetIntegerv(GL_BLEND_DST_ALPHA, &dstAlpha_);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
  }
  ~ScopedBlendAdd() {
    glBlendEquationSeparate(static_cast<GLenum>(equationRgb_), static_cast<GLenum>(equationAlpha_));
    glBlendFuncSeparate(static_cast<GLenum>(srcRgb_), static_cast<GLenum>(dstRgb_), static_cast<GLenum>(srcAlpha_),
                        static_cast<GLenum>(dstAlpha_));
    if (!enabled_) glDisable(GL_BLEND);
  }
  ScopedBlendAdd(const ScopedBlendAdd&) = delete;
  ScopedBlendAdd& operator=(const ScopedBlendAdd&) = delete;

 private:
  GLboolean enabled_ = GL_FALSE;
  GLint equationRgb_ = 0, equationAlpha_ = 0, srcRgb_ = 0, dstRgb_ = 0, srcAlpha_ = 0, dstAlpha_ = 0;
};

// The depth test on with `func`, depth writes on (keep-the-nearest scatter into a depth target).
class ScopedDepthTest {
 public:
  explicit ScopedDepthTest(GLenum func) {
    enabled_ = glIsEnabled(GL_DEPTH_TEST);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &mask_);
    glGetIntegerv(GL_DEPTH_FUNC, &func_);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(func);
    glDepthMask(GL_TRUE);
  }
  ~ScopedDepthTest() {
    glDepthFunc(static_cast<GLenum>(func_));
    glDepthMask(mask_);
    if (!enabled_) glDisable(GL_DEPTH_TEST);
  }
  ScopedDepthTest(const ScopedDepthTest&) = delete;
  ScopedDepthTest& operator=(const ScopedDepthTest&) = delete;

 private:
  GLboolean enabled_ = GL_FALSE;
  GLboolean mask_ = GL_TRUE;
  GLint func_ = GL_LESS;
};

// A glEnable/glDisable capability off for the scope (and back on at the end if it was on).
class ScopedDisable {
 public:
  explicit ScopedDisable(GLenum cap) : cap_(cap), was_(glIsEnabled(cap) == GL_TRUE) {
    if (was_) glDisable(cap_);
  }
  ~ScopedDisable() {
    if (was_) glEnable(cap_);
  }
  ScopedDisable(const ScopedDisable&) = delete;
  ScopedDisable& operator=(const ScopedDisable&) = delete;

 private:
  GLenum cap_;
  bool was_;
};

// Unbinds the program, vertex array and framebuffer on exit (also when a pass throws), so that a
// pass leaves nothing bound that its owner might delete while it is still current.
class ScopedPassBindings {
 public:
  ScopedPassBindings() = default;
  ~ScopedPassBindings() {
    glUseProgram(0);
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  ScopedPassBindings(const ScopedPassBindings&) = delete;
  ScopedPassBindings& operator=(const ScopedPassBindings&) = delete;
};

// Everything a nested full-screen pass touches, restored on exit (gl/handle.h conventions):
// framebuffer, program, vertex array, viewport, texture unit 0 and the active unit, and the
// per-fragment tests and blending a caller may have left on (turned off for the scope).
class ScopedPassState {
 public:
  ScopedPassState()
      : framebuffer_(GL_FRAMEBUFFER, GL_FRAMEBUFFER_BINDING, detail::bindFramebuffer),
        program_(0, GL_CURRENT_PROGRAM, detail::useProgram),
        vertexArray_(0, GL_VERTEX_ARRAY_BINDING, detail::bindVertexArray),
        blend_(GL_BLEND),
        depth_(GL_DEPTH_TEST),
        scissor_(GL_SCISSOR_TEST),
        stencil_(GL_STENCIL_TEST),
        cull_(GL_CULL_FACE) {
    glGetIntegerv(GL_VIEWPORT, viewport_);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &activeTexture_);
    glActiveTexture(GL_TEXTURE0);
    texture_.emplace(GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, detail::bindTexture);
  }
  ~ScopedPassState() {
    texture_.reset();
    glActiveTexture(static_cast<GLenum>(activeTexture_));
    glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
  }
  ScopedPassState(const ScopedPassState&) = delete;
  ScopedPassState& operator=(const ScopedPassState&) = delete;

 private:
  detail::ScopedBinding framebuffer_;
  detail::ScopedBinding program_;
  detail::ScopedBinding vertexArray_;
  ScopedDisable blend_, depth_, scissor_, stencil_, cull_;
  std::optional<detail::ScopedBinding> texture_;
  GLint viewport_[4] = {0, 0, 0, 0};
  GLint activeTexture_ = GL_TEXTURE0;
};

}  // namespace eik::gl
