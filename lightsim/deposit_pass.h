// DepositPass: ALGORITHM.md step 4, deposit (atlas voxelisation, §6.2.3): one GL_POINTS primitive
// per live patch (gl_VertexID = patch index) into the flat-3D atlas (atlas.h), landing on the texel
// of the voxel the analysis pass chose with the value it computed; the pass only scatters.
//
//   shader   shaders/lightsim/deposit.vert + deposit.frag, compiled for one deposit mode and the
//            atlas layout (AtlasLayout::defines)
//   step     4: accumulate: (Φ·Δs_m/V_voxel, 0) and (lum(Φ)·Δs_m·d, 1) summed by additive blending
//            (gl::ScopedBlendAdd); max: (E, lum(E)) and (d, 1) of the patch with the largest lum(E),
//            kept by a depth test (gl::ScopedDepthTest, GL_LESS) on ½ / (1 + lum(E)/E_ref)
//   in       depositA = (value, atlas x; x < 0: none) and depositB = (direction, atlas y) of
//            patches 0 .. count − 1 in the patch list layout (StepTargets), and E_ref (energyRef)
//   out      `atlas`: its two RGBA32F targets (and, max, its depth), added to or replaced
//
// The CPU twin is the sequential deposit loop of CpuSimulator::run (patch order, double sums).
#pragma once

#include <cstddef>

#include "gl/program.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "gl/vertex_array.h"
#include "lightsim/atlas.h"
#include "lightsim/simulator.h"

namespace eik::gpu {

class DepositPass {
 public:
  DepositPass(const gl::ShaderLibrary& library, const AtlasLayout& layout, DepositMode mode);
  // Deposits patches 0 .. count − 1. energyRef: E_ref of the max-mode depth mapping (a positive
  // irradiance well below the ones that matter).
  void run(const gl::Texture2D& depositA, const gl::Texture2D& depositB, std::size_t count, AtlasTargets& atlas,
           float energyRef) const;

 private:
  gl::Program program_;
  gl::VertexArray vao_;
  DepositMode mode_;
};

}  // namespace eik::gpu
