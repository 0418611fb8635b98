// CudaDevice's device-direct halo between the processes of one host (Device::share_halo_outbox,
// docs/scale-out.md): the outbox is a cudaMalloc of its own, shared by a CUDA IPC handle; the
// neighbours map it with cudaIpcOpenMemHandle and copy their parts into their HaloData on their
// stream (over NVLink between two GPUs, within the GPU between ranks that share one). Failures
// here are not sticky: the ranks then go back to the halo through host memory.
#include <fmt/format.h>

#include <cstring>

#include "cuda_device.h"

namespace motes::cuda {

namespace {

/// A handle: the IPC handle, then the outbox's size in bytes.
constexpr std::size_t kHandleBytes = sizeof(cudaIpcMemHandle_t) + sizeof(std::uint64_t);

}  // namespace

Result<std::vector<unsigned char>> CudaDevice::share_halo_outbox(std::size_t bytes) {
  if (Status s = synchronize(); !s) return s;
  cudaSetDevice(ordinal_);
  if (bytes > outbox_bytes_) {
    if (outbox_ != nullptr) cudaFree(outbox_);
    outbox_ = nullptr;
    outbox_bytes_ = 0;
    if (const cudaError_t e = cudaMalloc(&outbox_, bytes); e != cudaSuccess) {
      (void)cudaGetLastError();
      outbox_ = nullptr;
      return Status::error(fmt::format("cuda: no device memory for a halo outbox of {} bytes: {}",
                                       bytes, error_text(e)));
    }
    outbox_bytes_ = bytes;
  }
  cudaIpcMemHandle_t ipc{};
  if (cudaIpcGetMemHandle(&ipc, outbox_) != cudaSuccess) {
    (void)cudaGetLastError();  // no IPC here (e.g. a driver or system without it): host path
    return std::vector<unsigned char>{};
  }
  std::vector<unsigned char> handle(kHandleBytes);
  const std::uint64_t size = outbox_bytes_;
  std::memcpy(handle.data(), &ipc, sizeof ipc);
  std::memcpy(handle.data() + sizeof ipc, &size, sizeof size);
  return handle;
}

Status CudaDevice::publish_halo_outbox(std::size_t bytes) {
  const auto data = static_cast<std::size_t>(Buffer::HaloData);
  if (!allocated_ || bytes > outbox_bytes_ || bytes > bytes_[data]) {
    return Status::error(
        fmt::format("cuda: publishing {} bytes of HaloData ({} bytes) in an outbox of {} bytes",
                    bytes, allocated_ ? bytes_[data] : 0, outbox_bytes_));
  }
  if (Status s = flush(); !s) return s;
  if (bytes == 0) return Status::ok();
  return check(cudaMemcpyAsync(outbox_, buffers_[data], bytes, cudaMemcpyDeviceToDevice, stream_),
               "copying HaloData into the halo outbox");
}

Result<std::size_t> CudaDevice::open_peer_outbox(const std::vector<unsigned char>& handle) {
  if (handle.size() != kHandleBytes) {
    return Status::error(fmt::format("cuda: a halo outbox handle of {} bytes (not {})",
                                     handle.size(), kHandleBytes));
  }
  cudaIpcMemHandle_t ipc{};
  std::uint64_t size = 0;
  std::memcpy(&ipc, handle.data(), sizeof ipc);
  std::memcpy(&size, handle.data() + sizeof ipc, sizeof size);
  cudaSetDevice(ordinal_);
  void* memory = nullptr;
  if (const cudaError_t e = cudaIpcOpenMemHandle(&memory, ipc, cudaIpcMemLazyEnablePeerAccess);
      e != cudaSuccess) {
    (void)cudaGetLastError();
    return Status::error(
        fmt::format("cuda ({}): cudaIpcOpenMemHandle of a neighbour's halo "
                    "outbox failed: {}",
                    info_.name, error_text(e)));
  }
  peers_.push_back({memory, static_cast<std::size_t>(size)});
  return peers_.size() - 1;
}

Status CudaDevice::fetch_peer_outbox(std::size_t peer, std::size_t from, std::size_t to,
                                     std::size_t bytes) {
  const auto data = static_cast<std::size_t>(Buffer::HaloData);
  if (!allocated_ || peer >= peers_.size() || from + bytes > peers_[peer].bytes ||
      to + bytes > bytes_[data]) {
    return Status::error(fmt::format(
        "cuda: fetching bytes [{}, {}) of halo outbox {} ({} open) into bytes [{}, {}) of "
        "HaloData ({} bytes)",
        from, from + bytes, peer, peers_.size(), to, to + bytes, allocated_ ? bytes_[data] : 0));
  }
  if (Status s = flush(); !s) return s;
  if (bytes == 0) return Status::ok();
  return check(cudaMemcpyAsync(static_cast<char*>(buffers_[data]) + to,
                               static_cast<const char*>(peers_[peer].memory) + from, bytes,
                               cudaMemcpyDeviceToDevice, stream_),
               "copying a neighbour's halo outbox");
}

void CudaDevice::close_peer_outboxes() {
  cudaSetDevice(ordinal_);
  if (stream_ != nullptr) cudaStreamSynchronize(stream_);
  for (const PeerOutbox& p : peers_) cudaIpcCloseMemHandle(p.memory);
  peers_.clear();
}

void CudaDevice::release_outboxes() {
  close_peer_outboxes();
  if (outbox_ != nullptr) cudaFree(outbox_);
  outbox_ = nullptr;
  outbox_bytes_ = 0;
}

}  // namespace motes::cuda
