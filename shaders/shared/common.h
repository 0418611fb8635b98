// Common prelude for headers shared by C++ (OpenMP backend, core), CUDA and GLSL.
//
// Rules for every header in shaders/shared/ (see docs/architecture.md):
//  - GLSL-spelled types only: float, int, uint, vec3, vec4, uvec4; no swizzles (write v.x, v.y).
//  - Functions are declared MOTES_FN; out-parameters use MOTES_OUT(T) / MOTES_INOUT(T); large
//    read-only structs MOTES_IN(T) (a const reference in C++ and CUDA: no copy per call).
//  - Float literals carry the f suffix (valid GLSL 4.50 and C++), so C++ never widens to double.
//  - No pointers, templates, references or overloads that differ only by return type.
//  - Types live in namespace motes::shared in C++ (MOTES_SHARED_BEGIN/END), globally in GLSL.
//  - Where every backend must get bit-identical floats (the integer decisions of the neighbour
//    lists), products go through mul_rn: a rounded product that no compiler may fuse into a
//    multiply-add (CUDA __fmul_rn, GLSL `precise`; C++ in ISO mode does not contract).
#ifndef MOTES_SHARED_COMMON_H
#define MOTES_SHARED_COMMON_H

#ifdef __cplusplus

#include <cmath>
#include <cstddef>
#include <cstdint>

#ifdef __CUDACC__
#define MOTES_FN __host__ __device__ inline
#else
#define MOTES_FN inline
#endif
#define MOTES_INOUT(T) T&
#define MOTES_OUT(T) T&
#define MOTES_IN(T) const T&
#define MOTES_SHARED_BEGIN \
  namespace motes {        \
  namespace shared {
#define MOTES_SHARED_END \
  }                      \
  }

MOTES_SHARED_BEGIN

using uint = std::uint32_t;

struct vec3 {
  float x, y, z;
  MOTES_FN vec3() : x(0.0f), y(0.0f), z(0.0f) {}
  MOTES_FN explicit vec3(float s) : x(s), y(s), z(s) {}
  MOTES_FN vec3(float a, float b, float c) : x(a), y(b), z(c) {}
};

// 16-byte aligned, as std430 lays out vec4 in GPU buffers.
struct alignas(16) vec4 {
  float x, y, z, w;
  MOTES_FN vec4() : x(0.0f), y(0.0f), z(0.0f), w(0.0f) {}
  MOTES_FN explicit vec4(float s) : x(s), y(s), z(s), w(s) {}
  MOTES_FN vec4(float a, float b, float c, float d) : x(a), y(b), z(c), w(d) {}
  MOTES_FN vec4(vec3 v, float d) : x(v.x), y(v.y), z(v.z), w(d) {}
};
static_assert(sizeof(vec4) == 16 && alignof(vec4) == 16, "vec4 must match std430");

MOTES_FN vec3 operator+(vec3 a, vec3 b) { return vec3(a.x + b.x, a.y + b.y, a.z + b.z); }
MOTES_FN vec3 operator-(vec3 a, vec3 b) { return vec3(a.x - b.x, a.y - b.y, a.z - b.z); }
MOTES_FN vec3 operator-(vec3 a) { return vec3(-a.x, -a.y, -a.z); }
MOTES_FN vec3 operator*(vec3 a, float s) { return vec3(a.x * s, a.y * s, a.z * s); }
MOTES_FN vec3 operator*(float s, vec3 a) { return vec3(a.x * s, a.y * s, a.z * s); }
MOTES_FN vec3 operator*(vec3 a, vec3 b) { return vec3(a.x * b.x, a.y * b.y, a.z * b.z); }
MOTES_FN vec3 operator/(vec3 a, float s) { return vec3(a.x / s, a.y / s, a.z / s); }
MOTES_FN vec3& operator+=(vec3& a, vec3 b) {
  a = a + b;
  return a;
}
MOTES_FN vec3& operator-=(vec3& a, vec3 b) {
  a = a - b;
  return a;
}
MOTES_FN vec4 operator+(vec4 a, vec4 b) { return vec4(a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w); }
MOTES_FN vec4 operator*(vec4 a, float s) { return vec4(a.x * s, a.y * s, a.z * s, a.w * s); }
MOTES_FN vec4& operator+=(vec4& a, vec4 b) {
  a = a + b;
  return a;
}

MOTES_FN float dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
MOTES_FN float dot(vec4 a, vec4 b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
MOTES_FN vec3 cross(vec3 a, vec3 b) {
  return vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
MOTES_FN float sqrt(float x) { return std::sqrt(x); }
MOTES_FN float abs(float x) { return std::fabs(x); }
MOTES_FN float floor(float x) { return std::floor(x); }
MOTES_FN float sin(float x) { return std::sin(x); }
MOTES_FN float cos(float x) { return std::cos(x); }
MOTES_FN float max(float a, float b) { return a > b ? a : b; }
MOTES_FN float min(float a, float b) { return a < b ? a : b; }
MOTES_FN float clamp(float x, float lo, float hi) { return min(max(x, lo), hi); }
MOTES_FN float length(vec3 a) { return sqrt(dot(a, a)); }
MOTES_FN vec3 xyz(vec4 v) { return vec3(v.x, v.y, v.z); }
/// c ? a : b, component by component: a choice without a branch, so that a loop over contacts
/// stays one straight line a compiler can put in vector lanes (GLSL's ?: on vectors).
MOTES_FN vec3 choose(bool c, vec3 a, vec3 b) {
  return vec3(c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z);
}
MOTES_FN vec4 choose(bool c, vec4 a, vec4 b) {
  return vec4(c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z, c ? a.w : b.w);
}

#ifdef __CUDACC__
MOTES_FN float mul_rn(float a, float b) {
#ifdef __CUDA_ARCH__
  return __fmul_rn(a, b);
#else
  return a * b;
#endif
}
#else
MOTES_FN float mul_rn(float a, float b) { return a * b; }
#endif

/// a + b rounded, and in err what the rounding lost, exactly (Knuth's TwoSum: six operations in
/// the order written, which no compiler may reorder; GLSL marks them `precise`).
MOTES_FN vec3 add_exact(vec3 a, vec3 b, MOTES_OUT(vec3) err) {
  vec3 s = a + b;
  vec3 bb = s - a;
  err = (a - (s - bb)) + (b - bb);
  return s;
}

MOTES_SHARED_END

#else  // GLSL

#define MOTES_FN
#define MOTES_INOUT(T) inout T
#define MOTES_OUT(T) out T
#define MOTES_IN(T) in T
#define MOTES_SHARED_BEGIN
#define MOTES_SHARED_END
vec3 xyz(vec4 v) { return vec3(v.x, v.y, v.z); }
vec3 choose(bool c, vec3 a, vec3 b) { return c ? a : b; }
vec4 choose(bool c, vec4 a, vec4 b) { return c ? a : b; }
float mul_rn(float a, float b) {
  precise float r = a * b;
  return r;
}
vec3 add_exact(vec3 a, vec3 b, out vec3 err) {
  precise vec3 s = a + b;
  precise vec3 bb = s - a;
  precise vec3 e = (a - (s - bb)) + (b - bb);
  err = e;
  return s;
}

#endif

#endif  // MOTES_SHARED_COMMON_H
