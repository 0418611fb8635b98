#version 450
// A camera-facing quad per particle (4 vertices as a triangle strip, one instance per particle),
// large enough to cover the sphere's outline; sphere.frag finds the sphere inside it.
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"
#include "colors.glsl"

layout(location = 0) in vec4 sphere;  // per instance: centre, w = radius
layout(location = 1) in vec4 extra;   // per instance: linear RGB, or a velocity (colors.glsl)

layout(location = 0) out vec3 quad_point;
layout(location = 1) flat out vec4 out_sphere;
layout(location = 2) flat out vec3 out_color;

void main() {
  out_sphere = sphere;
  out_color = particle_color(sphere, extra);
  vec3 to_centre = sphere.xyz - view.eye.xyz;
  float d = length(to_centre);
  float r = sphere.w;
  // A particle that is not finite is not drawn (the staged path leaves it out).
  bool finite = !any(isnan(sphere)) && !any(isinf(sphere));
  if (!finite || !(r > 0.0) || d <= 1.001 * r) {
    // Not drawn: every vertex at the same point outside the view, a triangle of no area.
    quad_point = sphere.xyz;
    gl_Position = vec4(2.0, 2.0, 0.5, 1.0);
    return;
  }
  vec3 n = to_centre / d;
  vec3 helper = abs(dot(n, view.up.xyz)) < 0.9 ? view.up.xyz : view.right.xyz;
  vec3 s = normalize(cross(helper, n));
  vec3 t = cross(n, s);
  // The cone of rays from the eye that touch the sphere cuts the plane through the centre
  // (facing the eye) in a circle of this radius; the quad holds it, with a margin.
  float half_size = 1.02 * r * d / sqrt(d * d - r * r);
  vec2 corner = vec2((gl_VertexIndex & 1) != 0 ? 1.0 : -1.0, (gl_VertexIndex & 2) != 0 ? 1.0 : -1.0);
  quad_point = sphere.xyz + half_size * (corner.x * s + corner.y * t);
  gl_Position = to_clip(quad_point);
}
