#version 450
// The sky and, when the scene has one, the ground with its grid, per pixel as the headless
// renderer draws them (render/src/shade_pass.cpp, without shadows); the ground writes its depth,
// the sky the farthest.
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(location = 0) out vec4 out_color;

float line_coverage(float a, float grid, float footprint) {
  float dist = abs(a - round(a)) * grid;
  float half_width = 0.012 * grid;
  float cover = clamp((half_width - dist) / footprint + 0.5, 0.0, 1.0);
  return cover * clamp(1.0 - (footprint / grid - 0.08) / 0.25, 0.0, 1.0);
}

void main() {
  vec2 px = gl_FragCoord.xy;
  float focal = view.eye.w;
  vec3 d = view.forward.xyz * focal + view.right.xyz * (px.x - view.right.w) -
           view.up.xyz * (px.y - view.up.w);
  float f = clamp(px.y / (2.0 * view.up.w), 0.0, 1.0);
  vec3 top = vec3(0.62, 0.70, 0.80), bottom = vec3(0.90, 0.92, 0.95);
  vec3 sky_srgb = mix(top, bottom, f);
  vec3 sky = sky_srgb * sky_srgb;
  vec3 color = sky;
  float depth = 0.0;

  vec3 up = view.world_up.xyz;
  float ground = view.world_up.w;
  float eye_height = dot(view.eye.xyz, up);
  float dn = dot(d, up);
  if (view.grid_x.w > 0.5 && eye_height > ground && dn < 0.0) {
    float t = (ground - eye_height) / dn;
    vec3 hit = view.eye.xyz + t * d;
    depth = view.forward.w / (t * focal);
    vec3 rel = hit - view.centre.xyz;
    vec3 across = rel - up * dot(rel, up);
    float radius = view.centre.w;
    float fade = smoothstep(2.0 * radius, 5.0 * radius, length(across));
    if (fade < 1.0) {
      float grid = view.light.w;
      float slope = max(0.15, abs(dot(normalize(d), up)));
      float footprint = t * length(d) / focal / slope;
      vec3 grid_x = view.grid_x.xyz;
      vec3 grid_z = normalize(cross(grid_x, up));
      float line = max(line_coverage(dot(hit, grid_x) / grid, grid, footprint),
                       line_coverage(dot(hit, grid_z) / grid, grid, footprint));
      vec3 ground_srgb = vec3(0.86, 0.85, 0.82), grid_srgb = vec3(0.50, 0.52, 0.56);
      vec3 ground_base = ground_srgb * ground_srgb, grid_base = grid_srgb * grid_srgb;
      vec3 base = ground_base + (grid_base - ground_base) * (0.45 * line);
      float light_up = max(0.0, dot(up, view.light.xyz));
      color = mix(base * (0.42 + 0.55 * light_up), sky, fade);
    }
  }
  gl_FragDepth = depth;
  out_color = to_output(color);
}
