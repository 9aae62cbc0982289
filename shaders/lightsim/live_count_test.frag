#version 330 core
// Test pass of lightsim/live_count_test.cpp: 1 where the fragment's Morton slot is below
// liveCount(), 0 elsewhere.
#include "lightsim/live_count.glsl"
#include "lightsim/histo_pyramid.glsl"

out vec4 oLive;

void main() { oLive = vec4(hpTexelSlot(ivec2(gl_FragCoord.xy)) < liveCount() ? 1.0 : 0.0); }
