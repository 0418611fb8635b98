// The CUDA backend: every kernel family as CUDA kernels over the shared physics headers, CUB's
// radix sort for the grid, and the step's repeating cycle of kernel calls captured once into a
// CUDA graph and replayed (docs/architecture.md, "The CUDA backend").
#pragma once

#include <cuda_runtime_api.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "body_buffers.h"
#include "contact_inputs.h"
#include "halo_buffers.h"
#include "motes/backend/device.h"
#include "motes/backend/kernel_queue.h"
#include "shared/common.h"

namespace motes::cuda {

class CudaDevice final : public Device {
 public:
  /// Guard bytes after every buffer (pattern kGuardByte); no kernel may write them.
  static constexpr std::size_t kGuardBytes = 64;
  static constexpr unsigned char kGuardByte = 0xA5;
  /// Threads per block of every motes kernel.
  static constexpr unsigned kBlock = 256;
  /// impulses_compute's blocks of kBlock threads an SM (its launch bound: impulses_compute.cu).
  static constexpr unsigned kImpulseBlocksPerSm = 3;

  /// Opens CUDA device `ordinal` and creates its stream.
  static Result<std::unique_ptr<Device>> open(int ordinal);
  ~CudaDevice() override;

  [[nodiscard]] const DeviceInfo& info() const override { return info_; }
  [[nodiscard]] std::uint64_t required_bytes(const Sizes& sizes) const override;
  [[nodiscard]] std::uint64_t available_bytes() const override;
  Status allocate(const Sizes& sizes) override;
  Status write(Buffer b, const void* src, std::size_t bytes) override;
  Status write_at(Buffer b, std::size_t offset, const void* src, std::size_t bytes) override;
  Status read(Buffer b, void* dst, std::size_t bytes) override;

  void enqueue(Kernel k, const shared::StepParams& p) override;

  Status synchronize() override;
  /// Page-locked host memory (cudaMallocHost): read() and write() move it by DMA.
  [[nodiscard]] void* allocate_host(std::size_t bytes) override;
  void free_host(void* memory) override;
  Status check_guards() override;
  /// Device-direct halo between processes of one host through CUDA IPC (halo_outbox.cpp): the
  /// outbox is its own cudaMalloc, shared by cudaIpcGetMemHandle; a neighbour's is mapped by
  /// cudaIpcOpenMemHandle (peer access over NVLink enabled as needed) and copied from on stream_.
  [[nodiscard]] Result<std::vector<unsigned char>> share_halo_outbox(std::size_t bytes) override;
  Status publish_halo_outbox(std::size_t bytes) override;
  [[nodiscard]] Result<std::size_t> open_peer_outbox(
      const std::vector<unsigned char>& handle) override;
  Status fetch_peer_outbox(std::size_t peer, std::size_t from, std::size_t to,
                           std::size_t bytes) override;
  void close_peer_outboxes() override;
  /// The GPU's cudaDeviceProp::uuid (motes/cuda_interop.h).
  [[nodiscard]] const std::array<std::uint8_t, 16>& uuid() const { return uuid_; }
  [[nodiscard]] int ordinal() const { return ordinal_; }
  /// Runs the queued kernels, then copies the first `count` particle positions to `positions`
  /// and, unless it is null, the velocities to `velocities` (device memory on this GPU); returns
  /// when the copy is complete (cuda_interop.cpp).
  Status copy_particles_to(void* positions, void* velocities, std::size_t count);
  void set_timing(bool on) override { timing_ = on; }
  [[nodiscard]] KernelTimes kernel_times() const override { return times_; }
  void reset_kernel_times() override { times_ = {}; }

 private:
  /// A captured and instantiated graph of `copies` repetitions of a cycle of calls.
  struct Graph {
    std::vector<KernelCall> cycle;
    std::size_t copies = 0;
    cudaGraphExec_t exec = nullptr;
  };

  CudaDevice() = default;

  template <typename T>
  T* buf(Buffer b) const {
    return static_cast<T*>(buffers_[static_cast<std::size_t>(b)]);
  }
  /// Records the first failure (sticky); later calls report it.
  Status check(cudaError_t e, const char* what);
  void release_buffers();
  void release_graphs();

  /// Runs every queued call: captured graphs when timing is off, timed launches when on.
  Status flush();
  Status run_timed(const std::vector<KernelCall>& calls);
  /// Launches `calls` (none a NeighboursUpdate) one by one between events and adds their times.
  Status time_calls(const std::vector<KernelCall>& calls);
  Status run_graphs(const std::vector<KernelCall>& cycle, std::size_t reps);
  Result<cudaGraphExec_t> graph_for(const std::vector<KernelCall>& cycle, std::size_t copies);
  /// Launches calls[i] (and, when `fuse` and they allow it, fuses it with the calls after it);
  /// returns how many calls it consumed. A NeighboursUpdate is only launched while a graph is
  /// captured: a kernel sets the condition of an IF node that holds the rebuild.
  std::size_t launch(const std::vector<KernelCall>& calls, std::size_t i, bool fuse = true);
  /// True when calls[i] is a sweep of impulse contacts (no counting, no position contacts) whose
  /// substep's counting pass comes before it in `calls` with nothing between but such sweeps and
  /// impulses_apply calls that move no body (kernels.h: "A sweep ... after its substep's counting
  /// pass, positions and lists unchanged since"). Decided from the calls alone, so a graph
  /// captured from them replays the same decision.
  static bool sweep_follows_count(const std::vector<KernelCall>& calls, std::size_t i);

