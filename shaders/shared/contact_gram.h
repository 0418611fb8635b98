// The step of the velocity pass of position contacts (shared/position.h), made to converge where
// mass splitting does not.
//
// The velocity pass is a Jacobi iteration on the contacts' normal velocities. Mass splitting
// divides a contact's velocity error by N (1/m + (r x n) I^-1 (r x n)) for a body of N contacts:
// safe, but a flat face of N contacts then closes only the mean of (1/m) / (1/m + (r x n) I^-1
// (r x n)) of its error a sweep (the contacts' turning parts cancel in the body's sum, yet each
// contact's step counted them), 44% for a 3 x 1 x 3 box, and two sweeps left a box dropped flat
// with a fifth of its bounce (docs/position-solver.md).
//
// Here each body's step is bounded by the largest eigenvalue of its contacts' Gram matrix instead:
// with g_c = M^-1/2 J_c^T the contact's row in the body's mass-weighted coordinates (J_c = [n,
// r x n]), H = sum over the body's contacts of g_c g_c^T, and lambda_b >= its largest eigenvalue, a
// contact of bodies a and b steps by its error / (s_a lambda_a + s_b lambda_b) (s: the stack
// scales). The sweeps then never overshoot: with D the contacts' denominators, x^T D^-1/2 A
// D^-1/2 x = sum over bodies of |sum_c x_c sqrt(s_c / D_c) g_c|^2 <= sum_c x_c^2 (s_a lambda_a +
// s_b lambda_b) / D_c = |x|^2, so the iteration matrix's eigenvalues lie in [0, 1) and every sweep
// lowers the error in the energy norm (Richardson's iteration). A flat face's uniform mode, whose
// eigenvalue is N/m, the largest, closes in one sweep; one contact's lambda is its own
// 1/m + (r x n) I^-1 (r x n), as before.
//
// lambda_b is an upper bound, never an estimate from below: trace(H) (trace((H / trace
// H)^16))^(1/16) (the 16th root of the sum of the eigenvalues' 16th powers, over their largest by
// at most 6^(1/16) = 1.12 and by 0.3% for a flat face's spectrum). The counting pass
// (MOTES_FLAG_POSITION_GRAM) gives each particle sum of n n^T over its contacts (the arm is the
// particle's centre for all of them: shared/contact_body.h, contact_acting_point), and
// impulses_apply sums the blocks [S, S R^T; R S, R S R^T] (R = [r]x) over a body's particles in
// the order of its other sums (shared/impulse.h, MOTES_BODY_CHUNK).
#ifndef MOTES_SHARED_CONTACT_GRAM_H
#define MOTES_SHARED_CONTACT_GRAM_H

#include "common.h"
#include "quaternion.h"

MOTES_SHARED_BEGIN

/// A body's contact Gram matrix K = sum of J_c^T J_c (6 x 6, row-major; linear rows first), before
/// its mass weighting.
struct ContactGram {
  float k[36];
};

MOTES_FN ContactGram gram_zero() {
  ContactGram g;
  for (int i = 0; i < 36; ++i) g.k[i] = 0.0f;
  return g;
}

/// total += part, entry by entry (the chunks of a body's sum: shared/impulse.h, MOTES_BODY_CHUNK).
MOTES_FN void gram_merge(MOTES_INOUT(ContactGram) total, MOTES_IN(ContactGram) part) {
  for (int i = 0; i < 36; ++i) total.k[i] += part.k[i];
}

/// Adds the 3 x 3 block of rows a0, a1, a2 to K at (row, col).
MOTES_FN void gram_block_add(MOTES_INOUT(ContactGram) g, int row, int col, vec3 a0, vec3 a1,
                             vec3 a2) {
  g.k[row * 6 + col] += a0.x;
  g.k[row * 6 + col + 1] += a0.y;
  g.k[row * 6 + col + 2] += a0.z;
  g.k[(row + 1) * 6 + col] += a1.x;
  g.k[(row + 1) * 6 + col + 1] += a1.y;
  g.k[(row + 1) * 6 + col + 2] += a1.z;
  g.k[(row + 2) * 6 + col] += a2.x;
  g.k[(row + 2) * 6 + col + 1] += a2.y;
  g.k[(row + 2) * 6 + col + 2] += a2.z;
}

