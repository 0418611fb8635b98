// contacts_compute: every particle (one thread per particle id) gathers the forces of the
// particles overlapping it over the 27 neighbouring cells in the canonical order
// (docs/architecture.md), then the planes, and writes only its own force: no atomics, a fixed
// summation order. Same loop structure as backends/openmp/contacts_compute.cpp and
// shaders/contacts_compute.comp. Threads go in particle order, not grid order: scenes are built
// body by body, so neighbouring threads are neighbours in space and share the rows of cells they
// read, where grid order jumps between hashed rows; the force is written without a scatter.
#include "cuda_device.h"
#include "shared/contact_force.h"
#include "shared/grid_hash.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

struct ContactInputs {
  const vec4* __restrict__ spos;
  const vec4* __restrict__ svel;
  const uint* __restrict__ sbody;
  const uint* __restrict__ smat;
  const shared::ContactLaw* __restrict__ laws;
};

/// Adds the forces of sorted slots [lo, hi) on particle (pi, vi) of body_i.
__device__ void gather_range(const ContactInputs& in, uint lo, uint hi, vec4 pi, vec4 vi,
                             uint body_i, const shared::ContactLaw* law_row, uint flags, vec3& f) {
  const vec3 xi = shared::xyz(pi);
  const vec3 ui = shared::xyz(vi);
  for (uint t = lo; t < hi; ++t) {
    const vec4 pj = in.spos[t];
    const float dx = pj.x - pi.x;
    const float dy = pj.y - pi.y;
    const float dz = pj.z - pi.z;
    const float rsum = pi.w + pj.w;
    if (dx * dx + dy * dy + dz * dz >= rsum * rsum || in.sbody[t] == body_i) continue;
    const vec4 vj = in.svel[t];
    f += shared::particle_contact_force(xi, ui, pi.w, vi.w, shared::xyz(pj), shared::xyz(vj), pj.w,
                                        vj.w, law_row[in.smat[t]], flags);
  }
}

/// The particle's own data, in particle order (the same values as its sorted copies).
struct ParticleInputs {
  const vec4* __restrict__ pos;
  const vec4* __restrict__ vel;
  const uint* __restrict__ body;
  const uint* __restrict__ material;
};

__global__ void contacts_compute_kernel(shared::StepParams p, ContactInputs in, ParticleInputs own,
                                        const uint* __restrict__ cell_start,
                                        const shared::PlaneData* __restrict__ planes,
                                        vec4* __restrict__ force) {
  const std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (i >= p.particle_count) return;
  const vec4 pi = own.pos[i];
  const vec4 vi = own.vel[i];
  if (vi.w == 0.0f) {  // static particle: its force is never used
    force[i] = vec4(0.0f);
    return;
  }
  const uint body_i = own.body[i];
  const shared::ContactLaw* law_row = in.laws + std::size_t{own.material[i]} * p.material_count;
  const uint mask = p.table_mask;
  const int cx = shared::grid_cell_coord(pi.x, p.inv_cell_size);
  const int cy = shared::grid_cell_coord(pi.y, p.inv_cell_size);
  const int cz = shared::grid_cell_coord(pi.z, p.inv_cell_size);

  vec3 f(0.0f);
  uint centres[9];
  int row = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy, ++row) {
      const uint c = shared::grid_bucket(cx, cy + dy, cz + dz, mask);
      // Hashed rows can share buckets; every bucket is visited once, by its first row.
      bool clash = false;
      for (int r = 0; r < row; ++r) clash = clash || ((c - centres[r] + 2u) & mask) <= 4u;
      centres[row] = c;
      if (!clash && c >= 1u && c < mask) {  // buckets c-1, c, c+1 as one range
        gather_range(in, cell_start[c - 1u], cell_start[c + 2u], pi, vi, body_i, law_row, p.flags,
                     f);
        continue;
      }
      for (uint k = 0; k < 3u; ++k) {
        const uint b = (c + k - 1u) & mask;
        bool seen = false;
        for (int r = 0; r < row; ++r) seen = seen || shared::grid_row_covers(centres[r], b, mask);
        if (!seen) {
          gather_range(in, cell_start[b], cell_start[b + 1u], pi, vi, body_i, law_row, p.flags, f);
        }
      }
    }
  }
  const vec3 xi = shared::xyz(pi);
  const vec3 ui = shared::xyz(vi);
  for (uint k = 0; k < p.plane_count; ++k) {
    const shared::PlaneData pl = planes[k];
    f += shared::plane_contact_force(xi, ui, pi.w, vi.w, pl.normal_offset, law_row[pl.material],
                                     p.flags);
  }
  force[i] = vec4(f, 0.0f);
}

}  // namespace

void CudaDevice::launch_contacts_compute(const shared::StepParams& p) {
  if (p.particle_count == 0) return;
  const ContactInputs in{buf<vec4>(Buffer::SortedPos), buf<vec4>(Buffer::SortedVel),
                         buf<uint>(Buffer::SortedBody), buf<uint>(Buffer::SortedMaterial),
                         buf<shared::ContactLaw>(Buffer::ContactLaws)};
  const ParticleInputs own{buf<vec4>(Buffer::ParticlePos), buf<vec4>(Buffer::ParticleVel),
                           buf<uint>(Buffer::ParticleBody), buf<uint>(Buffer::ParticleMaterial)};
  contacts_compute_kernel<<<blocks_for(p.particle_count), kBlock, 0, stream_>>>(
      p, in, own, buf<uint>(Buffer::GridCellStart), buf<shared::PlaneData>(Buffer::Planes),
      buf<vec4>(Buffer::ParticleForce));
}

}  // namespace motes::cuda
