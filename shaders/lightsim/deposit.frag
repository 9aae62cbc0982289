#version 330 core
// ALGORITHM.md step 4: writes one patch's deposit into the two atlas targets (lightsim/atlas.h);
// additive blending sums them (accumulate), or the depth test keeps the strongest patch (max).
in vec4 vEnergy;
in vec4 vDirection;
in float vDepth;
layout(location = 0) out vec4 oEnergy;
layout(location = 1) out vec4 oDirection;

void main() {
  oEnergy = vEnergy;
  oDirection = vDirection;
#ifdef DEPOSIT_MAX
  gl_FragDepth = vDepth;
#endif
}
