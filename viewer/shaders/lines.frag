#version 450
// A wireframe's segment in its colour (lines.vert).
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(location = 0) in vec3 color;

layout(location = 0) out vec4 out_color;

void main() { out_color = to_output(color); }
