// grid_build: bucket of every particle, stable sort by (bucket, particle id), bucket starts and the
// particle data in grid order. CUB's LSD radix sort on only the key bits the table needs is stable,
// so sorting (bucket, id) pairs that start in id order gives the canonical order of every backend.
// Three launches: hash, CUB's sort, then one pass that writes the sorted copies and the bucket
// starts together.
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

/// Sorted slot s: copies particle order[s] to slot s. Bucket starts: a block of slots
/// [s0, s1) owns the buckets after slot s0-1's bucket up to slot s1-1's (the last block up to the
/// end of the table), a contiguous range that its threads write side by side, each start found by
/// binary search among the block's keys (first slot whose bucket is >= b). So each of the T + 1
/// starts is written exactly once, and with coalesced stores however sparse the table.
__global__ void grid_reorder_kernel(shared::StepParams p, const uint* __restrict__ keys,
                                    const uint* __restrict__ order, const vec4* __restrict__ pos,
                                    const uint* __restrict__ body, uint* __restrict__ cell_start,
                                    vec4* __restrict__ spos, uint* __restrict__ sbody) {
  __shared__ uint block_keys[CudaDevice::kBlock];
  const uint n = p.particle_count;
  const std::uint64_t s0 = std::uint64_t{blockIdx.x} * blockDim.x;
  const std::uint64_t s = s0 + threadIdx.x;
  if (s < n) {
    const uint i = order[s];
    spos[s] = pos[i];
    sbody[s] = body[i];
    block_keys[threadIdx.x] = keys[s];
  }
  __syncthreads();
  const auto count = static_cast<uint>(min(std::uint64_t{blockDim.x}, n - s0));
  const std::uint64_t first = s0 == 0 ? 0 : std::uint64_t{keys[s0 - 1]} + 1;
  const bool last_block = s0 + count == n;
  const std::uint64_t end =
      last_block ? std::uint64_t{p.table_mask} + 2 : std::uint64_t{block_keys[count - 1]} + 1;
  for (std::uint64_t b = first + threadIdx.x; b < end; b += blockDim.x) {
    uint lo = 0, hi = count;  // first k in [0, count) with block_keys[k] >= b, else count
    while (lo < hi) {
      const uint mid = (lo + hi) / 2;
      if (block_keys[mid] < b) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    cell_start[b] = static_cast<uint>(s0 + lo);
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
      p, sorted_keys_, order, buf<vec4>(Buffer::ParticlePos), buf<uint>(Buffer::ParticleBody),
      cell_start, buf<vec4>(Buffer::SortedPos), buf<uint>(Buffer::SortedBody));
}

}  // namespace motes::cuda
