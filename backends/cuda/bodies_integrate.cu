// bodies_integrate: one semi-implicit Euler step of every body (shared/body_math.h).
#include "body_passes.cuh"
#include "cuda_device.h"

namespace motes::cuda {

namespace {

__global__ void bodies_integrate_kernel(shared::StepParams p, BodyBuffers d) {
  const std::uint64_t b = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (b < p.body_count) body_step(d, static_cast<shared::uint>(b), p.gravity_dt, p.flags);
}

}  // namespace

void CudaDevice::launch_bodies_integrate(const shared::StepParams& p) {
  if (p.body_count == 0) return;
  bodies_integrate_kernel<<<blocks_for(p.body_count), kBlock, 0, stream_>>>(p, body_buffers());
}

}  // namespace motes::cuda
