// The backend registry: which backends this binary has, their devices, and opening one.
// Preference order for "auto": cuda, vulkan, openmp.
#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

#include "motes/devices.h"
#include "openmp/openmp_device.h"

namespace motes {

namespace {

constexpr const char* kNotImplemented =
    "not built: this version of motes has no {} backend yet (planned; see docs/architecture.md)";

}  // namespace

std::vector<BackendReport> list_backends() {
  std::vector<BackendReport> out;
  for (const char* name : {"cuda", "vulkan"}) {
    BackendReport r;
    r.backend = name;
    r.compiled = false;
    r.unavailable_reason = fmt::format(fmt::runtime(kNotImplemented), name);
    out.push_back(std::move(r));
  }
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
  std::string chosen = backend;
  if (backend == "auto") {
    for (const auto& r : list_backends()) {
      if (!r.devices.empty()) {
        chosen = r.backend;
        break;
      }
    }
  }
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
