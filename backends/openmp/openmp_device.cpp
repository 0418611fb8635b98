// OpenMPDevice: buffers, host transfers and timing. Kernels live in one file per family.
#include "openmp_device.h"

#include <fmt/format.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#ifdef MOTES_HAVE_OPENMP
#include <omp.h>
#endif

namespace motes::openmp {

AlignedBuffer::AlignedBuffer(std::size_t bytes)
    : data_(static_cast<std::byte*>(::operator new[](bytes + kPadding, std::align_val_t{64}))),
      size_(bytes) {
  std::memset(data_.get(), 0, bytes);
  std::memset(data_.get() + bytes, kGuardByte, kPadding);
}

bool AlignedBuffer::guard_intact() const {
  if (!data_) return true;
  for (std::size_t i = 0; i < kPadding; ++i) {
    if (static_cast<unsigned char>(data_[size_ + i]) != kGuardByte) return false;
  }
  return true;
}

namespace {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  }
  return "CPU";
}

int default_threads() {
#ifdef MOTES_HAVE_OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

}  // namespace

DeviceInfo describe(int threads) {
  DeviceInfo d;
  d.backend = "openmp";
  d.index = 0;
  d.name = cpu_model();
  const int t = threads > 0 ? threads : default_threads();
#ifdef MOTES_HAVE_OPENMP
  d.detail = fmt::format("{} thread{} (OpenMP {})", t, t == 1 ? "" : "s", _OPENMP);
#else
  d.detail = "1 thread (built without OpenMP)";
#endif
  return d;
}

OpenMPDevice::OpenMPDevice(int threads, int min_parallel)
    : min_parallel_(min_parallel < 0 ? kDefaultMinParallel : min_parallel) {
#ifdef MOTES_HAVE_OPENMP
  threads_ = threads > 0 ? threads : default_threads();
#else
  threads_ = 1;
#endif
  // OpenMP's default thread count follows the machine: fewer threads while other processes keep
  // its CPUs busy (cpu_share.h). An explicit count is kept as asked.
  const char* adapt = std::getenv("MOTES_CPU_ADAPT");
  share_ = CpuShare(threads_, threads <= 0 && !(adapt != nullptr && std::string(adapt) == "0"));
  team_ = share_.team();
  info_ = describe(threads_);
  // contacts_compute's shared pairs: "0" never, "1" always (tests reach both ways), else by the
  // last call's touching entries.
  if (const char* pairs = std::getenv("MOTES_OPENMP_SHARED_PAIRS"); pairs != nullptr) {
    if (std::string(pairs) == "0") shared_pairs_ = SharedPairs::Never;
    if (std::string(pairs) == "1") shared_pairs_ = SharedPairs::Always;
  }
  // contacts_compute's plane masks (plane_masks.cpp): "0" tests every plane (tests compare).
  if (const char* masks = std::getenv("MOTES_OPENMP_PLANE_MASKS"); masks != nullptr) {
    plane_masks_on_ = std::string(masks) != "0";
  }
  if (share_.adapting()) info_.detail += ", fewer while other processes keep the CPUs busy";
}

std::uint64_t OpenMPDevice::required_bytes(const Sizes& sizes) const {
  // Every buffer with its padding, and the radix sort's keys, ids and per-thread histograms.
  return buffers_bytes(sizes) + kBufferCount * AlignedBuffer::kPadding +
         std::uint64_t{sizes.particles} * 3 * sizeof(std::uint32_t) +
         static_cast<std::uint64_t>(threads_) * 2048 * sizeof(std::uint32_t);
}

std::uint64_t OpenMPDevice::available_bytes() const {
  // MemAvailable of /proc/meminfo: what the kernel can give without swapping.
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::uint64_t kib = 0;
  std::string unit;
  while (in >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024;
  }
  return UINT64_MAX;  // unknown: let the allocation itself decide
}

Status OpenMPDevice::allocate(const Sizes& sizes) {
  if (sizes.table < 64 || (sizes.table & (sizes.table - 1)) != 0) {
    return Status::error(
        fmt::format("grid table size {} is not a power of two >= 64", sizes.table));
  }
  try {
    std::vector<AlignedBuffer> fresh;
    fresh.reserve(kBufferCount);
    for (std::size_t i = 0; i < kBufferCount; ++i) {
      fresh.emplace_back(buffer_layout(static_cast<Buffer>(i), sizes).bytes());
    }
    sorted_keys_.assign(sizes.particles, 0);
    keys_tmp_.assign(sizes.particles, 0);
    ids_tmp_.assign(sizes.particles, 0);
    buffers_ = std::move(fresh);
    forget_impulse_passes();
    impulse_mirror_.clear();
    contact_pairs_ready_ = false;
    plane_masks_ready_ = false;
  } catch (const std::bad_alloc&) {
    return Status::error(
        fmt::format("out of host memory allocating {} particles and {} bodies on the openmp device",
                    sizes.particles, sizes.bodies));
  }
  sizes_ = sizes;
  return Status::ok();
}

