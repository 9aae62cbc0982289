#version 330 core
// ALGORITHM.md step 5 (thesis §6.2.4): the output count of each patch (0, 1 or 4), the base of the
// histogram pyramid, and its fate code (lightsim/fate.glsl) for the ledger. Slots at or beyond
// uCount get count 0.
#include "common/volume.glsl"
#include "lightsim/grid.glsl"
#include "lightsim/patch.glsl"
#include "lightsim/fate.glsl"

uniform sampler2D uPatch[8];
uniform int uCount;

layout(location = 0) out vec4 oCount;
layout(location = 1) out vec4 oFate;

void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy);
  int fate = FATE_NONE;
  if (mortonIndex(texel) < uCount) {
    Patch p;
    FETCH_PATCH(uPatch, texel, p);
    fate = patchFate(p);
  }
  oCount = vec4(fateCount(fate), 0.0, 0.0, 0.0);
  oFate = vec4(float(fate), 0.0, 0.0, 0.0);
}
