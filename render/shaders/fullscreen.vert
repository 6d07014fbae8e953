#version 300 es
// One triangle that covers the viewport, from gl_VertexID alone (no vertex buffer): ids 0, 1, 2 give
// (-1, -1), (3, -1), (-1, 3). A single triangle has no diagonal seam where two would share quads.
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
