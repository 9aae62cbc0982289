#version 330 core
// Writes one patch's ledger entries (lightsim/ledger.vert) into the eight targets; additive
// blending sums them.
in vec4 vEntry[8];
layout(location = 0) out vec4 o0;
layout(location = 1) out vec4 o1;
layout(location = 2) out vec4 o2;
layout(location = 3) out vec4 o3;
layout(location = 4) out vec4 o4;
layout(location = 5) out vec4 o5;
layout(location = 6) out vec4 o6;
layout(location = 7) out vec4 o7;
void main() {
  o0 = vEntry[0]; o1 = vEntry[1]; o2 = vEntry[2]; o3 = vEntry[3];
  o4 = vEntry[4]; o5 = vEntry[5]; o6 = vEntry[6]; o7 = vEntry[7];
}
