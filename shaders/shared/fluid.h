// Position-based fluids (issue 29; docs/fluids.md): Macklin and Müller 2013, "Position Based
// Fluids"; Macklin et al. 2014, "Unified Particle Physics for Real-Time Applications", section 7;
// Akinci et al. 2013, "Versatile Surface Tension and Adhesion for SPH Fluids". The per-pair terms
// every backend sums in its fixed list order, written once for C++, CUDA and GLSL.
//
// Conventions: r_ij = x_i - x_j; grad W_ij is the gradient of W(x_i - x_j) with respect to x_i
// (the gradient with respect to x_j is its negative). A fluid particle has mass m = rho_0 d^3 (d:
// its diameter, the rest spacing of its lattice) and support h (2 d: docs/fluids.md says why). A
// solid particle b counts in a fluid's density with the mass psi_b = s rho_0 d_b^3 (Macklin 2014,
// section 7.1) and takes no share of the density constraint's correction (its body takes the
// reaction). Kernels are written in q = r / h, so no power of h beyond h^4 is formed (h^9 of a
// millimetre support is below float's range).
#ifndef MOTES_SHARED_FLUID_H
#define MOTES_SHARED_FLUID_H

#include "common.h"

MOTES_SHARED_BEGIN

#define MOTES_FLUID_PI 3.14159265358979f

/// One fluid material, in the FluidMaterials table (docs/fluids.md, "Particles and buffers").
struct FluidMaterial {
  vec4 density_h;  // x: rest density rho_0 (kg/m^3), y: support h (m), z: particle mass (kg),
                   // w: alpha~, the constraint force mixing term (> 0): Jacobi's
                   // under-relaxation, a fixed fraction of a lattice particle's denominator at
                   // rest (0.5: docs/fluids.md, "Settled with the prototype")
  vec4 s_corr;     // x: k (dimensionless), y: n (a whole number >= 1), z: dq (m), w: solid scale s
  vec4 velocity;   // x: XSPH viscosity c, y: vorticity eps (m/s), z: cohesion gamma,
                   // w: adhesion beta
  vec4 reserved;   // 0
};

/// The poly6 kernel, 315 / (64 pi h^9) (h^2 - r^2)^3 for r < h, else 0; r2 = r^2.
MOTES_FN float fluid_poly6(float r2, float h) {
  float h2 = h * h;
  if (r2 >= h2) {
    return 0.0f;
  }
  float a = 1.0f - r2 / h2;
  return (315.0f / (64.0f * MOTES_FLUID_PI)) * (a * a * a) / (h * h2);
}

/// The spiky kernel, 15 / (pi h^6) (h - r)^3 for r < h, else 0 (Desbrun and Gascuel 1996;
/// Müller et al. 2003). Its gradient is what the density constraint uses.
MOTES_FN float fluid_spiky(float r, float h) {
  if (r >= h) {
    return 0.0f;
  }
  float a = 1.0f - r / h;
  return (15.0f / MOTES_FLUID_PI) * (a * a * a) / (h * h * h);
}

/// grad W_ij of the spiky kernel for r_ij = x_i - x_j: -45 / (pi h^6) (h - r)^2 r_ij / r, pointing
/// from i towards j (W falls with the distance); 0 beyond h and at r = 0.
MOTES_FN vec3 fluid_spiky_gradient(vec3 rij, float h) {
  float r2 = dot(rij, rij);
  if (r2 >= h * h || r2 == 0.0f) {
    return vec3(0.0f);
  }
  float r = sqrt(r2);
  float a = 1.0f - r / h;
  float h2 = h * h;
  return rij * ((-45.0f / MOTES_FLUID_PI) * (a * a) / (h2 * h2 * r));
}

