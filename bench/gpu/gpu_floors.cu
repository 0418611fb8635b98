// The GPU floors the Vulkan and CUDA benchmarks are compared with, measured on the same GPU in
// the same run (docs/benchmarks.md): a device-to-device copy (the bandwidth ceiling) and CUB's
// radix sort of N (key, value) pairs on only the key bits the grid uses (log2 of the 4N-bucket
// table), the sort floor for grid_build. Median of 20 timed runs after 3 warm-ups (CUDA events).
// Usage: motes_gpu_floors N...   Prints one JSON object per N.
#include <cuda_runtime.h>
#include <cub/device/device_radix_sort.cuh>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

#define CHECK(x)                                                                              \
  do {                                                                                        \
    cudaError_t e = (x);                                                                      \
    if (e != cudaSuccess) {                                                                   \
      std::fprintf(stderr, "%s:%d: %s: %s\n", __FILE__, __LINE__, #x, cudaGetErrorString(e)); \
      std::exit(1);                                                                           \
    }                                                                                         \
  } while (0)

__global__ void fill_keys(unsigned* keys, unsigned* values, unsigned n, unsigned mask) {
  unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  unsigned h = i * 0x9E3779B1u;  // scattered buckets, like hashed cells
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  keys[i] = h & mask;
  values[i] = i;
}

template <typename F>
double median_ms(F run) {
  cudaEvent_t a, b;
  CHECK(cudaEventCreate(&a));
  CHECK(cudaEventCreate(&b));
  for (int i = 0; i < 3; ++i) run();
  std::vector<float> t;
  for (int i = 0; i < 20; ++i) {
    CHECK(cudaEventRecord(a));
    run();
    CHECK(cudaEventRecord(b));
    CHECK(cudaEventSynchronize(b));
    float ms = 0;
    CHECK(cudaEventElapsedTime(&ms, a, b));
    t.push_back(ms);
  }
  std::sort(t.begin(), t.end());
  return 0.5 * (t[9] + t[10]);
}

int main(int argc, char** argv) {
  cudaDeviceProp prop{};
  CHECK(cudaGetDeviceProperties(&prop, 0));
  for (int a = 1; a < argc; ++a) {
    const unsigned n = static_cast<unsigned>(std::strtoul(argv[a], nullptr, 10));
    unsigned table = 64;
    while (table < 4ull * n) table <<= 1;
    int bits = 0;
    while ((1u << bits) < table) ++bits;
    unsigned *keys, *values, *keys_out, *values_out;
    CHECK(cudaMalloc(&keys, n * 4ull));
    CHECK(cudaMalloc(&values, n * 4ull));
    CHECK(cudaMalloc(&keys_out, n * 4ull));
    CHECK(cudaMalloc(&values_out, n * 4ull));
    fill_keys<<<(n + 255) / 256, 256>>>(keys, values, n, table - 1);
    CHECK(cudaGetLastError());
    size_t temp_bytes = 0;
    CHECK(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, keys, keys_out, values, values_out,
                                          n, 0, bits));
    void* temp;
    CHECK(cudaMalloc(&temp, temp_bytes));
    const double sort_ms = median_ms([&] {
      CHECK(cub::DeviceRadixSort::SortPairs(temp, temp_bytes, keys, keys_out, values, values_out, n,
                                            0, bits));
    });
    // Copy 16 bytes per particle (one vec4 array): read + write counted.
    const size_t copy_bytes = 16ull * n;
    void *src, *dst;
    CHECK(cudaMalloc(&src, copy_bytes));
    CHECK(cudaMalloc(&dst, copy_bytes));
    CHECK(cudaMemset(src, 1, copy_bytes));
    const double copy_ms =
        median_ms([&] { CHECK(cudaMemcpyAsync(dst, src, copy_bytes, cudaMemcpyDeviceToDevice)); });
    std::printf(
        "{\"gpu\": \"%s\", \"n\": %u, \"key_bits\": %d, \"cub_sort_pairs_ms\": %.5f, "
        "\"cub_pairs_per_s\": %.4g, \"copy_bytes\": %zu, \"copy_ms\": %.5f, "
        "\"copy_gb_per_s\": %.1f}\n",
        prop.name, n, bits, sort_ms, n / (sort_ms * 1e-3), copy_bytes, copy_ms,
        2.0 * copy_bytes / (copy_ms * 1e-3) / 1e9);
    CHECK(cudaFree(keys));
    CHECK(cudaFree(values));
    CHECK(cudaFree(keys_out));
    CHECK(cudaFree(values_out));
    CHECK(cudaFree(temp));
    CHECK(cudaFree(src));
    CHECK(cudaFree(dst));
  }
  return 0;
}