/// Adds a particle's contacts to its body's K: nn_diag.xyz and nn_off.xyz are the diagonal (xx,
/// yy, zz) and off-diagonal (xy, xz, yz) of S = sum of n n^T over its contacts, r its centre from
/// the body's centre. Nothing for a particle without contacts.
MOTES_FN void gram_add(MOTES_INOUT(ContactGram) g, vec4 nn_diag, vec4 nn_off, vec3 r) {
  if (nn_diag.x == 0.0f && nn_diag.y == 0.0f && nn_diag.z == 0.0f) return;
  // With R = [r]x (R v = r x v): the rows of S, of S R^T (row i: r x s_i), of its transpose R S
  // (the columns of S R^T) and of R S R^T (symmetric; row j: r x (column j of S R^T)).
  vec3 s0 = vec3(nn_diag.x, nn_off.x, nn_off.y);
  vec3 s1 = vec3(nn_off.x, nn_diag.y, nn_off.z);
  vec3 s2 = vec3(nn_off.y, nn_off.z, nn_diag.z);
  vec3 p0 = cross(r, s0);
  vec3 p1 = cross(r, s1);
  vec3 p2 = cross(r, s2);
  vec3 c0 = vec3(p0.x, p1.x, p2.x);
  vec3 c1 = vec3(p0.y, p1.y, p2.y);
  vec3 c2 = vec3(p0.z, p1.z, p2.z);
  gram_block_add(g, 0, 0, s0, s1, s2);
  gram_block_add(g, 0, 3, p0, p1, p2);
  gram_block_add(g, 3, 0, c0, c1, c2);
  gram_block_add(g, 3, 3, cross(r, c0), cross(r, c1), cross(r, c2));
}

/// An upper bound of the largest eigenvalue of M^-1/2 K M^-1/2 for a body (com.w: inverse mass,
/// inv_inertia.xyz: inverse principal moments, quat: its orientation); 0 for a static body or one
/// without contacts.
MOTES_FN float gram_bound(MOTES_IN(ContactGram) g, vec4 com, vec4 quat, vec4 inv_inertia) {
  if (com.w == 0.0f) return 0.0f;
  // T: rows 0-2 sqrt(1/m) e_i, rows 3-5 sqrt(1/I_k) c_k^T (c_k the body's axes in the world); the
  // eigenvalues of T K T^T are those of M^-1/2 K M^-1/2.
  float t[36];
  for (int i = 0; i < 36; ++i) t[i] = 0.0f;
  float sm = sqrt(com.w);
  t[0] = sm;
  t[7] = sm;
  t[14] = sm;
  vec3 c0 = quat_rotate(quat, vec3(1.0f, 0.0f, 0.0f)) * sqrt(inv_inertia.x);
  vec3 c1 = quat_rotate(quat, vec3(0.0f, 1.0f, 0.0f)) * sqrt(inv_inertia.y);
  vec3 c2 = quat_rotate(quat, vec3(0.0f, 0.0f, 1.0f)) * sqrt(inv_inertia.z);
  t[21] = c0.x;
  t[22] = c0.y;
  t[23] = c0.z;
  t[27] = c1.x;
  t[28] = c1.y;
  t[29] = c1.z;
  t[33] = c2.x;
  t[34] = c2.y;
  t[35] = c2.z;
  float tk[36];
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      float v = 0.0f;
      for (int k = 0; k < 6; ++k) v += t[i * 6 + k] * g.k[k * 6 + j];
      tk[i * 6 + j] = v;
    }
  }
  float h[36];
  float trace = 0.0f;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      float v = 0.0f;
      for (int k = 0; k < 6; ++k) v += tk[i * 6 + k] * t[j * 6 + k];
      h[i * 6 + j] = v;
    }
    trace += h[i * 7];
  }
  if (!(trace > 0.0f)) return 0.0f;
  for (int i = 0; i < 36; ++i) h[i] = h[i] / trace;
  // Four squarings: h = (H / trace H)^16.
  for (int step = 0; step < 4; ++step) {
    float sq[36];
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) {
        float v = 0.0f;
        for (int k = 0; k < 6; ++k) v += h[i * 6 + k] * h[k * 6 + j];
        sq[i * 6 + j] = v;
      }
    }
    for (int i = 0; i < 36; ++i) h[i] = sq[i];
  }
  float p16 = 0.0f;
  for (int i = 0; i < 6; ++i) p16 += h[i * 7];
  return trace * sqrt(sqrt(sqrt(sqrt(max(p16, 0.0f)))));
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_CONTACT_GRAM_H
