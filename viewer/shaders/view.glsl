// The camera and scene constants every viewer shader reads (push constants, 128 bytes; filled by
// viewer/src/painter.cpp). Pixel conventions as render/src/camera.cpp: a pixel (i, j) centre at
// (i + 0.5, j + 0.5), rows down, the ray through it forward * focal + right * (x - half_width) -
// up * (y - half_height). Depth is near / (distance along forward): 1 at the near plane, 0 at
// infinity (the depth test keeps the greater).
layout(push_constant) uniform View {
  vec4 eye;       // w: focal length in pixels
  vec4 right;     // w: half the width in pixels
  vec4 up;        // w: half the height in pixels
  vec4 forward;   // w: near plane distance
  vec4 light;     // unit, towards the light; w: grid spacing
  vec4 world_up;  // unit; w: ground height
  vec4 centre;    // centre of the first frame's particles; w: their radius
  vec4 grid_x;    // a unit axis of the grid on the ground; w: 1 when there is a ground
} view;

// Clip coordinates of a world point.
vec4 to_clip(vec3 p) {
  vec3 rel = p - view.eye.xyz;
  float z = dot(rel, view.forward.xyz);
  float x = dot(rel, view.right.xyz) * view.eye.w / view.right.w;
  float y = -dot(rel, view.up.xyz) * view.eye.w / view.up.w;
  return vec4(x, y, view.forward.w, z);
}

// Linear colour to the 8-bit output (gamma 2, as render/src/shading.cpp's store_srgb8).
vec4 to_output(vec3 linear) { return vec4(sqrt(clamp(linear, 0.0, 1.0)), 1.0); }