/// The share of poly6 beyond a plane at distance z from the particle: the integral of W over the
/// half-space, (315 / 256) int_q^1 (1 - u^2)^4 du with q = z / h (1/2 at the plane, 0 from h on).
/// A plane counts rho_0 times it in a fluid particle's density, as fluid filling the solid side
/// would (docs/fluids.md, "Measured with the serial prototype": prototyped there, not yet in the
/// plan's kernels).
MOTES_FN float fluid_plane_share(float z, float h) {
  float q = clamp(z / h, 0.0f, 1.0f);
  // int_q^1 (1 - u^2)^4 du = (1 - q)^5 (128/315 + 65/63 q + 23/21 q^2 + 5/9 q^3 + 1/9 q^4): no
  // cancellation near q = 1, exactly 0 there.
  float a = 1.0f - q;
  float a2 = a * a;
  float rest =
      128.0f / 315.0f + q * (65.0f / 63.0f + q * (23.0f / 21.0f + q * (5.0f / 9.0f + q / 9.0f)));
  return (315.0f / 256.0f) * (a2 * a2 * a) * rest;
}

/// d/dz of fluid_plane_share: -(315 / 256) (1 - q^2)^4 / h for z < h, else 0 (the share falls
/// as the particle leaves the plane).
MOTES_FN float fluid_plane_share_slope(float z, float h) {
  if (z >= h) {
    return 0.0f;
  }
  float q = max(z / h, 0.0f);
  float a = 1.0f - q * q;
  float a2 = a * a;
  return -(315.0f / 256.0f) * (a2 * a2) / h;
}

/// The density constraint C = rho / rho_0 - 1, unilateral (clamped to >= 0: a particle short of
/// neighbours, at the free surface, is not pulled in; Macklin 2014, section 7) or not.
MOTES_FN float fluid_constraint(float rho, float rho0, bool unilateral) {
  float c = rho / rho0 - 1.0f;
  return unilateral ? max(c, 0.0f) : c;
}

/// A neighbour j's part of the density constraint's gradient, for the gather of lambda_i:
/// xyz: (m_j / rho_0) grad W_ij, summed into grad_i C_i; w: w_j |grad_j C_i|^2 =
/// w_j (m_j / rho_0)^2 |grad W_ij|^2, summed into the denominator (w_j = 0 for a solid particle:
/// its body takes the reaction instead).
MOTES_FN vec4 fluid_gradient_term(vec3 rij, float mj, float wj, float rho0, float h) {
  vec3 g = fluid_spiky_gradient(rij, h) * (mj / rho0);
  return vec4(g, wj * dot(g, g));
}

/// lambda_i = -C_i / (w_i |grad_i C_i|^2 + sum_j w_j |grad_j C_i|^2 + alpha~), grad_i C_i and the
/// sum gathered with fluid_gradient_term (gathered.xyz, gathered.w); alpha~ > 0 (the constraint
/// force mixing term, Macklin 2013's epsilon) keeps a lone particle from dividing by zero.
MOTES_FN float fluid_lambda(float c, vec4 gathered, float wi, float alpha) {
  vec3 g = xyz(gathered);
  return -c / (wi * dot(g, g) + gathered.w + alpha);
}

/// Macklin 2013's artificial pressure -k (W(r) / W(dq))^n, in lambda's units (kg m^2: times
/// m_i h^2, so that k is dimensionless at every h); n a whole number (products, not pow).
MOTES_FN float fluid_s_corr(float r2, float mi, MOTES_IN(FluidMaterial) f) {
  float h = f.density_h.y;
  float w = fluid_poly6(r2, h) / fluid_poly6(f.s_corr.z * f.s_corr.z, h);
  float p = 1.0f;
  uint n = uint(f.s_corr.y);
  for (uint k = 0u; k < n; ++k) {
    p *= w;
  }
  return -f.s_corr.x * mi * (h * h) * p;
}

/// A neighbour j's part of particle i's correction dx_i =
/// (1 / rho_0) sum_j (lambda_i m_j / m_i + lambda_j + s_corr_ij) grad W_ij; a solid j has
/// lambda_j = 0, s_corr_ij = 0 and m_j = psi_j. With equal masses, Macklin 2013's eq. (12).
MOTES_FN vec3 fluid_shift_term(float lambda_i, float lambda_j, float mi, float mj, float s_corr,
                               vec3 grad_ij, float rho0) {
  return grad_ij * ((lambda_i * (mj / mi) + lambda_j + s_corr) / rho0);
}

