// impulses_apply: each dynamic body (one thread per body) sums its particles' impulses, counts and
// moments in particle order and applies them (shared/impulse.h: body_apply_impulse); with
// MOTES_FLAG_IMPULSE_COUNT it first keeps its velocities and contact count as the start of the
// impulse stage; with MOTES_FLAG_IMPULSE_PUSH it keeps the velocities it leaves in BodyVelPush and
// BodyAngMomPush. As backends/openmp/impulses_apply.cpp.
#include "cuda_device.h"
#include "shared/impulse.h"
#include "shared/neighbours.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

struct ApplyBuffers {
  const uint* __restrict__ first;
  vec4* __restrict__ com;   // BodyPos (moved by the projection of position contacts)
  vec4* __restrict__ quat;  // BodyQuat
  const vec4* __restrict__ inv_inertia;
  const vec4* __restrict__ impulse;
  const vec4* __restrict__ moment;
  vec4* __restrict__ vel;
  vec4* __restrict__ angmom;
  vec4* __restrict__ angvel;
  vec4* __restrict__ vel0;
  vec4* __restrict__ angvel0;
  vec4* __restrict__ vel_push;     // BodyVelPush (written with MOTES_FLAG_IMPULSE_PUSH)
  vec4* __restrict__ angmom_push;  // BodyAngMomPush
  uint* __restrict__ stamp;        // ImpulseStamp (written by the counting pass)
  const uint* __restrict__ state;  // NeighbourState
};

__global__ void impulses_apply_kernel(shared::StepParams p, ApplyBuffers d) {
  const std::uint64_t t = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (t >= p.body_count) return;
  const auto b = static_cast<uint>(t);
  vec4 com = d.com[b];
  vec4 sum(0.0f);
  vec3 m(0.0f);
  if (com.w != 0.0f) {
    const uint end = d.first[b + 1];
    for (uint i = d.first[b]; i < end; ++i) {
      sum = sum + d.impulse[i];
      m += shared::xyz(d.moment[i]);
    }
  }
  if ((p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u) {
    d.vel0[b] = shared::impulse_start_velocity(d.vel[b], d.vel0[b], sum.w, p.flags);
    d.angvel0[b] = shared::impulse_start_angular_velocity(d.angvel[b], d.angvel0[b], p.flags);
    // The counting pass has read every slot: the body's particles' slots are now this build's.
    if (com.w != 0.0f) {
      const uint builds = d.state[MOTES_NEIGHBOUR_BUILDS];
      const uint end = d.first[b + 1];
      for (uint i = d.first[b]; i < end; ++i) d.stamp[i] = builds;
    }
  }
  vec4 vel = d.vel[b];
  vec4 angmom = d.angmom[b];
  vec4 angvel;
  vec4 quat = d.quat[b];
  shared::body_apply_contacts(com, quat, d.inv_inertia[b], vel, angmom, angvel, shared::xyz(sum), m,
                              p.gravity_dt, p.flags);
  d.com[b] = com;
  d.quat[b] = quat;
  d.vel[b] = vel;
  d.angmom[b] = angmom;
  d.angvel[b] = angvel;
  if ((p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u) {
    d.vel_push[b] = vel;
    d.angmom_push[b] = angmom;
  }
}

}  // namespace

void CudaDevice::launch_impulses_apply(const shared::StepParams& p) {
  if (p.body_count == 0) return;
  const ApplyBuffers d{buf<uint>(Buffer::BodyFirst),       buf<vec4>(Buffer::BodyPos),
                       buf<vec4>(Buffer::BodyQuat),        buf<vec4>(Buffer::BodyInvInertia),
                       buf<vec4>(Buffer::ParticleForce),   buf<vec4>(Buffer::ParticleMoment),
                       buf<vec4>(Buffer::BodyVel),         buf<vec4>(Buffer::BodyAngMom),
                       buf<vec4>(Buffer::BodyAngVel),      buf<vec4>(Buffer::BodyVelStart),
                       buf<vec4>(Buffer::BodyAngVelStart), buf<vec4>(Buffer::BodyVelPush),
                       buf<vec4>(Buffer::BodyAngMomPush),  buf<uint>(Buffer::ImpulseStamp),
                       buf<uint>(Buffer::NeighbourState)};
  impulses_apply_kernel<<<blocks_for(p.body_count), kBlock, 0, stream_>>>(p, d);
}

}  // namespace motes::cuda
