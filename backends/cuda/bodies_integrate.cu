// bodies_integrate: one semi-implicit Euler step of every body (shared/body_math.h); with
// MOTES_FLAG_IMPULSE_PUSH the pose moves with BodyVelPush and BodyAngMomPush (body_push_pose);
// with MOTES_FLAG_IMPULSE_SPLIT with the body's velocities, which then take the push copies
// (body_split_pose).
#include "body_passes.cuh"
#include "cuda_device.h"

namespace motes::cuda {

namespace {

__global__ void bodies_integrate_kernel(shared::StepParams p, BodyBuffers d) {
  const std::uint64_t b = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (b < p.body_count) body_step(d, static_cast<shared::uint>(b), p.gravity_dt, p.flags);
}

/// The impulse stage's pose: moved with the push copies (MOTES_FLAG_IMPULSE_PUSH), or with the
/// body's own velocities, which then take the push copies (MOTES_FLAG_IMPULSE_SPLIT); the centre
/// as the pair BodyPos + BodyPosLow.
__global__ void bodies_pose_kernel(shared::StepParams p, BodyBuffers d,
                                   const shared::vec4* __restrict__ vel_push,
                                   const shared::vec4* __restrict__ angmom_push,
                                   shared::vec4* __restrict__ pos_low) {
  const std::uint64_t t = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (t >= p.body_count) return;
  const auto b = static_cast<shared::uint>(t);
  const bool split = (p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u;
  shared::vec4 pos = d.body_pos[b];
  shared::vec4 low = pos_low[b];
  shared::vec4 quat = d.quat[b];
  shared::vec4 vel = d.body_vel[b];
  shared::vec4 angmom = d.angmom[b];
  shared::vec4 angvel;
  if (split) {
    shared::body_split_pose(pos, low, quat, vel, angmom, angvel, d.inv_inertia[b], vel_push[b],
                            angmom_push[b], p.gravity_dt);
    d.body_vel[b] = vel;
    d.angmom[b] = angmom;
  } else {
    shared::body_push_pose(pos, low, quat, angvel, d.inv_inertia[b], angmom, vel_push[b],
                           angmom_push[b], p.gravity_dt);
  }
  d.body_pos[b] = pos;
  pos_low[b] = low;
  d.quat[b] = quat;
  d.angvel[b] = angvel;
}

}  // namespace

void CudaDevice::launch_bodies_integrate(const shared::StepParams& p) {
  if (p.body_count == 0) return;
  if ((p.flags & (MOTES_FLAG_IMPULSE_PUSH | MOTES_FLAG_IMPULSE_SPLIT)) != 0u) {
    bodies_pose_kernel<<<blocks_for(p.body_count), kBlock, 0, stream_>>>(
        p, body_buffers(), buf<shared::vec4>(Buffer::BodyVelPush),
        buf<shared::vec4>(Buffer::BodyAngMomPush), buf<shared::vec4>(Buffer::BodyPosLow));
    return;
  }
  bodies_integrate_kernel<<<blocks_for(p.body_count), kBlock, 0, stream_>>>(p, body_buffers());
}

}  // namespace motes::cuda
