// grid_build: bucket of every particle, stable sort by (bucket, particle id), bucket starts and the
// particle data in grid order. CUB's LSD radix sort on only the key bits the table needs is stable,
// so sorting (bucket, id) pairs that start in id order gives the canonical order of every backend.
// Three launches: hash, CUB's sort, then one pass that writes the bucket starts and the sorted
// copies together.
#include <cub/device/device_radix_sort.cuh>

#include <bit>

#include "cuda_device.h"
#include "shared/grid_hash.h"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

__global__ void grid_hash_kernel(shared::StepParams p, const vec4* __restrict__ pos,
                                 uint* __restrict__ bucket) {
  const std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (i >= p.particle_count) return;
  const vec4 x = pos[i];
  bucket[i] = shared::grid_bucket(shared::grid_cell_coord(x.x, p.inv_cell_size),
                                  shared::grid_cell_coord(x.y, p.inv_cell_size),
                                  shared::grid_cell_coord(x.z, p.inv_cell_size), p.table_mask);
}

/// Sorted slot s: copies particle order[s] to slot s, and writes the start of every bucket from
/// the one after the previous slot's bucket up to its own (the last slot also closes the table),
/// so each of the T + 1 starts is written exactly once.
__global__ void grid_reorder_kernel(shared::StepParams p, const uint* __restrict__ keys,
                                    const uint* __restrict__ order, const vec4* __restrict__ pos,
                                    const vec4* __restrict__ vel, const uint* __restrict__ body,
                                    const uint* __restrict__ material,
                                    uint* __restrict__ cell_start, vec4* __restrict__ spos,
                                    vec4* __restrict__ svel, uint* __restrict__ sbody,
                                    uint* __restrict__ smat) {
  const std::uint64_t s = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  const uint n = p.particle_count;
  if (s >= n) return;
  const uint i = order[s];
  spos[s] = pos[i];
  svel[s] = vel[i];
  sbody[s] = body[i];
  smat[s] = material[i];
  const uint key = keys[s];
  const std::uint64_t lo = s == 0 ? 0 : std::uint64_t{keys[s - 1]} + 1;
  for (std::uint64_t b = lo; b <= key; ++b) cell_start[b] = static_cast<uint>(s);
  if (s + 1 == n) {
    const std::uint64_t table = std::uint64_t{p.table_mask} + 1;
    for (std::uint64_t b = std::uint64_t{key} + 1; b <= table; ++b) cell_start[b] = n;
  }
}

__global__ void ids_fill_kernel(uint n, uint* ids) {
  const std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (i < n) ids[i] = static_cast<uint>(i);
}

}  // namespace

Result<std::size_t> CudaDevice::sort_temp_size(std::uint32_t n, int key_bits) {
  std::size_t bytes = 0;
  const cudaError_t e = cub::DeviceRadixSort::SortPairs(
      nullptr, bytes, static_cast<const uint*>(nullptr), static_cast<uint*>(nullptr),
      static_cast<const uint*>(nullptr), static_cast<uint*>(nullptr), static_cast<int>(n), 0,
      key_bits);
  if (e != cudaSuccess) return Status::error(cudaGetErrorString(e));
  return bytes;
}

void CudaDevice::launch_ids_fill(std::uint32_t n) {
  if (n > 0) ids_fill_kernel<<<blocks_for(n), kBlock, 0, stream_>>>(n, ids_);
}

void CudaDevice::launch_grid_build(const shared::StepParams& p) {
  const uint n = p.particle_count;
  uint* cell_start = buf<uint>(Buffer::GridCellStart);
  if (n == 0) {
    cudaMemsetAsync(cell_start, 0, (std::size_t{p.table_mask} + 2) * sizeof(uint), stream_);
    return;
  }
  uint* bucket = buf<uint>(Buffer::GridBucket);
  uint* order = buf<uint>(Buffer::GridOrder);
  grid_hash_kernel<<<blocks_for(n), kBlock, 0, stream_>>>(p, buf<vec4>(Buffer::ParticlePos),
                                                          bucket);
  std::size_t temp_bytes = sort_temp_bytes_;
  const cudaError_t sorted = cub::DeviceRadixSort::SortPairs(
      sort_temp_, temp_bytes, bucket, sorted_keys_, ids_, order, static_cast<int>(n), 0,
      std::bit_width(p.table_mask), stream_);
  if (sorted != cudaSuccess) {
    check(sorted, "cub::DeviceRadixSort::SortPairs");
    return;
  }
  grid_reorder_kernel<<<blocks_for(n), kBlock, 0, stream_>>>(
      p, sorted_keys_, order, buf<vec4>(Buffer::ParticlePos), buf<vec4>(Buffer::ParticleVel),
      buf<uint>(Buffer::ParticleBody), buf<uint>(Buffer::ParticleMaterial), cell_start,
      buf<vec4>(Buffer::SortedPos), buf<vec4>(Buffer::SortedVel), buf<uint>(Buffer::SortedBody),
      buf<uint>(Buffer::SortedMaterial));
}

}  // namespace motes::cuda
