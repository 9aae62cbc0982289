#version 330 core
// Test producer of lightsim/histo_pyramid_test.cpp: writes the .r of uCounts into the pyramid's
// base through a framebuffer of its own, as the analysis pass does.
uniform sampler2D uCounts;

layout(location = 0) out vec4 oCount;

void main() { oCount = vec4(texelFetch(uCounts, ivec2(gl_FragCoord.xy), 0).r, 0.0, 0.0, 0.0); }
