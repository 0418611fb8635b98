// CudaDevice: devices, buffers, host transfers, guard words and errors. Queueing and graphs are in
// cuda_launch.cpp; kernels live in one file per family.
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>

#include "cuda_backend.h"
#include "cuda_device.h"
#include "motes/backend/env.h"

namespace motes::cuda {

std::string error_text(cudaError_t e) {
  return fmt::format("{} ({})", cudaGetErrorString(e), cudaGetErrorName(e));
}

namespace {

DeviceInfo describe(int ordinal, const cudaDeviceProp& prop) {
  DeviceInfo d;
  d.backend = "cuda";
  d.index = ordinal;
  d.name = prop.name;
  int driver = 0;
  cudaDriverGetVersion(&driver);
  d.detail = fmt::format("compute capability {}.{}, {} SMs, {:.1f} GiB, driver CUDA {}.{}",
                         prop.major, prop.minor, prop.multiProcessorCount,
                         static_cast<double>(prop.totalGlobalMem) / (1024.0 * 1024.0 * 1024.0),
                         driver / 1000, (driver % 1000) / 10);
  return d;
}

}  // namespace

Listing list_devices() {
  Listing l;
  int count = 0;
  const cudaError_t e = cudaGetDeviceCount(&count);
  if (e != cudaSuccess) {
    cudaGetLastError();
    if (e == cudaErrorNoDevice) {
      l.reason = "no CUDA GPU on this machine";
    } else if (e == cudaErrorInsufficientDriver) {
      l.reason =
          "no NVIDIA driver, or one too old for this build's CUDA runtime (" + error_text(e) + ")";
    } else {
      l.reason = "CUDA unavailable: " + error_text(e);
    }
    return l;
  }
  for (int i = 0; i < count; ++i) {
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, i) != cudaSuccess) continue;
    l.devices.push_back(describe(i, prop));
  }
  if (l.devices.empty()) l.reason = "no CUDA GPU on this machine";
  return l;
}

Result<std::unique_ptr<Device>> open_device(int index) {
  if (index < 0) {
    const char* env = std::getenv("MOTES_CUDA_DEVICE");
    index = 0;
    if (env != nullptr && *env != '\0') {
      char* end = nullptr;
      const long v = std::strtol(env, &end, 10);
      if (*end != '\0' || v < 0 || v > 1024) {
        return Status::error(fmt::format("MOTES_CUDA_DEVICE='{}' is not a device index", env));
      }
      index = static_cast<int>(v);
    }
  }
  const Listing l = list_devices();
  if (l.devices.empty()) return Status::error("backend cuda is unavailable: " + l.reason);
  if (index >= static_cast<int>(l.devices.size())) {
    return Status::error(fmt::format("cuda device {} does not exist ({} device{}: 0 to {})", index,
                                     l.devices.size(), l.devices.size() == 1 ? "" : "s",
                                     l.devices.size() - 1));
  }
  return CudaDevice::open(index);
}

Result<std::unique_ptr<Device>> CudaDevice::open(int ordinal) {
  std::unique_ptr<CudaDevice> d(new CudaDevice());
  d->ordinal_ = ordinal;
  cudaDeviceProp prop{};
  if (Status s = d->check(cudaSetDevice(ordinal), "cudaSetDevice"); !s) return s;
  if (Status s = d->check(cudaGetDeviceProperties(&prop, ordinal), "cudaGetDeviceProperties"); !s) {
    return s;
  }
  d->info_ = describe(ordinal, prop);
  static_assert(sizeof(prop.uuid) == sizeof(d->uuid_));
  std::memcpy(d->uuid_.data(), &prop.uuid, sizeof(d->uuid_));
  d->impulse_list_from_ =
      std::uint64_t{static_cast<unsigned>(prop.multiProcessorCount)} * kImpulseBlocksPerSm * kBlock;
  Result<std::optional<std::uint64_t>> from = env_whole_number(
      "MOTES_CUDA_IMPULSE_LIST_FROM",
      "a number of particles (a whole number; 0 lists the particles within reach of a contact at "
      "every size)");
  if (!from) return from.status();
  if (from.value()) d->impulse_list_from_ = *from.value();
  const char* host_rebuild = std::getenv("MOTES_CUDA_HOST_REBUILD");
  d->host_rebuild_ = host_rebuild != nullptr && std::strcmp(host_rebuild, "1") == 0;
  for (cudaStream_t* stream : {&d->stream_, &d->body_stream_}) {
    if (Status s =
            d->check(cudaStreamCreateWithFlags(stream, cudaStreamNonBlocking), "cudaStreamCreate");
        !s) {
      return s;
    }
  }
  std::unique_ptr<Device> out = std::move(d);
  return out;
}

