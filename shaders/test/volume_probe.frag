#version 330 core
// Test (gl/ tests): samples an uploaded volume through common/volume.glsl at voxel centres, laid
// out like fetch3d.frag. PROBE(uvw) is a define: the vec4 expression to write.
#include "common/volume.glsl"

uniform ivec3 uDims;
out vec4 outColor;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec3 v = ivec3(p.x % uDims.x, p.y, p.x / uDims.x);
  vec3 uvw = (vec3(v) + 0.5) / vec3(uDims);
  outColor = PROBE(uvw);
}
