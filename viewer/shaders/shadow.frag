#version 450
// Inside a particle's shadow on the ground (shadow.vert): the share of the ground's output colour
// that is left, into the picture's alpha (the pipeline writes alpha alone and keeps the least, so
// that overlapping shadows take the darkest rather than darken each other). backdrop.frag's
// colour is multiplied by it: the ground with `blocked` of its light taken away, in the output's
// gamma 2.
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(location = 0) in vec2 ellipse;
layout(location = 1) flat in vec3 shade;

layout(location = 0) out vec4 out_color;

void main() {
  float blocked = shade.y * (1.0 - smoothstep(1.0 - shade.x, 1.0 + shade.x, length(ellipse)));
  if (!(blocked > 0.0)) discard;
  out_color = vec4(0.0, 0.0, 0.0, mix(sqrt(1.0 - blocked), 1.0, shade.z));
}