CudaDevice::~CudaDevice() {
  cudaSetDevice(ordinal_);
  if (stream_ != nullptr) cudaStreamSynchronize(stream_);
  release_graphs();
  release_buffers();
  release_outboxes();
  for (cudaEvent_t e : events_) cudaEventDestroy(e);
  if (stream_ != nullptr) cudaStreamDestroy(stream_);
  if (body_stream_ != nullptr) cudaStreamDestroy(body_stream_);
}

Status CudaDevice::check(cudaError_t e, const char* what) {
  if (e == cudaSuccess) return Status::ok();
  cudaGetLastError();  // clears a non-sticky error; a sticky one stays with the context
  Status s = Status::error(fmt::format(
      "cuda ({}): {} failed: {}", info_.name.empty() ? "device" : info_.name, what, error_text(e)));
  if (error_) error_ = s;
  return error_;
}

void CudaDevice::release_buffers() {
  for (void*& p : buffers_) {
    if (p != nullptr) cudaFree(p);
    p = nullptr;
  }
  bytes_ = {};
  for (void* p : {static_cast<void*>(ids_), static_cast<void*>(sorted_keys_), sort_temp_,
                  static_cast<void*>(impulse_listed_)}) {
    if (p != nullptr) cudaFree(p);
  }
  impulse_listed_ = nullptr;
  ids_ = nullptr;
  sorted_keys_ = nullptr;
  sort_temp_ = nullptr;
  sort_temp_bytes_ = 0;
  allocated_ = false;
}

std::uint64_t CudaDevice::required_bytes(const Sizes& sizes) const {
  // Every buffer and its guard bytes, the sort's ids and keys, and CUB's temporary storage (about
  // the keys and values again, plus its histograms).
  const std::uint64_t n = sizes.particles;
  // With impulse contacts, the list of particles within reach (impulses_compute.cu).
  const std::uint64_t listed =
      sizes.impulse != 0 ? (std::uint64_t{sizes.rigid_particles} + 1) * 4 : 0;
  return buffers_bytes(sizes) + kBufferCount * (kGuardBytes + 256) + n * 8 + n * 8 + listed +
         (8u << 20);
}

std::uint64_t CudaDevice::available_bytes() const {
  std::size_t free_bytes = 0;
  std::size_t total_bytes = 0;
  if (cudaSetDevice(ordinal_) != cudaSuccess ||
      cudaMemGetInfo(&free_bytes, &total_bytes) != cudaSuccess) {
    cudaGetLastError();
    return UINT64_MAX;  // unknown: let the allocation itself decide
  }
  // What this device already holds is given back before allocate() allocates again.
  std::uint64_t held = 0;
  if (allocated_) {
    for (std::size_t b : bytes_) held += b + kGuardBytes;
    held += sort_temp_bytes_ + 2 * std::uint64_t{sizes_.particles} * sizeof(shared::uint);
    if (impulse_listed_ != nullptr) held += (std::uint64_t{sizes_.rigid_particles} + 1) * 4;
  }
  return free_bytes + held;
}

