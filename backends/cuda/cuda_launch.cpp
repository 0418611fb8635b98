// Queueing, graphs and timing. Kernel calls are queued; flush() finds the shortest cycle the queue
// repeats (a step: its kernel families, once per substep), captures it once into a CUDA graph (and
// a graph of kGraphCycles repetitions of it), caches both, and launches them as many times as the
// cycle repeats: no host synchronization or allocation per step. The neighbour-list rebuild sits
// in an IF node of the graph whose condition a kernel sets from NeighbourState. Timing launches
// the calls one by one between CUDA events instead, deciding the rebuild on the host.
#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "cuda_device.h"

namespace motes::cuda {

namespace {

/// Cycles per big graph: a graph launch costs a few microseconds of host time, so long runs
/// launch one graph per kGraphCycles steps.
constexpr std::size_t kGraphCycles = 16;
/// Graphs kept; more and the oldest is freed.
constexpr std::size_t kMaxGraphs = 8;
/// Timed calls between two waits for their events.
constexpr std::size_t kTimedBatch = 256;

}  // namespace

void CudaDevice::enqueue(Kernel k, const shared::StepParams& p) {
  if (!error_) return;
  if (!allocated_) {
    error_ = Status::error("cuda: kernel launched before allocate");
    return;
  }
  // Every kernel indexes its buffers by these counts: refuse any the allocation cannot hold.
  if (p.particle_count > sizes_.particles || p.body_count > sizes_.bodies ||
      std::uint64_t{p.table_mask} + 1 > sizes_.table || p.plane_count > sizes_.planes ||
      p.material_count > sizes_.materials || p.rigid_particle_count > sizes_.rigid_particles ||
      p.rigid_particle_count > p.particle_count ||
      p.neighbour_capacity > sizes_.neighbour_capacity) {
    error_ = Status::error(fmt::format(
        "cuda: {} launched with {} particles ({} rigid), {} bodies, {} buckets, {} planes, {} "
        "materials and {} list entries per particle on buffers allocated for {} ({}), {}, {}, "
        "{}, {} and {}",
        kernel_name(k), p.particle_count, p.rigid_particle_count, p.body_count,
        std::uint64_t{p.table_mask} + 1, p.plane_count, p.material_count, p.neighbour_capacity,
        sizes_.particles, sizes_.rigid_particles, sizes_.bodies, sizes_.table, sizes_.planes,
        sizes_.materials, sizes_.neighbour_capacity));
    return;
  }
  if (p.cluster_count > sizes_.clusters || p.linked_first > p.particle_count ||
      p.soft_first > p.linked_first || p.linked_first - p.soft_first > sizes_.soft_particles) {
    error_ = Status::error(fmt::format(
        "cuda: {} launched with {} clusters and soft particles [{}, {}) of {} on buffers "
        "allocated for {} clusters and {} soft particles",
        kernel_name(k), p.cluster_count, p.soft_first, p.linked_first, p.particle_count,
        sizes_.clusters, sizes_.soft_particles));
    return;
  }
  // ParticleMoment (and the impulse stage's buffers) exist only for impulse contacts, or, the
  // moment, for cloth and ropes attached to rigid bodies (Sizes::absorb).
  const bool absorbs = k == Kernel::ImpulsesApply ||
                       (k == Kernel::ParticlesUpdate && (p.flags & MOTES_FLAG_ABSORB) != 0u);
  if ((k == Kernel::ImpulsesCompute && sizes_.impulse == 0) ||
      (absorbs && sizes_.impulse == 0 && sizes_.absorb == 0) ||
      (k == Kernel::ImpulsesApply && (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u &&
       sizes_.impulse == 0)) {
    error_ = Status::error(fmt::format(
        "cuda: {} launched on buffers allocated without impulse contacts or attachments",
        kernel_name(k)));
    return;
  }
  // The halo entries and the partition's buffers exist only in runs over MPI ranks (Sizes).
  if (std::string why = halo_launch_error(k, p, sizes_); !why.empty()) {
    error_ = Status::error("cuda: " + why);
    return;
  }
  // energy_reduce writes a block per 256 items: no more than EnergyPartials holds.
  if (std::string why = energy_launch_error(k, p, sizes_); !why.empty()) {
    error_ = Status::error("cuda: " + why);
    return;
  }
  pending_.push_back({k, p});
}

bool CudaDevice::sweep_follows_count(const std::vector<KernelCall>& calls, std::size_t i) {
  const shared::StepParams& p = calls[i].params;
  if (calls[i].kernel != Kernel::ImpulsesCompute ||
      (p.flags & (MOTES_FLAG_IMPULSE_COUNT | MOTES_FLAG_POSITION)) != 0u) {
    return false;
  }
  while (i-- > 0) {
    const shared::StepParams& q = calls[i].params;
    // The same particles, lists and reach (impulse_margin), and no position contacts (whose
    // impulses_apply moves the bodies).
    if ((q.flags & MOTES_FLAG_POSITION) != 0u || q.particle_count != p.particle_count ||
        q.rigid_particle_count != p.rigid_particle_count || q.plane_count != p.plane_count ||
        q.neighbour_capacity != p.neighbour_capacity || q.neighbour_skin != p.neighbour_skin) {
      return false;
    }
    if (calls[i].kernel == Kernel::ImpulsesCompute) {
      if ((q.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u) return true;
      continue;
    }
    if (calls[i].kernel != Kernel::ImpulsesApply) return false;
  }
  return false;
}

std::size_t CudaDevice::launch(const std::vector<KernelCall>& calls, std::size_t i, bool fuse) {
  const shared::StepParams& p = calls[i].params;
  impulse_sweep_listed_ = sweep_follows_count(calls, i);
  if (calls[i].kernel == Kernel::BodiesReduce && fuse && bodies_fusable_ &&
      p.body_count == sizes_.bodies && p.rigid_particle_count == sizes_.rigid_particles &&
      i + 2 < calls.size() && same_call(calls[i + 1], {Kernel::BodiesIntegrate, p}) &&
      same_call(calls[i + 2], {Kernel::ParticlesUpdate, p})) {
    launch_bodies_step(p);
    return 3;
  }
  switch (calls[i].kernel) {
#define MOTES_LAUNCH_CASE(E, name, reads, writes) \
  case Kernel::E:                                 \
    launch_##name(p);                             \
    break;
    MOTES_KERNELS(MOTES_LAUNCH_CASE)
#undef MOTES_LAUNCH_CASE
    case Kernel::Count:
      break;
  }
  return 1;
}

void CudaDevice::release_graphs() {
  for (Graph& g : graphs_) cudaGraphExecDestroy(g.exec);
  graphs_.clear();
}

Result<cudaGraphExec_t> CudaDevice::graph_for(const std::vector<KernelCall>& cycle,
                                              std::size_t copies) {
  for (const Graph& g : graphs_) {
    if (g.copies == copies && same_calls(g.cycle, cycle)) return g.exec;
  }
  if (graphs_.size() >= kMaxGraphs) {  // nothing is in flight between flushes
    cudaGraphExecDestroy(graphs_.front().exec);
    graphs_.erase(graphs_.begin());
  }
  if (Status s = check(cudaStreamBeginCapture(stream_, cudaStreamCaptureModeThreadLocal),
                       "cudaStreamBeginCapture");
      !s) {
    return s;
  }
  for (std::size_t c = 0; c < copies; ++c) {
    for (std::size_t i = 0; i < cycle.size();) i += launch(cycle, i);
  }
  const cudaError_t launched = cudaGetLastError();
  cudaGraph_t graph = nullptr;
  const cudaError_t ended = cudaStreamEndCapture(stream_, &graph);
  if (Status s = check(launched, "a kernel launch during graph capture"); !s) {
    if (graph != nullptr) cudaGraphDestroy(graph);
    return s;
  }
  if (Status s = check(ended, "cudaStreamEndCapture"); !s) return s;
  cudaGraphExec_t exec = nullptr;
  const cudaError_t made = cudaGraphInstantiate(&exec, graph, 0);
  cudaGraphDestroy(graph);
  if (Status s = check(made, "cudaGraphInstantiate"); !s) return s;
  graphs_.push_back({cycle, copies, exec});
  return exec;
}

Status CudaDevice::run_graphs(const std::vector<KernelCall>& cycle, std::size_t reps) {
  if (reps >= kGraphCycles) {
    Result<cudaGraphExec_t> big = graph_for(cycle, kGraphCycles);
    if (!big) return big.status();
    for (; reps >= kGraphCycles; reps -= kGraphCycles) {
      if (Status s = check(cudaGraphLaunch(big.value(), stream_), "cudaGraphLaunch"); !s) return s;
    }
  }
  if (reps == 0) return Status::ok();
  Result<cudaGraphExec_t> one = graph_for(cycle, 1);
  if (!one) return one.status();
  for (; reps > 0; --reps) {
    if (Status s = check(cudaGraphLaunch(one.value(), stream_), "cudaGraphLaunch"); !s) return s;
  }
  return Status::ok();
}

Status CudaDevice::run_timed(const std::vector<KernelCall>& calls) {
  // A NeighboursUpdate is decided on the host: the calls before it run, NeighbourState is read,
  // and grid_build and neighbours_build are timed as themselves when a rebuild is due.
  std::vector<KernelCall> batch;
  for (const KernelCall& call : calls) {
    if (call.kernel != Kernel::NeighboursUpdate) {
      batch.push_back(call);
      continue;
    }
    if (Status s = time_calls(batch); !s) return s;
    batch.clear();
    shared::uint rebuild = 0;
    if (Status s = check(cudaMemcpyAsync(&rebuild, buf<shared::uint>(Buffer::NeighbourState),
                                         sizeof rebuild, cudaMemcpyDeviceToHost, stream_),
                         "reading NeighbourState");
        !s) {
      return s;
    }
    if (Status s = check(cudaStreamSynchronize(stream_), "reading NeighbourState"); !s) return s;
    times_.launches[static_cast<std::size_t>(Kernel::NeighboursUpdate)] += 1;
    if (rebuild != 0) {
      batch.push_back({Kernel::GridBuild, call.params});
      batch.push_back({Kernel::NeighboursBuild, call.params});
    }
  }
  return time_calls(batch);
}

Status CudaDevice::time_calls(const std::vector<KernelCall>& calls) {
  if (events_.size() < 2 * kTimedBatch) {
    events_.reserve(2 * kTimedBatch);
    while (events_.size() < 2 * kTimedBatch) {
      cudaEvent_t e = nullptr;
      if (Status s = check(cudaEventCreate(&e), "cudaEventCreate"); !s) return s;
      events_.push_back(e);
    }
  }
  for (std::size_t start = 0; start < calls.size(); start += kTimedBatch) {
    const std::size_t end = std::min(calls.size(), start + kTimedBatch);
    for (std::size_t i = start; i < end; ++i) {
      const std::size_t e = 2 * (i - start);
      cudaEventRecord(events_[e], stream_);
      launch(calls, i, false);  // unfused: the time of every family on its own
      cudaEventRecord(events_[e + 1], stream_);
    }
    if (Status s = check(cudaGetLastError(), "a kernel launch"); !s) return s;
    if (Status s = check(cudaStreamSynchronize(stream_), "running the queued kernels"); !s) {
      return s;
    }
    for (std::size_t i = start; i < end; ++i) {
      const std::size_t e = 2 * (i - start);
      float ms = 0.0f;
      if (Status s =
              check(cudaEventElapsedTime(&ms, events_[e], events_[e + 1]), "cudaEventElapsedTime");
          !s) {
        return s;
      }
      const auto k = static_cast<std::size_t>(calls[i].kernel);
      times_.seconds[k] += 1e-3 * static_cast<double>(ms);
      times_.launches[k] += 1;
    }
  }
  return Status::ok();
}

Status CudaDevice::flush() {
  if (!error_) {
    pending_.clear();
    return error_;
  }
  if (pending_.empty()) return Status::ok();
  std::vector<KernelCall> calls;
  calls.swap(pending_);
  cudaSetDevice(ordinal_);
  // MOTES_CUDA_HOST_REBUILD=1: no graphs, the rebuild decided on the host (as with timing on),
  // for tools that cannot follow conditional graph nodes (compute-sanitizer: gpu/run-suite.sh).
  if (timing_ || host_rebuild_) return run_timed(calls);
  const std::size_t period = repeating_period(calls);
  const std::vector<KernelCall> cycle(calls.begin(),
                                      calls.begin() + static_cast<std::ptrdiff_t>(period));
  return run_graphs(cycle, calls.size() / period);
}

}  // namespace motes::cuda
