// Flat 3D atlas addressing (lightsim/atlas.h, Harris et al. 2003): z-slices of the grid tiled
// ATLAS_TILES_X to a row. Needs the defines ATLAS_DIMS (ivec3), ATLAS_TILES_X (int) and
// ATLAS_SIZE (vec2) from AtlasLayout::defines().
ivec2 atlasTexel(ivec3 voxel) {
  return ivec2((voxel.z % ATLAS_TILES_X) * ATLAS_DIMS.x + voxel.x, (voxel.z / ATLAS_TILES_X) * ATLAS_DIMS.y + voxel.y);
}
// Clip-space position of a GL_POINTS primitive (size 1) that covers exactly atlas texel `t`.
vec4 atlasPointPosition(ivec2 t) {
  vec2 ndc = (vec2(t) + 0.5) / ATLAS_SIZE * 2.0 - 1.0;
  return vec4(ndc, 0.0, 1.0);
}
// A position no point survives clipping at (for patches that deposit nothing).
const vec4 kCulledPoint = vec4(2.0, 2.0, 2.0, 1.0);
