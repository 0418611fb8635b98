// bodies_integrate: one semi-implicit Euler step of every body (shared/body_math.h); with
// MOTES_FLAG_IMPULSE_PUSH the pose moves with BodyVelPush and BodyAngMomPush (body_push_pose);
// with MOTES_FLAG_IMPULSE_SPLIT with the body's velocities, which then take the push copies
// (body_split_pose); both move the centre as the pair BodyPos + BodyPosLow.
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/body_math.h"

namespace motes::openmp {

using shared::vec4;

void OpenMPDevice::bodies_integrate(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  // The poses move (not in the velocity half): particles_update places the particles again.
  if ((p.flags & MOTES_FLAG_BODY_VELOCITY) == 0u) impulse_points_ready_ = false;
  const auto bodies = static_cast<std::int64_t>(p.body_count);
  vec4* pos = buf<vec4>(Buffer::BodyPos);
  vec4* quat = buf<vec4>(Buffer::BodyQuat);
  vec4* vel = buf<vec4>(Buffer::BodyVel);
  vec4* angmom = buf<vec4>(Buffer::BodyAngMom);
  vec4* angvel = buf<vec4>(Buffer::BodyAngVel);
  const vec4* inv_inertia = buf<vec4>(Buffer::BodyInvInertia);
  const vec4* force = buf<vec4>(Buffer::BodyForce);
  const vec4* torque = buf<vec4>(Buffer::BodyTorque);

  if ((p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u) {
    const vec4* vel_push = buf<vec4>(Buffer::BodyVelPush);
    const vec4* angmom_push = buf<vec4>(Buffer::BodyAngMomPush);
    vec4* low = buf<vec4>(Buffer::BodyPosLow);
    for_items(bodies, parallel(bodies), [&](std::int64_t b) {
      shared::body_split_pose(pos[b], low[b], quat[b], vel[b], angmom[b], angvel[b], inv_inertia[b],
                              vel_push[b], angmom_push[b], p.gravity_dt);
    });
    record(Kernel::BodiesIntegrate, start);
    return;
  }
  if ((p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u) {
    const vec4* vel_push = buf<vec4>(Buffer::BodyVelPush);
    const vec4* angmom_push = buf<vec4>(Buffer::BodyAngMomPush);
    vec4* low = buf<vec4>(Buffer::BodyPosLow);
    for_items(bodies, parallel(bodies), [&](std::int64_t b) {
      shared::body_push_pose(pos[b], low[b], quat[b], angvel[b], inv_inertia[b], angmom[b],
                             vel_push[b], angmom_push[b], p.gravity_dt);
    });
    record(Kernel::BodiesIntegrate, start);
    return;
  }
  for_items(bodies, parallel(bodies), [&](std::int64_t b) {
    shared::body_integrate(pos[b], quat[b], vel[b], angmom[b], angvel[b], inv_inertia[b], force[b],
                           torque[b], p.gravity_dt, p.flags);
  });
  record(Kernel::BodiesIntegrate, start);
}

}  // namespace motes::openmp
