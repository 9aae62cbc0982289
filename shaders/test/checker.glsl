// Test helper (gl/ tests): 1 on the "odd" cells of a checkerboard of `cell` pixels, else 0.
float checker(vec2 fragCoord, float cell) {
  ivec2 c = ivec2(floor(fragCoord / cell));
  return float((c.x + c.y) & 1);
}
