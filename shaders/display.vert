#version 330 core
// One triangle that covers the viewport; no vertex buffer needed (a VAO is
// still bound because the core profile requires one).
out vec2 uv;

void main() {
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    // The film's row 0 is the top of the image, texture row 0 is the bottom.
    uv = vec2(corner.x, 1.0 - corner.y);
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
