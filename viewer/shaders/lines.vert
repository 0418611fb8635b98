#version 450
// The segments of a wireframe (motes view's W and C keys, viewer/src/wireframe.cpp): world points
// to clip space; drawn over the picture without a depth test.
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(location = 0) in vec4 point;  // xyz; w unused
layout(location = 1) in vec4 color;  // linear RGB

layout(location = 0) out vec3 out_color;

void main() {
  out_color = color.rgb;
  gl_Position = to_clip(point.xyz);
}
