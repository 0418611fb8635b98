#version 450
// A round point.
layout(location = 0) in vec3 color;
layout(location = 0) out vec4 out_color;

void main() {
  if (length(gl_PointCoord - vec2(0.5)) > 0.5) discard;
  out_color = vec4(color, 1.0);
}
