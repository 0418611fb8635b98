// contacts_compute: every particle gathers the forces of the particles overlapping it, visiting
// the 27 neighbouring cells in the canonical order (docs/architecture.md), then the planes.
// No atomics: each particle writes only its own force, so sums are in a fixed order.
#include <chrono>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "openmp_device.h"
#include "shared/contact_force.h"
#include "shared/grid_hash.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

void OpenMPDevice::contacts_compute(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto n = static_cast<std::int64_t>(p.particle_count);
  const uint mask = p.table_mask;
  const uint materials = p.material_count;
  const uint* order = buf<uint>(Buffer::GridOrder);
  const uint* cell_start = buf<uint>(Buffer::GridCellStart);
  const vec4* spos = buf<vec4>(Buffer::SortedPos);
  const vec4* svel = buf<vec4>(Buffer::SortedVel);
  const uint* sbody = buf<uint>(Buffer::SortedBody);
  const uint* smat = buf<uint>(Buffer::SortedMaterial);
  const auto* laws = buf<shared::ContactLaw>(Buffer::ContactLaws);
  const auto* planes = buf<shared::PlaneData>(Buffer::Planes);
  vec4* force = buf<vec4>(Buffer::ParticleForce);

#pragma omp parallel for num_threads(threads_) schedule(static) if (parallel(n))
  for (std::int64_t s = 0; s < n; ++s) {
    const vec4 pi = spos[s];
    const vec4 vi = svel[s];
    if (vi.w == 0.0f) {  // static particle: its force is never used
      force[order[s]] = vec4(0.0f);
      continue;
    }
    const vec3 xi = shared::xyz(pi);
    const vec3 ui = shared::xyz(vi);
    const uint body_i = sbody[s];
    const shared::ContactLaw* law_row = laws + std::size_t{smat[s]} * materials;
    const int cx = shared::grid_cell_coord(pi.x, p.inv_cell_size);
    const int cy = shared::grid_cell_coord(pi.y, p.inv_cell_size);
    const int cz = shared::grid_cell_coord(pi.z, p.inv_cell_size);

    // The sorted ranges to visit, in the canonical order: up to 9 rows of 3 buckets.
    uint range_lo[27];
    uint range_hi[27];
    int ranges = 0;
    alignas(16) uint centres[12] = {};
    int row = 0;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy, ++row) {
        const uint c = shared::grid_bucket(cx, cy + dy, cz + dz, mask);
        // Hashed rows can share buckets; every bucket is visited once, by its first row.
        // Two rows' bucket triples overlap when their centres are within 2 of each other.
#if defined(__SSE2__)
        const __m128i shifted = _mm_set1_epi32(static_cast<int>(c + 2u));
        const __m128i maskv = _mm_set1_epi32(static_cast<int>(mask));
        const __m128i five = _mm_set1_epi32(5);
        const __m128i lo4 = _mm_and_si128(
            _mm_sub_epi32(shifted, _mm_load_si128(reinterpret_cast<const __m128i*>(centres))),
            maskv);
        const __m128i hi4 = _mm_and_si128(
            _mm_sub_epi32(shifted, _mm_load_si128(reinterpret_cast<const __m128i*>(centres + 4))),
            maskv);
        const int near = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmplt_epi32(lo4, five))) |
                         (_mm_movemask_ps(_mm_castsi128_ps(_mm_cmplt_epi32(hi4, five))) << 4);
        const bool clash = (near & ((1 << row) - 1)) != 0;
#else
        bool clash = false;
        for (int r = 0; r < row; ++r) clash = clash || ((c - centres[r] + 2u) & mask) <= 4u;
#endif
        centres[row] = c;
        if (!clash && c >= 1u && c < mask) {  // buckets c-1, c, c+1 as one range
          range_lo[ranges] = cell_start[c - 1u];
          range_hi[ranges++] = cell_start[c + 2u];
          continue;
        }
        for (uint k = 0; k < 3; ++k) {
          const uint b = (c + k - 1u) & mask;
          bool seen = false;
          for (int r = 0; r < row; ++r) seen = seen || shared::grid_row_covers(centres[r], b, mask);
          if (seen) continue;
          range_lo[ranges] = cell_start[b];
          range_hi[ranges++] = cell_start[b + 1u];
        }
      }
    }

    vec3 f(0.0f);
    // The force of candidate t on particle s (zero unless they overlap), added in order.
    auto add_contact = [&](uint t) {
      if (sbody[t] == body_i) return;  // also t == s
      const vec4 pj = spos[t];
      const vec4 vj = svel[t];
      f += shared::particle_contact_force(xi, ui, pi.w, vi.w, shared::xyz(pj), shared::xyz(vj),
                                          pj.w, vj.w, law_row[smat[t]], p.flags);
    };
    for (int r = 0; r < ranges; ++r) {
      const uint hi = range_hi[r];
#if defined(__SSE2__)
      // Four candidates at a time: the same float operations, in the same order, as the overlap
      // test inside particle_contact_force, so the filter never disagrees with it. Loads past
      // `hi` stay inside the buffer's padding and are masked off.
      const __m128 px = _mm_set1_ps(pi.x);
      const __m128 py = _mm_set1_ps(pi.y);
      const __m128 pz = _mm_set1_ps(pi.z);
      const __m128 pr = _mm_set1_ps(pi.w);
      for (uint t = range_lo[r]; t < hi; t += 4) {
        __m128 a = _mm_load_ps(&spos[t].x);
        __m128 b = _mm_load_ps(&spos[t + 1].x);
        __m128 c = _mm_load_ps(&spos[t + 2].x);
        __m128 d = _mm_load_ps(&spos[t + 3].x);
        _MM_TRANSPOSE4_PS(a, b, c, d);  // a: x, b: y, c: z, d: radius of the four candidates
        const __m128 dx = _mm_sub_ps(a, px);
        const __m128 dy = _mm_sub_ps(b, py);
        const __m128 dz = _mm_sub_ps(c, pz);
        const __m128 d2 =
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
        const __m128 rsum = _mm_add_ps(pr, d);
        unsigned hits =
            static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(d2, _mm_mul_ps(rsum, rsum))));
        if (hi - t < 4) hits &= (1u << (hi - t)) - 1u;
        for (; hits != 0; hits &= hits - 1u)
          add_contact(t + static_cast<uint>(__builtin_ctz(hits)));
      }
#else
      for (uint t = range_lo[r]; t < hi; ++t) {
        const vec4 pj = spos[t];
        const float dx = pj.x - pi.x;
        const float dy = pj.y - pi.y;
        const float dz = pj.z - pi.z;
        const float rsum = pi.w + pj.w;
        if (dx * dx + dy * dy + dz * dz < rsum * rsum) add_contact(t);
      }
#endif
    }
    for (uint k = 0; k < p.plane_count; ++k) {
      const shared::PlaneData pl = planes[k];
      f += shared::plane_contact_force(xi, ui, pi.w, vi.w, pl.normal_offset, law_row[pl.material],
                                       p.flags);
    }
    force[order[s]] = vec4(f, 0.0f);
  }
  record(Kernel::ContactsCompute, start);
}

}  // namespace motes::openmp
