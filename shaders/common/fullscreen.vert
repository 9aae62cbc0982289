#version 330 core
// A triangle that covers the whole viewport, made from gl_VertexID alone: draw 3 vertices with an
// empty vertex array (gl::FullscreenTriangle). vUv runs over [0,1]² across the viewport.
out vec2 vUv;

void main() {
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));  // (0,0) (2,0) (0,2)
  vUv = corner;
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
