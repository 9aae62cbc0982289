// The energy ledger on the GPU (see ledger_pass.h).
#include "lightsim/ledger_pass.h"

#include <algorithm>
#include <vector>

#include "gl/debug.h"
#include "gl/scoped_state.h"

namespace eik::gpu {

LedgerPass::LedgerPass(const gl::ShaderLibrary& library, int rows)
    : rows_(std::max(1, rows)),
      target_({kBins, rows_}, std::vector<gl::TextureFormat>(kMainColumns, gl::TextureFormat::RGBA32F)),
      extraTarget_({kBins, rows_},
                   std::vector<gl::TextureFormat>(kLedgerColumns - kMainColumns, gl::TextureFormat::RGBA32F)),
      step_(library.program("lightsim/ledger.vert", "lightsim/ledger.frag")),
      extra_(library.program("lightsim/ledger.vert", "lightsim/ledger.frag", {{"LEDGER_EXTRA", "1"}})),
      unfinished_(library.program("lightsim/ledger.vert", "lightsim/ledger.frag", {{"LEDGER_UNFINISHED", "1"}})),
      vao_(gl::VertexArray::create()) {
  clear();
}

void LedgerPass::reset() {
  clear();
  row_ = 0;
  sums_ = {};
}

void LedgerPass::addStep(const StepTargets& targets, const PatchTextures& current, std::size_t count, bool extra) {
  if (full()) flush();
  if (extra && count > 0) {
    draw(
        extra_, extraTarget_,
        [&] {
          targets.ledgerA.bind(0);
          extra_.setSampler("uLedgerA", 0);
          targets.ledgerB.bind(1);  // a torn patch's share received (ledger.vert)
          extra_.setSampler("uLedgerB", 1);
          current.texture(PatchTextures::kFlux).bind(2);
          extra_.setSampler("uFlux", 2);
        },
        count);
    --row_;  // the same row as the main entries below
  }
  draw(
      step_, target_,
      [&] {
        targets.ledgerA.bind(0);
        step_.setSampler("uLedgerA", 0);
        targets.ledgerB.bind(1);
        step_.setSampler("uLedgerB", 1);
        current.texture(PatchTextures::kFlux).bind(2);
        step_.setSampler("uFlux", 2);
      },
      count);
}

void LedgerPass::addUnfinished(const PatchTextures& list, std::size_t count) {
  draw(
      unfinished_, target_,
      [&] {
        list.texture(PatchTextures::kFlux).bind(0);
        unfinished_.setSampler("uFlux", 0);
      },
      count);
}

void LedgerPass::flush() {
  if (row_ == 0) return;
  for (int c = 0; c < kLedgerColumns; ++c) {
    const std::vector<float> data = c < kMainColumns ? target_.readRGBA(c) : extraTarget_.readRGBA(c - kMainColumns);
    const std::size_t used = static_cast<std::size_t>(row_) * kBins;  // rows from the bottom
    for (std::size_t i = 0; i < used; ++i) {
      sums_[static_cast<std::size_t>(c)] += glm::dvec4(data[i * 4], data[i * 4 + 1], data[i * 4 + 2], data[i * 4 + 3]);
    }
  }
  clear();
  row_ = 0;
}

void LedgerPass::clear() {
  for (int c = 0; c < kMainColumns; ++c) target_.clear(c, glm::vec4(0.0f));
  for (int c = kMainColumns; c < kLedgerColumns; ++c) extraTarget_.clear(c - kMainColumns, glm::vec4(0.0f));
}

template <class Setup>
void LedgerPass::draw(const gl::Program& program, gl::Framebuffer& target, Setup&& setup, std::size_t points) {
  if (full()) flush();
  if (points > 0) {
    gl::ScopedPassBindings unbind;
    target.bind();
    program.use();
    setup();
    program.set("uRow", row_);
    program.set("uBins", kBins);
    program.set("uLedgerSize", glm::vec2(static_cast<float>(kBins), static_cast<float>(rows_)));
    gl::ScopedBlendAdd blend;
    vao_.bind();
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(points));
    gl::checkErrors("Ledger");
  }
  ++row_;
}

}  // namespace eik::gpu