Status CudaDevice::allocate(const Sizes& sizes) {
  if (!error_) return error_;
  if (sizes.table < 64 || (sizes.table & (sizes.table - 1)) != 0) {
    return Status::error(
        fmt::format("grid table size {} is not a power of two >= 64", sizes.table));
  }
  if (Status s = synchronize(); !s) return s;
  cudaSetDevice(ordinal_);
  release_graphs();
  release_buffers();
  sizes_ = sizes;
  host_first_.clear();
  host_body_.clear();
  bodies_fusable_ = false;
  largest_body_ = 0;
  smallest_body_ = 0;
  auto fail = [&](cudaError_t e, const std::string& what) {
    cudaGetLastError();
    release_buffers();
    std::size_t free_bytes = 0, total_bytes = 0;
    cudaMemGetInfo(&free_bytes, &total_bytes);
    return Status::error(fmt::format(
        "cuda ({}): cannot allocate {} for {} particles and {} bodies: {} ({:.2f} GiB of {:.2f} "
        "GiB free)",
        info_.name, what, sizes.particles, sizes.bodies, error_text(e),
        static_cast<double>(free_bytes) / 1073741824.0,
        static_cast<double>(total_bytes) / 1073741824.0));
  };
  for (std::size_t i = 0; i < kBufferCount; ++i) {
    const auto b = static_cast<Buffer>(i);
    const std::size_t bytes = buffer_layout(b, sizes).bytes();
    void* p = nullptr;
    if (cudaError_t e = cudaMalloc(&p, bytes + kGuardBytes); e != cudaSuccess) {
      return fail(e, fmt::format("{} ({} bytes)", buffer_name(b), bytes));
    }
    buffers_[i] = p;
    bytes_[i] = bytes;
    cudaError_t e = cudaMemset(p, 0, bytes);
    if (e == cudaSuccess) e = cudaMemset(static_cast<char*>(p) + bytes, kGuardByte, kGuardBytes);
    if (e != cudaSuccess) return fail(e, buffer_name(b));
  }
  const std::size_t n = std::max<std::size_t>(sizes.particles, 1);
  void* ids = nullptr;
  if (cudaError_t e = cudaMalloc(&ids, n * sizeof(shared::uint)); e != cudaSuccess) {
    return fail(e, "the sort's particle ids");
  }
  ids_ = static_cast<shared::uint*>(ids);
  void* keys = nullptr;
  if (cudaError_t e = cudaMalloc(&keys, n * sizeof(shared::uint)); e != cudaSuccess) {
    return fail(e, "the sort's keys");
  }
  sorted_keys_ = static_cast<shared::uint*>(keys);
  // CUB's temporary storage, once, for the most key bits any table of this size can need.
  const int key_bits = std::bit_width(sizes.table - 1u);
  Result<std::size_t> temp = sort_temp_size(sizes.particles, key_bits);
  if (!temp) return fail(cudaErrorInvalidValue, "(sizing) the sort's temporary storage");
  sort_temp_bytes_ = temp.value();
  if (cudaError_t e = cudaMalloc(&sort_temp_, std::max<std::size_t>(sort_temp_bytes_, 16));
      e != cudaSuccess) {
    return fail(e, fmt::format("the sort's temporary storage ({} bytes)", sort_temp_bytes_));
  }
  if (sizes.impulse != 0) {
    void* listed = nullptr;
    const std::size_t bytes = (std::size_t{sizes.rigid_particles} + 1) * sizeof(shared::uint);
    if (cudaError_t e = cudaMalloc(&listed, bytes); e != cudaSuccess) {
      return fail(e, "the list of particles within reach of an impulse contact");
    }
    impulse_listed_ = static_cast<shared::uint*>(listed);
    if (cudaError_t e = cudaMemset(listed, 0, bytes); e != cudaSuccess) {
      return fail(e, "the list of particles within reach of an impulse contact");
    }
  }
  launch_ids_fill(sizes.particles);
  if (cudaError_t e = cudaGetLastError(); e != cudaSuccess) return fail(e, "the particle ids");
  if (cudaError_t e = cudaStreamSynchronize(stream_); e != cudaSuccess) {
    return fail(e, "the particle ids");
  }
  allocated_ = true;
  return Status::ok();
}

