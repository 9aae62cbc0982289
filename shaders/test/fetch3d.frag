// Test (gl/ tests): reads a 3D texture back through a fragment shader. Pixel (x, y) of a
// (dims.x·dims.z) × dims.y target shows voxel (x mod dims.x, y, x div dims.x).
// No #version on purpose: ShaderLibrary then adds "#version 330 core".
// USE_SAMPLER: filtered texture() at the voxel centre instead of texelFetch.
uniform sampler3D uTex;
uniform ivec3 uDims;
out vec4 outColor;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec3 v = ivec3(p.x % uDims.x, p.y, p.x / uDims.x);
#ifdef USE_SAMPLER
  outColor = texture(uTex, (vec3(v) + 0.5) / vec3(uDims));
#else
  outColor = texelFetch(uTex, v, 0);
#endif
}
