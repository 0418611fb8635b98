// How the sphere pipeline colours a particle (set 0, binding 0; viewer/src/particles.cpp fills it):
// the staged path gives each particle's linear colour as its second attribute (mode 0); the
// zero-copy path gives per-particle colours the same way for body and kind colours, and for speed
// and height colours the particle's velocity (mode 1) or nothing (mode 2), which are coloured
// here by render::ParticleColors' rule with its map's stops.
#ifndef COLORS_WRITABLE
#define COLORS_ACCESS readonly
#else
#define COLORS_ACCESS
#endif
layout(std430, set = 0, binding = 0) COLORS_ACCESS buffer Colors {
  vec4 stops[5];  // the colour map, sRGB, at 0, 1/4, ... 1
  vec4 up;        // the unit axis heights are measured along
  vec4 range;     // x, y: the height range (y > x, else every height is mid-map)
  uint mode;      // 0: linear colour attribute; 1: by speed, the attribute a velocity; 2: by height
  uint speed2;    // floatBitsToUint of the largest squared speed seen (speed_max.comp)
} colors;

// render::ParticleColors' map: linear between equal steps, clamped; sRGB.
vec3 colormap(float t) {
  if (!(t > 0.0)) return colors.stops[0].rgb;
  if (t >= 1.0) return colors.stops[4].rgb;
  float x = t * 4.0;
  int i = int(x);
  float f = x - float(i);
  return colors.stops[i].rgb * (1.0 - f) + colors.stops[i + 1].rgb * f;
}

// Linear colour of a particle at `sphere` (centre, radius) with second attribute `extra`.
vec3 particle_color(vec4 sphere, vec4 extra) {
  vec3 srgb;
  if (colors.mode == 1u) {
    float top = sqrt(uintBitsToFloat(colors.speed2));
    srgb = top > 0.0 ? colormap(length(extra.xyz) / top) : colormap(0.0);
  } else if (colors.mode == 2u) {
    float lo = colors.range.x, hi = colors.range.y;
    srgb = hi > lo ? colormap((dot(colors.up.xyz, sphere.xyz) - lo) / (hi - lo)) : colormap(0.5);
  } else {
    return extra.rgb;
  }
  return srgb * srgb;  // gamma 2, as the headless renderer
}
