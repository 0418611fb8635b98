// grid_build: bucket of every particle, stable sort by (bucket, particle id), bucket starts and
// the particle data in grid order. The result is unique (a stable sort), so it is identical at
// every thread count and on every backend.
#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>
#include <numeric>

#include "openmp_device.h"
#include "shared/grid_hash.h"

#ifdef MOTES_HAVE_OPENMP
#include <omp.h>
#endif

namespace motes::openmp {

using shared::uint;
using shared::vec4;

namespace {

int thread_id() {
#ifdef MOTES_HAVE_OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

int thread_count() {
#ifdef MOTES_HAVE_OPENMP
  return omp_get_num_threads();
#else
  return 1;
#endif
}

}  // namespace

void OpenMPDevice::sort_by_bucket(std::uint32_t n, std::uint32_t key_bits) {
  const uint* bucket = buf<uint>(Buffer::GridBucket);
  uint* order = buf<uint>(Buffer::GridOrder);
  // Digits of at most 11 bits: 2 passes up to 2^22 buckets (4 M particles), 3 beyond.
  const std::uint32_t passes = std::max<std::uint32_t>(1, (key_bits + 10) / 11);
  const std::uint32_t digit_bits = (key_bits + passes - 1) / passes;
  const std::uint32_t radix = 1u << digit_bits;
  const std::uint32_t digit_mask = radix - 1;
  histograms_.assign(static_cast<std::size_t>(threads_) * radix, 0);

  // Ping-pong so that the last pass writes (sorted_keys_, order).
  uint* keys[2] = {keys_tmp_.data(), sorted_keys_.data()};
  uint* ids[2] = {ids_tmp_.data(), order};
  std::uint32_t out = (passes % 2 == 1) ? 1 : 0;

#pragma omp parallel num_threads(team_) if (parallel(n))
  {
    const auto t = static_cast<std::size_t>(thread_id());
    const auto nt = static_cast<std::size_t>(thread_count());
    const std::size_t lo = n * t / nt;
    const std::size_t hi = n * (t + 1) / nt;
    std::uint32_t* hist = histograms_.data() + t * radix;
    std::uint32_t dst = out;
    for (std::uint32_t pass = 0; pass < passes; ++pass) {
      const std::uint32_t shift = pass * digit_bits;
      const bool first = pass == 0;
      const uint* key_in = first ? bucket : keys[1 - dst];
      const uint* id_in = first ? nullptr : ids[1 - dst];
      std::fill(hist, hist + radix, 0u);
      for (std::size_t i = lo; i < hi; ++i) ++hist[(key_in[i] >> shift) & digit_mask];
#pragma omp barrier
#pragma omp single
      {
        // Exclusive scan, digit-major then thread: keeps the sort stable.
        std::uint32_t sum = 0;
        for (std::uint32_t d = 0; d < radix; ++d) {
          for (std::size_t u = 0; u < nt; ++u) {
            std::uint32_t& h = histograms_[u * radix + d];
            const std::uint32_t c = h;
            h = sum;
            sum += c;
          }
        }
      }
      uint* key_out = keys[dst];
      uint* id_out = ids[dst];
      for (std::size_t i = lo; i < hi; ++i) {
        const uint k = key_in[i];
        const std::uint32_t at = hist[(k >> shift) & digit_mask]++;
        key_out[at] = k;
        id_out[at] = first ? static_cast<uint>(i) : id_in[i];
      }
#pragma omp barrier
      dst = 1 - dst;
    }
  }
}

void OpenMPDevice::grid_build(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto n = static_cast<std::int64_t>(p.particle_count);
  const uint mask = p.table_mask;
  const std::int64_t table = std::int64_t{mask} + 1;
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  uint* bucket = buf<uint>(Buffer::GridBucket);

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n))
  for (std::int64_t i = 0; i < n; ++i) {
    const vec4 x = pos[i];
    bucket[i] = shared::grid_bucket(shared::grid_cell_coord(x.x, p.inv_cell_size),
                                    shared::grid_cell_coord(x.y, p.inv_cell_size),
                                    shared::grid_cell_coord(x.z, p.inv_cell_size), mask);
  }

  sort_by_bucket(p.particle_count, static_cast<std::uint32_t>(std::bit_width(mask)));

  // Bucket b holds sorted positions [start[b], start[b+1]); each b is written exactly once: by the
  // sorted position whose key is the first key >= b (or by n past the last key).
  uint* cell_start = buf<uint>(Buffer::GridCellStart);
  const uint* keys = sorted_keys_.data();
  if (n == 0) {
    std::fill(cell_start, cell_start + table + 1, 0u);
  } else {
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n))
    for (std::int64_t s = 0; s <= n; ++s) {
      const std::int64_t lo = s == 0 ? 0 : std::int64_t{keys[s - 1]} + 1;
      const std::int64_t hi = s == n ? table : std::int64_t{keys[s]};
      for (std::int64_t b = lo; b <= hi; ++b) cell_start[b] = static_cast<uint>(s);
    }
  }

  const uint* order = buf<uint>(Buffer::GridOrder);
  const uint* body = buf<uint>(Buffer::ParticleBody);
  vec4* spos = buf<vec4>(Buffer::SortedPos);
  uint* sbody = buf<uint>(Buffer::SortedBody);
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n))
  for (std::int64_t s = 0; s < n; ++s) {
    const uint i = order[s];
    spos[s] = pos[i];
    sbody[s] = body[i];
  }
  record(Kernel::GridBuild, start);
}

}  // namespace motes::openmp