/// What a rigid particle b takes of its pair with fluid particle i: minus the momentum i gains
/// from the pair's shift term (computed with i's arithmetic: fluid_shift_term of i), as an
/// impulse over the substep h_s.
MOTES_FN vec3 fluid_rigid_reaction(vec3 shift_term_i, float mi, float hs) {
  return shift_term_i * (-mi / hs);
}

/// The pressure of the substep's summed lambdas Lambda_i (docs/fluids.md, "Pressure"): the
/// constraint's force on i, (1 / (rho_0 h_s^2)) sum_j (Lambda_i + Lambda_j) m_j grad W_ij, is SPH's
/// symmetric pressure force -m_i sum_j m_j (p_i + p_j) / rho_0^2 grad W_ij with the rest volume
/// m / rho_0 that the constraint's gradient uses (not m / rho_i: reading it with rho_i^2 raised a
/// tank's pressure slope by 4 times its mean compression), so p_i = -Lambda_i rho_0 / (m_i h_s^2).
/// On particles the spiky gradient's moment (fluid_gradient_moment_term) is below 1, and this p
/// reads rho g depth / M: a hydrostatic check multiplies it by the measured moment.
MOTES_FN float fluid_pressure(float lambda_sum, float rho0, float mi, float hs) {
  return -lambda_sum * rho0 / (mi * (hs * hs));
}

/// A neighbour j's part of the diagonal of the kernel gradient's first moment,
/// M_i = sum_j (m_j / rho_0) (x_j - x_i) (x) grad W_ij: the identity in the continuum (by parts,
/// -int r (x) grad W dV = I), 0.9563 I on a cubic lattice of spacing h / 2 (FluidMath.
/// GradientMomentOnTheLattice). SPH's gradient of a linear field reads M times its slope, so the
/// lambdas' pressure of a column at rest reads rho g / M_yy.
MOTES_FN vec3 fluid_gradient_moment_term(vec3 rij, float mj, float rho0, float h) {
  vec3 g = fluid_spiky_gradient(rij, h);
  return vec3(-rij.x * g.x, -rij.y * g.y, -rij.z * g.z) * (mj / rho0);
}

/// XSPH viscosity: a neighbour's part of sum_j (2 m_j / (rho_i + rho_j)) (v_j - v_i) W_ij, which
/// the particle adds times c (dimensionless) to its velocity. The pair's weight is symmetric (the
/// mean density, not rho_j: Macklin 2013's form has none), so the pass keeps the liquid's momentum
/// (with rho_j alone a splash gained 0.3% of its momentum in 0.2 s, the surface's particles being
/// light).
MOTES_FN vec3 fluid_xsph_term(vec3 vi, vec3 vj, float mj, float rhoi, float rhoj, float r2,
                              float h) {
  return (vj - vi) * ((2.0f * mj / (rhoi + rhoj)) * fluid_poly6(r2, h));
}

/// Vorticity: a neighbour's part of omega_i = sum_j (m_j / rho_j) (v_j - v_i) x grad_j W_ij (the
/// SPH curl; grad_j W_ij = -grad W_ij).
MOTES_FN vec3 fluid_vorticity_term(vec3 vi, vec3 vj, float mj, float rhoj, vec3 grad_ij) {
  return cross(vj - vi, -grad_ij) * (mj / rhoj);
}

/// A neighbour's part of eta_i, the gradient of |omega| at i:
/// (m_j / rho_j) (|omega_j| - |omega_i|) grad W_ij.
MOTES_FN vec3 fluid_eta_term(float wi, float wj, float mj, float rhoj, vec3 grad_ij) {
  return grad_ij * ((mj / rhoj) * (wj - wi));
}

/// Vorticity confinement's change of velocity over the substep h_s: h_s eps (N x omega),
/// N = eta / |eta| (none where eta vanishes).
MOTES_FN vec3 fluid_confinement(vec3 eta, vec3 omega, float eps, float hs) {
  float len2 = dot(eta, eta);
  if (len2 == 0.0f) {
    return vec3(0.0f);
  }
  return cross(eta / sqrt(len2), omega) * (eps * hs);
}

