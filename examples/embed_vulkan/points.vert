#version 450
// One point per particle, straight from motes' buffers: ParticlePos (centre, radius) and
// ParticleVel (velocity, inverse mass) as per-vertex attributes. An orthographic view along -z.
layout(location = 0) in vec4 particle;
layout(location = 1) in vec4 velocity;
layout(push_constant) uniform View {
  vec4 frame;  // xy: the picture's centre in the world, z: pixels per metre, w: width / height
  vec2 size;   // the picture in pixels
} view;
layout(location = 0) out vec3 color;

void main() {
  vec2 p = (particle.xy - view.frame.xy) * view.frame.z;  // pixels from the centre
  gl_Position = vec4(2.0 * p.x / view.size.x, -2.0 * p.y / view.size.y, 0.5, 1.0);
  gl_PointSize = max(2.0, 2.0 * particle.w * view.frame.z);
  float speed = clamp(length(velocity.xyz), 0.0, 1.0);  // m/s: blue at rest, orange at 1 m/s
  color = mix(vec3(0.2, 0.45, 0.9), vec3(1.0, 0.45, 0.1), speed);
}
