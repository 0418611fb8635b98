// A CUDA simulation's particles copied into memory another API exported (motes/cuda_interop.h).
#include "motes/cuda_interop.h"

#include <fmt/format.h>

#include "cuda_backend.h"
#include "cuda_device.h"

namespace motes {

namespace {

Result<cuda::CudaDevice*> cuda_device_of(Simulation& sim, const char* what) {
  auto* device = dynamic_cast<cuda::CudaDevice*>(&sim.device());
  if (device == nullptr) {
    const DeviceInfo& info = sim.device().info();
    return Status::error(fmt::format("{}: the simulation runs on {} ({}), not on CUDA", what,
                                     info.backend, info.name));
  }
  return device;
}

}  // namespace

Status cuda::CudaDevice::copy_particles_to(void* positions, void* velocities, std::size_t count) {
  if (Status s = synchronize(); !s) return s;
  const std::size_t bytes = count * sizeof(shared::vec4);
  if (count == 0) return Status::ok();
  if (Status s = check(cudaMemcpyAsync(positions, buf<shared::vec4>(Buffer::ParticlePos), bytes,
                                       cudaMemcpyDeviceToDevice, stream_),
                       "copying the positions out");
      !s) {
    return s;
  }
  if (velocities != nullptr) {
    if (Status s = check(cudaMemcpyAsync(velocities, buf<shared::vec4>(Buffer::ParticleVel), bytes,
                                         cudaMemcpyDeviceToDevice, stream_),
                         "copying the velocities out");
        !s) {
      return s;
    }
  }
  return check(cudaStreamSynchronize(stream_), "copying the particles out");
}

Result<std::array<std::uint8_t, 16>> cuda_device_uuid(Simulation& sim) {
  Result<cuda::CudaDevice*> device = cuda_device_of(sim, "cuda_device_uuid");
  if (!device) return device.status();
  return device.value()->uuid();
}

struct CudaImportedMemory::Impl {
  int ordinal = 0;
  cudaExternalMemory_t memory = nullptr;
  void* pointer = nullptr;
  std::uint64_t bytes = 0;
};

CudaImportedMemory::CudaImportedMemory(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

CudaImportedMemory::~CudaImportedMemory() {
  cudaSetDevice(impl_->ordinal);
  if (impl_->pointer != nullptr) cudaFree(impl_->pointer);
  if (impl_->memory != nullptr) cudaDestroyExternalMemory(impl_->memory);
}

Result<std::unique_ptr<CudaImportedMemory>> CudaImportedMemory::import_fd(Simulation& sim, int fd,
                                                                          std::uint64_t bytes,
                                                                          bool dedicated) {
  Result<cuda::CudaDevice*> device = cuda_device_of(sim, "CudaImportedMemory::import_fd");
  if (!device) return device.status();
  auto impl = std::make_unique<Impl>();
  impl->ordinal = device.value()->ordinal();
  impl->bytes = bytes;
  auto refused = [&](const char* what, cudaError_t e) {
    return Status::error(fmt::format("CudaImportedMemory::import_fd ({}): {} failed: {}",
                                     device.value()->info().name, what, cuda::error_text(e)));
  };
  if (cudaError_t e = cudaSetDevice(impl->ordinal); e != cudaSuccess) {
    return refused("cudaSetDevice", e);
  }
  cudaExternalMemoryHandleDesc desc{};
  desc.type = cudaExternalMemoryHandleTypeOpaqueFd;
  desc.handle.fd = fd;
  desc.size = bytes;
  desc.flags = dedicated ? cudaExternalMemoryDedicated : 0;
  if (cudaError_t e = cudaImportExternalMemory(&impl->memory, &desc); e != cudaSuccess) {
    impl->memory = nullptr;
    return refused("cudaImportExternalMemory", e);
  }
  // From here CUDA owns the descriptor: the destructor releases both.
  std::unique_ptr<CudaImportedMemory> out(new CudaImportedMemory(std::move(impl)));
  cudaExternalMemoryBufferDesc buffer{};
  buffer.offset = 0;
  buffer.size = bytes;
  if (cudaError_t e =
          cudaExternalMemoryGetMappedBuffer(&out->impl_->pointer, out->impl_->memory, &buffer);
      e != cudaSuccess) {
    out->impl_->pointer = nullptr;
    return refused("cudaExternalMemoryGetMappedBuffer", e);
  }
  return out;
}

Status CudaImportedMemory::copy_particles(Simulation& sim, std::uint64_t positions_offset,
                                          std::optional<std::uint64_t> velocities_offset) {
  Result<cuda::CudaDevice*> device = cuda_device_of(sim, "CudaImportedMemory::copy_particles");
  if (!device) return device.status();
  if (device.value()->ordinal() != impl_->ordinal) {
    return Status::error(
        "CudaImportedMemory::copy_particles: the simulation runs on another GPU than the memory");
  }
  const std::uint64_t bytes = std::uint64_t{sim.particle_count()} * sizeof(shared::vec4);
  for (std::optional<std::uint64_t> offset : {std::optional(positions_offset), velocities_offset}) {
    if (offset && (*offset > impl_->bytes || bytes > impl_->bytes - *offset)) {
      return Status::error(fmt::format(
          "CudaImportedMemory::copy_particles: {} bytes at offset {} pass the end of the {} "
          "imported",
          bytes, *offset, impl_->bytes));
    }
  }
  auto* base = static_cast<unsigned char*>(impl_->pointer);
  return device.value()->copy_particles_to(base + positions_offset,
                                           velocities_offset ? base + *velocities_offset : nullptr,
                                           sim.particle_count());
}

}  // namespace motes