/// Akinci et al. 2013's cohesion spline C(r): 32 / (pi h^9) times (h - r)^3 r^3 for h/2 < r <= h,
/// 2 (h - r)^3 r^3 - h^6 / 64 for 0 < r <= h/2, 0 elsewhere.
MOTES_FN float fluid_cohesion_kernel(float r, float h) {
  if (r <= 0.0f || r > h) {
    return 0.0f;
  }
  float q = r / h;
  float a = (1.0f - q) * q;
  float a3 = a * a * a;
  float s = q > 0.5f ? a3 : 2.0f * a3 - 1.0f / 64.0f;
  return (32.0f / MOTES_FLUID_PI) * s / (h * h * h);
}

/// Akinci et al. 2013's adhesion spline A(r): 0.007 / h^3.25 (-4 r^2 / h + 6 r - 2 h)^(1/4) for
/// h/2 < r <= h, else 0 (the fourth root as two square roots).
MOTES_FN float fluid_adhesion_kernel(float r, float h) {
  if (r <= 0.5f * h || r > h) {
    return 0.0f;
  }
  float q = r / h;
  float b = max(-4.0f * q * q + 6.0f * q - 2.0f, 0.0f);
  return 0.007f * sqrt(sqrt(b)) / (h * h * h);
}

/// A neighbour's part of Akinci's surface normal n_i = h sum_j (m_j / rho_j) grad W_ij.
MOTES_FN vec3 fluid_normal_term(float mj, float rhoj, vec3 grad_ij, float h) {
  return grad_ij * (h * (mj / rhoj));
}

/// Cohesion and curvature between fluid particles i and j as i's change of velocity over h_s:
/// -h_s gamma K_ij (m_j C(r) r_ij / r + (n_i - n_j)), K_ij = 2 rho_0 / (rho_i + rho_j).
MOTES_FN vec3 fluid_cohesion_term(vec3 rij, float mj, float rhoi, float rhoj, vec3 ni, vec3 nj,
                                  float rho0, float gamma, float h, float hs) {
  float r2 = dot(rij, rij);
  vec3 pull = vec3(0.0f);
  if (r2 > 0.0f) {
    float r = sqrt(r2);
    pull = rij * (mj * fluid_cohesion_kernel(r, h) / r);
  }
  float k = 2.0f * rho0 / (rhoi + rhoj);
  return (pull + (ni - nj)) * (-hs * gamma * k);
}

/// Adhesion of fluid particle i to solid particle b (psi_b its fluid-equivalent mass) as i's
/// change of velocity over h_s: -h_s beta psi_b A(r) r_ib / r.
MOTES_FN vec3 fluid_adhesion_term(vec3 rib, float psib, float beta, float h, float hs) {
  float r2 = dot(rib, rib);
  if (r2 == 0.0f) {
    return vec3(0.0f);
  }
  float r = sqrt(r2);
  return rib * (-hs * beta * psib * fluid_adhesion_kernel(r, h) / r);
}

/// Whether particle `index` is a fluid particle: in StepParams' range [fluid_first,
/// fluid_first + fluid_count).
MOTES_FN bool fluid_particle(uint index, uint fluid_first, uint fluid_count) {
  return index - fluid_first < fluid_count;
}

/// The mass a neighbour j counts with in fluid particle i's sums (fluid_density, fluid_update):
/// a fluid j its own material's mass (m_fluid_j), a solid j of radius r_j the fluid mass its
/// lattice cell would hold, psi_j = s rho_0 (2 r_j)^3 with i's material's s and rho_0 (Macklin
/// 2014, section 7.1).
MOTES_FN float fluid_neighbour_mass(bool j_fluid, float m_fluid_j, float rj,
                                    MOTES_IN(FluidMaterial) fi) {
  float d = 2.0f * rj;
  return j_fluid ? m_fluid_j : fi.s_corr.w * fi.density_h.x * (d * d * d);
}

/// A plane's part of fluid particle i's density gather at the distance z = dot(n, x_i) - offset of
/// its centre: xyz, its part of grad_i C_i (the share's slope times n); w, its part of rho_i
/// (rho_0 times poly6's share beyond the plane, as fluid filling the solid side would give).
MOTES_FN vec4 fluid_plane_density(vec4 normal_offset, vec3 xi, MOTES_IN(FluidMaterial) fi) {
  float z = dot(xyz(normal_offset), xi) - normal_offset.w;
  float h = fi.density_h.y;
  return vec4(xyz(normal_offset) * fluid_plane_share_slope(z, h),
              fi.density_h.x * fluid_plane_share(z, h));
}

