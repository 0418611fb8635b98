#version 450
// The shadow of a particle on the ground (docs/viewer.md, "Shadows"): the sphere's outline cast
// along the light onto the ground plane, an ellipse, covered by one quad on the ground (4
// vertices as a triangle strip, one instance per particle, the sphere pipeline's first
// per-instance array). Drawn after the spheres (a shadow hidden behind them fails the depth test
// before its fragments run) and before the backdrop: shadow.frag writes how much of the ground's
// output colour is left into the picture's alpha, by which backdrop.frag's colour is then scaled.
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(location = 0) in vec4 sphere;  // per instance: centre, w = radius

layout(location = 0) out vec2 ellipse;  // the ground point in units of the ellipse's semi-axes
// x: half the soft edge's width (same units as ellipse); y: the share of the ground's light the
// shadow's core takes away; z: how much the ground is faded into the sky there (backdrop.frag).
layout(location = 1) flat out vec3 shade;

void main() {
  vec3 up = view.world_up.xyz;
  float ground = view.world_up.w;
  vec3 light = view.light.xyz;
  float r = sphere.w;
  float height = dot(sphere.xyz, up) - ground;  // of the centre
  float sin_elevation = dot(light, up);
  bool finite = !any(isnan(sphere)) && !any(isinf(sphere));
  // No shadow without a ground seen from above, with a light so low that shadows are long, or
  // for a particle that is not finite or lies under the ground.
  if (!finite || !(r > 0.0) || view.grid_x.w < 0.5 || dot(view.eye.xyz, up) <= ground ||
      !(sin_elevation > 0.1) || height < -r) {
    ellipse = vec2(0.0);
    shade = vec3(0.0);
    gl_Position = vec4(2.0, 2.0, 0.5, 1.0);  // a triangle of no area outside the view
    return;
  }
  // The centre cast along the light, and the ellipse's semi-axes: r / sin(elevation) along the
  // light's direction on the ground, r across it.
  vec3 centre = sphere.xyz - light * (height / sin_elevation);
  vec3 flat_light = light - up * sin_elevation;
  vec3 along = dot(flat_light, flat_light) > 1e-8 ? normalize(flat_light) : view.grid_x.xyz;
  vec3 across = cross(up, along);
  // Higher above the ground: a wider soft edge and a lighter shadow (the penumbra of a light of
  // some size, and the sky's light reaching under the particle).
  float gap = max(height - r, 0.0) / r;
  float soft = 0.2 + 0.5 * clamp(gap / 6.0, 0.0, 1.0);
  float darkness = 0.8 / (1.0 + 0.15 * gap);
  // As the headless renderer shades the ground (render/src/shade_pass.cpp), base * (0.42 + 0.55 *
  // lit * light_up): the share of it that the direct light is.
  float direct = 0.55 * sin_elevation / (0.42 + 0.55 * sin_elevation);
  // The ground fades into the sky away from the particles (backdrop.frag); so does the shadow.
  vec3 rel = centre - view.centre.xyz;
  float fade = smoothstep(2.0 * view.centre.w, 5.0 * view.centre.w, length(rel - up * dot(rel, up)));
  float reach = 1.0 + soft;
  vec2 corner = vec2((gl_VertexIndex & 1) != 0 ? 1.0 : -1.0, (gl_VertexIndex & 2) != 0 ? 1.0 : -1.0);
  ellipse = reach * corner;
  shade = vec3(soft, darkness * direct, fade);
  gl_Position = to_clip(centre + reach * r * (corner.x / sin_elevation * along + corner.y * across));
}