BodyBuffers CudaDevice::body_buffers() const {
  return {buf<shared::uint>(Buffer::BodyFirst),       buf<shared::uint>(Buffer::ParticleBody),
          buf<shared::vec4>(Buffer::ParticleLocal),   buf<shared::vec4>(Buffer::ParticleForce),
          buf<shared::vec4>(Buffer::ParticlePos),     buf<shared::vec4>(Buffer::ParticleVel),
          buf<shared::vec4>(Buffer::BodyPos),         buf<shared::vec4>(Buffer::BodyQuat),
          buf<shared::vec4>(Buffer::BodyVel),         buf<shared::vec4>(Buffer::BodyAngMom),
          buf<shared::vec4>(Buffer::BodyAngVel),      buf<shared::vec4>(Buffer::BodyInvInertia),
          buf<shared::vec4>(Buffer::BodyForce),       buf<shared::vec4>(Buffer::BodyTorque),
          buf<shared::vec4>(Buffer::NeighbourRefPos), buf<shared::uint>(Buffer::NeighbourState)};
}

HaloBodies CudaDevice::halo_bodies() const {
  return {{buf<shared::vec4>(Buffer::BodyPos), buf<shared::vec4>(Buffer::BodyQuat),
           buf<shared::vec4>(Buffer::BodyVel), buf<shared::vec4>(Buffer::BodyAngMom),
           buf<shared::vec4>(Buffer::BodyAngVel)}};
}

ContactInputs CudaDevice::contact_inputs() const {
  return {buf<shared::vec4>(Buffer::ParticlePos),       buf<shared::vec4>(Buffer::ParticleVel),
          buf<shared::uint>(Buffer::ParticleBody),      buf<shared::uint>(Buffer::ParticleMaterial),
          buf<shared::uint>(Buffer::NeighbourList),     buf<shared::uint>(Buffer::NeighbourCount),
          buf<shared::vec4>(Buffer::NeighbourRefPos),   buf<shared::uint>(Buffer::GridOrder),
          buf<shared::uint>(Buffer::GridCellStart),     buf<shared::uint>(Buffer::SortedBody),
          buf<shared::ContactLaw>(Buffer::ContactLaws), buf<shared::PlaneData>(Buffer::Planes)};
}

void CudaDevice::update_fusable() {
  // Bodies of up to this many particles take the fused pass (one thread per body, looping over
  // its particles). Measured on an H100: a win for free spheres (W1), a loss for 15-particle
  // dominoes (W2), whose particles a thread then reads 240 bytes apart from its neighbours'.
  constexpr shared::uint kFusedBodyParticles = 4;
  bodies_fusable_ = false;
  const std::size_t bodies = sizes_.bodies;
  largest_body_ = 0;
  smallest_body_ = 0;
  if (host_first_.size() == bodies + 1 && bodies > 0) {
    smallest_body_ = ~shared::uint{0};
    for (std::size_t b = 0; b < bodies; ++b) {
      const shared::uint n =
          host_first_[b + 1] > host_first_[b] ? host_first_[b + 1] - host_first_[b] : 0u;
      largest_body_ = std::max(largest_body_, n);
      smallest_body_ = std::min(smallest_body_, n);
    }
  }
  if (host_first_.size() != bodies + 1 || host_body_.size() != sizes_.particles) return;
  if (host_first_[0] != 0 || host_first_[bodies] != sizes_.rigid_particles) return;
  for (std::size_t b = 0; b < bodies; ++b) {
    const shared::uint lo = host_first_[b], hi = host_first_[b + 1];
    if (hi < lo || hi - lo > kFusedBodyParticles || hi > sizes_.rigid_particles) return;
    for (shared::uint i = lo; i < hi; ++i) {
      if (host_body_[i] != b) return;
    }
  }
  bodies_fusable_ = true;
}

Status CudaDevice::write(Buffer b, const void* src, std::size_t bytes) {
  const auto i = static_cast<std::size_t>(b);
  if (!allocated_) return Status::error("cuda: write before allocate");
  if (bytes > bytes_[i]) {
    return Status::error(fmt::format("cuda: writing {} bytes into {} of {} bytes", bytes,
                                     buffer_name(b), bytes_[i]));
  }
  if (Status s = flush(); !s) return s;
  if (b == Buffer::BodyFirst || b == Buffer::ParticleBody) {
    std::vector<shared::uint>& host = b == Buffer::BodyFirst ? host_first_ : host_body_;
    host.assign(bytes_[i] / sizeof(shared::uint), 0);
    if (bytes > 0) std::memcpy(host.data(), src, bytes);
    if (bytes != bytes_[i]) host.clear();  // partial writes: contents unknown, never fused
    update_fusable();
  }
  if (bytes == 0) return Status::ok();
  if (Status s = check(cudaMemcpyAsync(buffers_[i], src, bytes, cudaMemcpyHostToDevice, stream_),
                       "cudaMemcpy to the device");
      !s) {
    return s;
  }
  return check(cudaStreamSynchronize(stream_), "cudaMemcpy to the device");
}