/// What fluid_update writes to a solid particle b's ParticleForce from its reaction R (a momentum:
/// the sum of fluid_solid_reaction over its fluid neighbours): a rigid body's particle R itself
/// (w 0: its body takes it, particles_update with MOTES_FLAG_ABSORB | MOTES_FLAG_PARTICLE_SHIFT);
/// a free particle (a free sphere, a soft body's, a cloth's or a rope's, inverse mass w_b) the
/// shift R w_b h_s with w 1, which particles_integrate's shift turns into the velocity change
/// R w_b: either way the pair keeps its momentum.
MOTES_FN vec4 fluid_solid_force(vec3 reaction, bool rigid, float wb, float hs) {
  if (rigid) {
    return vec4(reaction, 0.0f);
  }
  return vec4(reaction * (wb * hs), 1.0f);
}

/// A solid particle b's reaction to its pair with fluid particle i (fluid_update): minus
/// the momentum i gains from the pair's term of its correction dx_i, computed as i computes it
/// (fluid_shift_term with b's lambda 0, no s_corr and b's mass psi_b of i's material,
/// fluid_neighbour_mass), over the substep h_s; summed over b's fluid neighbours, b takes it
/// (fluid_solid_force), so the pair keeps its momentum. Any solid particle that can move reacts:
/// a rigid body's, a free sphere, a soft body's, a cloth's or a rope's.
MOTES_FN vec3 fluid_solid_reaction(vec3 xi, float lambda_i, vec3 xb, float rb,
                                   MOTES_IN(FluidMaterial) fi, float hs) {
  float mi = fi.density_h.z;
  float psi = fluid_neighbour_mass(false, 0.0f, rb, fi);
  vec3 term = fluid_shift_term(lambda_i, 0.0f, mi, psi, 0.0f,
                               fluid_spiky_gradient(xi - xb, fi.density_h.y), fi.density_h.x);
  return fluid_rigid_reaction(term, mi, hs);
}

/// A solid particle b's reaction to fluid particle i's adhesion (fluid_velocity with
/// MOTES_FLAG_FLUID_ADHESION; a momentum): minus m_i times i's term, computed as i computes it
/// (fluid_adhesion_term with i's material, b's psi_b of it), so the pair keeps its momentum; summed
/// over b's fluid neighbours in list order, b takes it by fluid_adhesion_taken.
MOTES_FN vec3 fluid_adhesion_reaction(vec3 xi, vec3 xb, float rb, MOTES_IN(FluidMaterial) fi,
                                      float hs) {
  float psi = fluid_neighbour_mass(false, 0.0f, rb, fi);
  vec3 term = fluid_adhesion_term(xi - xb, psi, fi.velocity.w, fi.density_h.y, hs);
  return term * (-fi.density_h.z);
}

/// How a solid particle b that can move (inverse mass w_b != 0) takes its adhesion reaction R: a
/// rigid body's particle hands R to its body (ParticleForce (R, 0): particles_update with
/// MOTES_FLAG_ABSORB | MOTES_FLAG_PARTICLE_SHIFT, then impulses_apply's velocity change); a free
/// one (a free sphere, a soft body's, a cloth's, a rope's) changes its velocity v_b by R w_b.
/// Returns the free particle's new velocity (w kept); a rigid one's is its old.
MOTES_FN vec4 fluid_adhesion_taken(vec4 vb, vec3 reaction, bool rigid) {
  if (rigid) {
    return vb;
  }
  return vec4(xyz(vb) + reaction * vb.w, vb.w);
}

MOTES_SHARED_END

#ifdef __cplusplus
static_assert(sizeof(motes::shared::FluidMaterial) == 64, "FluidMaterial layout");
static_assert(offsetof(motes::shared::FluidMaterial, s_corr) == 16, "FluidMaterial layout");
static_assert(offsetof(motes::shared::FluidMaterial, velocity) == 32, "FluidMaterial layout");
#endif

#endif  // MOTES_SHARED_FLUID_H
