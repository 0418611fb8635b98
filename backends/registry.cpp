// The backend registry: which backends this binary has, their devices, and opening one.
// "auto" picks a CUDA GPU, else a Vulkan GPU, else the CPU backend (a CPU Vulkan driver such as
// lavapipe is slower than OpenMP on the same cores).
#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

#include "motes/devices.h"
#include "openmp/openmp_device.h"
#ifdef MOTES_HAVE_CUDA
#include "cuda/cuda_backend.h"
#endif
#ifdef MOTES_HAVE_VULKAN
#include "vulkan/vulkan_backend.h"
#endif

namespace motes {

namespace {

BackendReport cuda_report() {
  BackendReport r;
  r.backend = "cuda";
#ifdef MOTES_HAVE_CUDA
  r.compiled = true;
  cuda::Listing l = cuda::list_devices();
  r.devices = std::move(l.devices);
  r.unavailable_reason = l.reason;
#else
  r.unavailable_reason = MOTES_CUDA_STATUS;
#endif
  return r;
}

BackendReport vulkan_report() {
  BackendReport r;
  r.backend = "vulkan";
#ifdef MOTES_HAVE_VULKAN
  r.compiled = true;
  vulkan::Listing l = vulkan::list_devices();
  r.devices = std::move(l.devices);
  r.unavailable_reason = l.reason;
#else
  r.unavailable_reason = MOTES_VULKAN_STATUS;
#endif
  return r;
}

/// "auto": a CUDA GPU, else a Vulkan GPU, else the CPU backend (OpenMP beats lavapipe on the
/// same cores).
std::string auto_backend() {
#ifdef MOTES_HAVE_CUDA
  if (!cuda::list_devices().devices.empty()) return "cuda";
#endif
#ifdef MOTES_HAVE_VULKAN
  const vulkan::Listing l = vulkan::list_devices();
  if (l.preferred >= 0 && l.preferred_is_gpu) return "vulkan";
#endif
  return "openmp";
}

}  // namespace

std::vector<BackendReport> list_backends() {
  std::vector<BackendReport> out;
  out.push_back(cuda_report());
  out.push_back(vulkan_report());
  BackendReport cpu;
  cpu.backend = "openmp";
  cpu.compiled = true;
  cpu.devices.push_back(openmp::describe(0));
  out.push_back(std::move(cpu));
  return out;
}

Result<std::unique_ptr<Device>> open_device(const std::string& backend, int index,
                                            const DeviceOptions& options) {
  if (options.cpu_threads < 0) {
    return Status::error(fmt::format("cpu threads must be >= 0, got {}", options.cpu_threads));
  }
  const std::string chosen = backend == "auto" ? auto_backend() : backend;
#ifdef MOTES_HAVE_CUDA
  if (chosen == "cuda") return cuda::open_device(index);
#endif
#ifdef MOTES_HAVE_VULKAN
  if (chosen == "vulkan") return vulkan::open_device(index);
#endif
  if (chosen == "openmp") {
    if (index > 0) {
      return Status::error(
          fmt::format("backend openmp has one device (index 0); device {} does not exist", index));
    }
    std::unique_ptr<Device> d =
        std::make_unique<openmp::OpenMPDevice>(options.cpu_threads, options.cpu_min_parallel);
    return d;
  }
  for (const auto& r : list_backends()) {
    if (r.backend == chosen) {
      return Status::error(
          fmt::format("backend {} is unavailable: {}", chosen, r.unavailable_reason));
    }
  }
  return Status::error(
      fmt::format("unknown backend '{}' (choose auto, openmp, cuda or vulkan)", backend));
}

}  // namespace motes
