// bodies_reduce: force and torque of each body (one thread per body), summed over its particles in
// particle order, as backends/openmp/bodies_reduce.cpp.
#include "body_passes.cuh"
#include "cuda_device.h"

namespace motes::cuda {

namespace {

__global__ void bodies_reduce_kernel(shared::uint bodies, BodyBuffers d) {
  const std::uint64_t b = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (b < bodies) body_reduce(d, static_cast<shared::uint>(b));
}

}  // namespace

void CudaDevice::launch_bodies_reduce(const shared::StepParams& p) {
  if (p.body_count == 0) return;
  bodies_reduce_kernel<<<blocks_for(p.body_count), kBlock, 0, stream_>>>(p.body_count,
                                                                         body_buffers());
}

}  // namespace motes::cuda
