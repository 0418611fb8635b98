// What impulses_apply.comp and impulses_apply_wide.comp share: a chunk's sums in the contract's
// order (shared/impulse.h, MOTES_BODY_CHUNK), and what they do with a body once it is summed: the
// counting pass's start (and the Gram bound of position contacts, shared/contact_gram.h), the
// body's update, the pushed velocities. As backends/openmp/impulses_apply.cpp.
#ifndef MOTES_IMPULSES_APPLY_BODY_GLSL
#define MOTES_IMPULSES_APPLY_BODY_GLSL

/// One chunk's sums: particles [c, end) in order from zero.
void chunk_sums(uint c, uint end, out vec4 part, out vec3 part_m) {
  part = vec4(0.0f);
  part_m = vec3(0.0f);
  for (uint i = c; i < end; ++i) {
    part = part + particle_force[i];
    part_m += xyz(particle_moment[i]);
  }
}

/// One chunk's Gram matrix (shared/contact_gram.h), in the same order.
ContactGram chunk_gram(uint c, uint end, vec4 com) {
  ContactGram g = gram_zero();
  for (uint i = c; i < end; ++i) {
    gram_add(g, particle_force[i], particle_moment[i], xyz(particle_pos[i]) - xyz(com));
  }
  return g;
}

/// The counting pass has read every slot: the body's particles' slots are now this build's
/// (lane of lanes: the threads that share the body).
void stamp_body(uint b, vec4 com, uint lane, uint lanes) {
  if ((p.flags & MOTES_FLAG_IMPULSE_COUNT) == 0u || com.w == 0.0f) return;
  uint builds = neighbour_state[MOTES_NEIGHBOUR_BUILDS];
  uint end = body_first[b + 1u];
  for (uint i = body_first[b] + lane; i < end; i += lanes) impulse_stamp[i] = builds;
}

/// bound: the Gram bound, kept in the Gram counting pass (gram).
void finish_body(uint b, vec4 com, vec4 sum, vec3 m, bool gram, float bound) {
  if ((p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u) {
    body_vel_start[b] = impulse_start_velocity(body_vel[b], body_vel_start[b], sum.w, p.flags);
    body_angvel_start[b] =
        impulse_start_angular_velocity(body_angvel[b], body_angvel_start[b], p.flags);
    if (gram) body_angvel_start[b].w = bound;
  }
  vec4 vel = body_vel[b];
  vec4 angmom = body_angmom[b];
  vec4 angvel;
  vec4 quat = body_quat[b];
  body_apply_contacts(com, quat, body_inv_inertia[b], vel, angmom, angvel, xyz(sum), m,
                      p.gravity_dt, p.flags);
  body_pos[b] = com;
  body_quat[b] = quat;
  body_vel[b] = vel;
  body_angmom[b] = angmom;
  body_angvel[b] = angvel;
  if ((p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u) {
    body_vel_push[b] = vel;
    body_angmom_push[b] = angmom;
  }
}

#endif  // MOTES_IMPULSES_APPLY_BODY_GLSL
