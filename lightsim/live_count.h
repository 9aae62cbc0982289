// LiveCount: the number of live patches of the GPU list, kept on the GPU so that no pass of a step
// needs it on the CPU (ALGORITHM.md step 6, "The count stays on the GPU").
//
//   texture  one RGBA32F texel: the histogram pyramid's top, copied after each build (its four
//            components add up to the new list's count, each an integer that float holds exactly
//            up to 2^24), or the count uploaded for the first list. The update and analysis passes
//            read it (shaders/lightsim/live_count.glsl, liveCount()) and skip the slots at or past
//            it, so they may be drawn over more slots than are live.
//   readback request() queues a 1-texel read of it into a pixel-pack buffer and returns; wait()
//            returns that value, waiting only if the GPU has not reached it yet. The simulator
//            requests a step's new count and collects it one step later, after the next step's
//            passes are queued (GpuSimulatorOptions::CountReadback), so the GPU never idles
//            waiting for the CPU.
//
// Needs a current GL context for its whole life.
#pragma once

#include <cstdint>

#include "gl/buffer.h"
#include "gl/framebuffer.h"
#include "gl/program.h"
#include "gl/texture.h"
#include "lightsim/histo_pyramid.h"

namespace eik::gpu {

class LiveCount {
 public:
  LiveCount();

  // The count of a list made on the CPU (the initial patches; tests). Exact up to 2^24.
  void set(std::uint64_t count);
  // The count ← the total of `pyramid` as its last build left it (a GPU copy; no wait).
  void takeTotal(const HistoPyramid& pyramid);

  // Queues the read of the current count (no wait). At most one read is pending: request() while
  // one is throws std::logic_error.
  void request();
  bool pending() const { return pending_; }
  // The requested count (waits until the GPU has written it). Throws std::logic_error when none
  // is pending, RuntimeError when the texel does not hold non-negative integers.
  std::uint64_t wait();

  // Binds the texel to unit `unit` as `name` of `program` (shaders/lightsim/live_count.glsl:
  // uLiveCount).
  void bind(const gl::Program& program, int unit, const char* name = "uLiveCount") const;

 private:
  gl::Texture2D texture_;        // 1×1 RGBA32F
  gl::Framebuffer framebuffer_;  // texture_ attached (the read of request())
  gl::Buffer pbo_;
  bool pending_ = false;
};

}  // namespace eik::gpu