  // One file per kernel family launches it on stream_ (grid_build.cu, contacts_compute.cu...).
#define MOTES_LAUNCH_DECLARATION(E, name, reads, writes) \
  void launch_##name(const shared::StepParams& p);
  MOTES_KERNELS(MOTES_LAUNCH_DECLARATION)
#undef MOTES_LAUNCH_DECLARATION
  /// neighbours_update.cu: the kernel that sets the rebuild's IF-node condition.
  void launch_neighbours_decide(cudaGraphConditionalHandle handle);
  /// bodies_reduce, bodies_integrate and particles_update in one pass (bodies_step.cu), for scenes
  /// whose bodies are small; the same arithmetic as the three kernels.
  void launch_bodies_step(const shared::StepParams& p);
  /// CUB's temporary storage for sorting n pairs on key_bits bits (grid_build.cu).
  static Result<std::size_t> sort_temp_size(std::uint32_t n, int key_bits);
  /// Fills ids_ with 0..n-1 (grid_build.cu).
  void launch_ids_fill(std::uint32_t n);
  /// The buffers of the three body passes.
  [[nodiscard]] BodyBuffers body_buffers() const;
  /// The body buffers of a halo entry, in HaloData's order.
  [[nodiscard]] HaloBodies halo_bodies() const;
  /// The buffers of contacts_compute and impulses_compute.
  [[nodiscard]] ContactInputs contact_inputs() const;

  DeviceInfo info_;
  int ordinal_ = 0;
  std::array<std::uint8_t, 16> uuid_{};
  cudaStream_t stream_ = nullptr;  ///< every launch goes here
  /// A second stream, swapped into stream_ while the body of a conditional rebuild is captured.
  cudaStream_t body_stream_ = nullptr;
  Sizes sizes_;
  bool allocated_ = false;
  std::array<void*, kBufferCount> buffers_{};
  std::array<std::size_t, kBufferCount> bytes_{};
  // grid_build scratch: particle ids 0..N-1 (CUB's input values), sorted keys, CUB temp storage.
  shared::uint* ids_ = nullptr;
  shared::uint* sorted_keys_ = nullptr;
  void* sort_temp_ = nullptr;
  std::size_t sort_temp_bytes_ = 0;
  /// The particles a counting pass of impulse contacts found within reach of a contact: [0] their
  /// count, then their ids (impulses_compute.cu). Allocated with impulse contacts (Sizes::impulse).
  shared::uint* impulse_listed_ = nullptr;
  /// Set by launch() for the call it launches: an impulses_compute sweep that may visit only
  /// impulse_listed_ (sweep_follows_count).
  bool impulse_sweep_listed_ = false;
  /// The fewest rigid particles whose counting pass lists them: one wave of impulses_compute
  /// (kImpulseBlocksPerSm blocks an SM); a sweep of fewer runs in one wave anyway, and reading its
  /// particle from the list costs it a load's latency. MOTES_CUDA_IMPULSE_LIST_FROM=N sets it
  /// (tests: 0 lists every count).
  std::uint64_t impulse_list_from_ = 0;
  /// Host copies of BodyFirst and ParticleBody as last written: the fused body pass is used only
  /// when they agree (body b owns exactly particles [first[b], first[b+1])) and every body is
  /// small, so that it computes what the three separate kernels compute.
  std::vector<shared::uint> host_first_, host_body_;
  bool bodies_fusable_ = false;
  /// The most and the fewest particles a body has (0: not known: BodyFirst not written whole).
  shared::uint largest_body_ = 0;
  shared::uint smallest_body_ = 0;
  /// Bodies of this many particles (four chunks of shared/impulse.h: MOTES_BODY_CHUNK) or more take
  /// impulses_apply's block per body, the others a thread each (impulses_apply.cu).
  static constexpr shared::uint kWideBodyParticles = 256;
  void update_fusable();

  /// This device's halo outbox and the opened outboxes of other processes (halo_outbox.cpp).
  struct PeerOutbox {
    void* memory = nullptr;
    std::size_t bytes = 0;
  };
  void* outbox_ = nullptr;
  std::size_t outbox_bytes_ = 0;
  std::vector<PeerOutbox> peers_;
  void release_outboxes();

  std::vector<KernelCall> pending_;
  std::vector<Graph> graphs_;
  bool host_rebuild_ = false;  ///< MOTES_CUDA_HOST_REBUILD=1: calls launched one by one
  std::vector<cudaEvent_t> events_;
  Status error_;
  bool timing_ = false;
  KernelTimes times_;
};

/// A CUDA error as text: its description and its name.
std::string error_text(cudaError_t e);

/// Blocks for n threads of CudaDevice::kBlock.
inline unsigned blocks_for(std::uint64_t n) {
  return static_cast<unsigned>((n + CudaDevice::kBlock - 1) / CudaDevice::kBlock);
}

/// Blocks of a grid-stride loop over n items: a thread per item up to 4,096 blocks (about four
/// times the threads an H100's 132 SMs hold at once); beyond, each thread takes several.
inline unsigned grid_stride_blocks(std::uint64_t n) {
  constexpr unsigned kMaxBlocks = 4096;
  const unsigned blocks = blocks_for(n);
  return blocks < kMaxBlocks ? blocks : kMaxBlocks;
}

}  // namespace motes::cuda