Status CudaDevice::write_at(Buffer b, std::size_t offset, const void* src, std::size_t bytes) {
  // The host's mirrors of BodyFirst and ParticleBody are whole-buffer copies: the patched buffer
  // goes through write.
  if (b == Buffer::BodyFirst || b == Buffer::ParticleBody) {
    return Device::write_at(b, offset, src, bytes);
  }
  const auto i = static_cast<std::size_t>(b);
  if (!allocated_) return Status::error("cuda: write before allocate");
  if (offset > bytes_[i] || bytes > bytes_[i] - offset) {
    return Status::error(fmt::format("cuda: writing {} bytes at {} into {} of {} bytes", bytes,
                                     offset, buffer_name(b), bytes_[i]));
  }
  if (Status s = flush(); !s) return s;
  if (bytes == 0) return Status::ok();
  if (Status s = check(cudaMemcpyAsync(static_cast<unsigned char*>(buffers_[i]) + offset, src,
                                       bytes, cudaMemcpyHostToDevice, stream_),
                       "cudaMemcpy to the device");
      !s) {
    return s;
  }
  return check(cudaStreamSynchronize(stream_), "cudaMemcpy to the device");
}

Status CudaDevice::read(Buffer b, void* dst, std::size_t bytes) {
  const auto i = static_cast<std::size_t>(b);
  if (!allocated_) return Status::error("cuda: read before allocate");
  if (bytes > bytes_[i]) {
    return Status::error(fmt::format("cuda: reading {} bytes from {} of {} bytes", bytes,
                                     buffer_name(b), bytes_[i]));
  }
  if (Status s = flush(); !s) return s;
  if (bytes == 0) return synchronize();
  if (Status s = check(cudaMemcpyAsync(dst, buffers_[i], bytes, cudaMemcpyDeviceToHost, stream_),
                       "cudaMemcpy to the host");
      !s) {
    return s;
  }
  return check(cudaStreamSynchronize(stream_), "cudaMemcpy to the host");
}

void* CudaDevice::allocate_host(std::size_t bytes) {
  cudaSetDevice(ordinal_);
  void* memory = nullptr;
  if (cudaMallocHost(&memory, std::max<std::size_t>(bytes, 1)) != cudaSuccess) {
    (void)cudaGetLastError();  // not sticky: the caller falls back or reports it
    return nullptr;
  }
  return memory;
}

void CudaDevice::free_host(void* memory) {
  if (memory != nullptr) cudaFreeHost(memory);
}

Status CudaDevice::synchronize() {
  if (Status s = flush(); !s) return s;
  if (stream_ == nullptr) return error_;
  return check(cudaStreamSynchronize(stream_), "running the queued kernels");
}

Status CudaDevice::check_guards() {
  if (Status s = synchronize(); !s) return s;
  if (!allocated_) return Status::ok();
  unsigned char guard[kGuardBytes];
  for (std::size_t i = 0; i < kBufferCount; ++i) {
    if (Status s = check(cudaMemcpy(guard, static_cast<char*>(buffers_[i]) + bytes_[i], kGuardBytes,
                                    cudaMemcpyDeviceToHost),
                         "reading guard words");
        !s) {
      return s;
    }
    for (unsigned char g : guard) {
      if (g != kGuardByte) {
        return Status::error(fmt::format("cuda: a kernel wrote past the end of {} ({} bytes)",
                                         buffer_name(static_cast<Buffer>(i)), bytes_[i]));
      }
    }
  }
  return Status::ok();
}

}  // namespace motes::cuda