Status OpenMPDevice::write(Buffer b, const void* src, std::size_t bytes) {
  const auto i = static_cast<std::size_t>(b);
  if (i >= buffers_.size()) return Status::error("openmp: write before allocate");
  if (bytes > buffers_[i].size()) {
    return Status::error(fmt::format("openmp: writing {} bytes into {} of {} bytes", bytes,
                                     buffer_name(b), buffers_[i].size()));
  }
  impulse_acc_flush();
  if (bytes > 0) std::memcpy(buffers_[i].data(), src, bytes);
  wrote(b);
  return Status::ok();
}

Status OpenMPDevice::write_at(Buffer b, std::size_t offset, const void* src, std::size_t bytes) {
  const auto i = static_cast<std::size_t>(b);
  if (i >= buffers_.size()) return Status::error("openmp: write before allocate");
  if (offset > buffers_[i].size() || bytes > buffers_[i].size() - offset) {
    return Status::error(fmt::format("openmp: writing {} bytes at {} into {} of {} bytes", bytes,
                                     offset, buffer_name(b), buffers_[i].size()));
  }
  impulse_acc_flush();
  if (bytes > 0) std::memcpy(buffers_[i].data() + offset, src, bytes);
  wrote(b);
  return Status::ok();
}

void OpenMPDevice::wrote(Buffer b) {
  impulse_contacts_ready_ = false;  // what the kept contact frames were made from may have changed
  impulse_points_ready_ = false;    // and the particles' places (poses, offsets)
  plane_masks_ready_ = false;       // the places, radii or planes they were made from
  if (b == Buffer::NeighbourList || b == Buffer::NeighbourCount) {
    impulse_mirror_.clear();
    contact_pairs_ready_ = false;
  }
  // New positions or lists: the last counting pass no longer says who touches whom.
  if (b == Buffer::ParticlePos || b == Buffer::NeighbourList || b == Buffer::NeighbourCount) {
    forget_impulse_passes();
  }
}

Status OpenMPDevice::read(Buffer b, void* dst, std::size_t bytes) {
  const auto i = static_cast<std::size_t>(b);
  if (i >= buffers_.size()) return Status::error("openmp: read before allocate");
  if (bytes > buffers_[i].size()) {
    return Status::error(fmt::format("openmp: reading {} bytes from {} of {} bytes", bytes,
                                     buffer_name(b), buffers_[i].size()));
  }
  impulse_acc_flush();
  if (bytes > 0) std::memcpy(dst, buffers_[i].data(), bytes);
  return Status::ok();
}

void OpenMPDevice::enqueue(Kernel k, const shared::StepParams& p) {
  team_ = share_.team();
  // Between the sweeps of a substep only they and impulses_apply run; anything else sees the
  // contacts' accumulated impulses in ContactImpulse.
  if (k != Kernel::ImpulsesCompute && k != Kernel::ImpulsesApply) impulse_acc_flush();
  switch (k) {
#define MOTES_FAMILY_CASE(E, name, reads, writes) \
  case Kernel::E:                                 \
    name(p);                                      \
    break;
    MOTES_KERNELS(MOTES_FAMILY_CASE)
#undef MOTES_FAMILY_CASE
    case Kernel::Count:
      break;
  }
}

void OpenMPDevice::forget_impulse_passes() {
  impulse_mirror_.clear();
  impulse_touches_.clear();
  impulse_active_.clear();
  impulse_body_active_.clear();
  impulse_frames_.clear();
  impulse_points_.clear();
  impulse_points_ready_ = false;
  impulse_contacts_ready_ = false;
  impulse_acc_pending_ = false;  // written back already, or its buffer made anew (allocate)
}

Status OpenMPDevice::check_guards() {
  for (std::size_t i = 0; i < buffers_.size(); ++i) {
    if (!buffers_[i].guard_intact()) {
      return Status::error(fmt::format("openmp: a kernel wrote past the end of {} ({} bytes)",
                                       buffer_name(static_cast<Buffer>(i)), buffers_[i].size()));
    }
  }
  return Status::ok();
}

ContactInputs OpenMPDevice::contact_inputs() {
  return {buf<shared::vec4>(Buffer::ParticlePos),       buf<shared::vec4>(Buffer::ParticleVel),
          buf<shared::uint>(Buffer::ParticleBody),      buf<shared::uint>(Buffer::ParticleMaterial),
          buf<shared::uint>(Buffer::NeighbourList),     buf<shared::uint>(Buffer::NeighbourCount),
          buf<shared::vec4>(Buffer::NeighbourRefPos),   buf<shared::uint>(Buffer::GridOrder),
          buf<shared::uint>(Buffer::GridCellStart),     buf<shared::uint>(Buffer::SortedBody),
          buf<shared::ContactLaw>(Buffer::ContactLaws), buf<shared::PlaneData>(Buffer::Planes)};
}

void OpenMPDevice::record(Kernel k, std::chrono::steady_clock::time_point start) {
  if (!timing_) return;
  const auto i = static_cast<std::size_t>(k);
  times_.seconds[i] +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  times_.launches[i] += 1;
}

}  // namespace motes::openmp
