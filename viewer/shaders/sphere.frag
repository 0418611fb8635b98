#version 450
// The sphere seen through its quad: the ray from the eye, its first hit, the depth of that hit,
// and the headless renderer's shading without shadows (render/src/shade_pass.cpp).
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(location = 0) in vec3 quad_point;
layout(location = 1) flat in vec4 in_sphere;
layout(location = 2) flat in vec3 in_color;

layout(location = 0) out vec4 out_color;

void main() {
  vec3 eye = view.eye.xyz;
  vec3 dir = normalize(quad_point - eye);
  vec3 oc = in_sphere.xyz - eye;
  float r = in_sphere.w;
  float along = dot(oc, dir);
  vec3 across = oc - along * dir;
  float off2 = dot(across, across);
  if (off2 > r * r) discard;
  float t = along - sqrt(r * r - off2);
  if (!(t > 0.0)) discard;
  vec3 hit = eye + t * dir;
  float depth = dot(hit - eye, view.forward.xyz);
  gl_FragDepth = view.forward.w / depth;

  vec3 n = normalize(hit - in_sphere.xyz);
  vec3 light = view.light.xyz;
  vec3 to_eye = -dir;
  float diffuse = max(0.0, dot(n, light));
  float ambient = 0.16 + 0.2 * (0.5 + 0.5 * dot(n, view.world_up.xyz));
  float rim = 0.65 + 0.35 * max(0.0, dot(n, to_eye));
  vec3 half_vector = normalize(light + to_eye);
  float specular = diffuse > 0.0 ? 0.3 * pow(max(0.0, dot(n, half_vector)), 48.0) : 0.0;
  out_color = to_output(in_color * (ambient * rim + 0.8 * diffuse) + vec3(specular));
}
