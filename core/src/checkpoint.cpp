// Checkpoints (docs/reliability.md, "Checkpoint and resume"): everything that defines the future of
// a run, as raw bits, in one file written atomically.
//
// Version 3, in the machine's byte order (little-endian on every supported machine):
//   header (96 bytes): magic "MOTESCK1", version, header bytes, file bytes, step, time, setup hash,
//     scene hash, particles, scene bodies, rigid bodies, rigid particles, hash table size T,
//     neighbour capacity K, clusters, section count, run record bytes;
//   run record: the backend, then CheckpointRun (strings as u32 length + bytes; the extension, as
//     u64 length + bytes, only when it is not empty);
//   sections: {the buffer's name (buffer_name, 32 bytes padded with zeros), u32 element bytes,
//     u32 0, u64 bytes, the buffer's first `bytes` bytes}, one per buffer of state_buffers(), in
//     that order, in the device's order (the same on every backend): 18 (17 in files written
//     before BodyPosLow, still read), and PartitionRefPos after them for one rank of a run over
//     MPI ranks;
//   checksum: FNV-1a 64 of every byte before it.
// Version 2 (still read): the same, but each section starts {u32 buffer, u32 element bytes, u64
// bytes} with the buffer's number in the Buffer enum as it was then (kVersion2Buffers), so that
// the enum can be regrouped.
// Version 1 (still read by load_state): a 48-byte header {magic, version, particles, bodies,
// reserved, step, time, payload bytes}, the scene-ordered body and particle arrays of a Snapshot,
// and the FNV-1a 64 of that payload.
#include "motes/checkpoint.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "motes/backend/bytes.h"
#include "motes/simulation.h"
#include "shared/neighbours.h"
#include "shared/shape_matching.h"

namespace motes {

namespace {

constexpr std::array<char, 8> kMagic = {'M', 'O', 'T', 'E', 'S', 'C', 'K', '1'};
constexpr std::size_t kHeaderBytes = 96;
constexpr std::size_t kSectionHeaderBytes = 48;
constexpr std::size_t kVersion2SectionHeaderBytes = 16;
constexpr std::size_t kSectionNameBytes = 32;

/// Version 2's section numbers: the Buffer enum as it was when version 2 was written.
constexpr std::array<const char*, 45> kVersion2Buffers = {
    "ParticlePos",     "ParticleVel",    "ParticleLocal",   "ParticleBody",    "ParticleMaterial",
    "ParticleForce",   "BodyPos",        "BodyQuat",        "BodyVel",         "BodyAngMom",
    "BodyAngVel",      "BodyInvInertia", "BodyForce",       "BodyTorque",      "BodyFirst",
    "GridBucket",      "GridOrder",      "GridCellStart",   "SortedPos",       "SortedBody",
    "NeighbourList",   "NeighbourCount", "NeighbourRefPos", "NeighbourState",  "ContactLaws",
    "Planes",          "Constraints",    "Clusters",        "ClusterMembers",  "ClusterFrames",
    "ClusterGather",   "ParticleMoment", "BodyVelStart",    "BodyAngVelStart", "ContactImpulse",
    "ImpulseStamp",    "MotionCheck",    "LinkExclusions",  "HaloIndex",       "HaloData",
    "PartitionRefPos", "PartitionCheck", "BodyVelPush",     "BodyAngMomPush",  "EnergyPartials"};
constexpr std::size_t kV1HeaderBytes = 48;

/// The device buffers a checkpoint holds: every buffer that a step reads before it writes it
/// (docs/architecture.md, "The step"). Not here: the fixed inputs (covered by the setup hash),
/// forces (written before they are read in every substep) and GridBucket and SortedPos (read only
/// by the list build that rewrites them).
/// The impulse contacts' history (ContactImpulse, ImpulseStamp) came later: files written before
/// it have kSectionsBeforeImpulses sections and are read when those buffers are empty. The
/// centres' parts below their floats (BodyPosLow) came last: files without that section are
/// read with zeros there.
constexpr std::array<Buffer, 18> kStateBuffers = {
    Buffer::ParticlePos,     Buffer::ParticleVel,    Buffer::BodyPos,       Buffer::BodyQuat,
    Buffer::BodyVel,         Buffer::BodyAngMom,     Buffer::BodyAngVel,    Buffer::ClusterFrames,
    Buffer::NeighbourRefPos, Buffer::NeighbourState, Buffer::NeighbourList, Buffer::NeighbourCount,
    Buffer::GridOrder,       Buffer::GridCellStart,  Buffer::SortedBody,    Buffer::ContactImpulse,
    Buffer::ImpulseStamp,    Buffer::BodyPosLow,
};
constexpr std::size_t kSectionsBeforeImpulses = 15;
// load_state checks these sections by position.
constexpr std::size_t kPosSection = 0;
constexpr std::size_t kVelSection = 1;
constexpr std::size_t kListSection = 10;
constexpr std::size_t kCountSection = 11;
constexpr std::size_t kOrderSection = 12;
constexpr std::size_t kStartSection = 13;
static_assert(kStateBuffers[kPosSection] == Buffer::ParticlePos &&
              kStateBuffers[kVelSection] == Buffer::ParticleVel &&
              kStateBuffers[kListSection] == Buffer::NeighbourList &&
              kStateBuffers[kCountSection] == Buffer::NeighbourCount &&
              kStateBuffers[kOrderSection] == Buffer::GridOrder &&
              kStateBuffers[kStartSection] == Buffer::GridCellStart);

/// The sections of a simulation's checkpoint: kStateBuffers, then, for one rank of a run over MPI
/// ranks (Sizes::partition), PartitionRefPos: the positions at the ranks' last partition, from
/// which particles_displacement decides the next one. A single process's checkpoint has no such
/// section, so its format is what it was before runs over ranks.
std::vector<Buffer> state_buffers(const Sizes& sizes) {
  std::vector<Buffer> out(kStateBuffers.begin(), kStateBuffers.end());
  if (sizes.partition != 0) out.push_back(Buffer::PartitionRefPos);
  return out;
}

/// The fixed part of a version 2 file.
struct Header {
  std::array<char, 8> magic{};
  std::uint32_t version = 0;
  std::uint32_t header_bytes = 0;
  std::uint64_t file_bytes = 0;
  std::uint64_t step = 0;
  double time = 0.0;
  std::uint64_t setup_hash = 0;
  std::uint64_t scene_hash = 0;
  std::uint32_t particles = 0;
  std::uint32_t bodies = 0;
  std::uint32_t rigid_bodies = 0;
  std::uint32_t rigid_particles = 0;
  std::uint32_t table = 0;
  std::uint32_t neighbour_capacity = 0;
  std::uint32_t clusters = 0;
  std::uint32_t section_count = 0;
  std::uint64_t record_bytes = 0;
};
static_assert(sizeof(Header) == kHeaderBytes, "checkpoint header layout");

/// Version 1's header.
struct HeaderV1 {
  std::array<char, 8> magic;
  std::uint32_t version;
  std::uint32_t particles;
  std::uint32_t bodies;
  std::uint32_t reserved;
  std::uint64_t step;
  double time;
  std::uint64_t payload_bytes;
};
static_assert(sizeof(HeaderV1) == kV1HeaderBytes, "checkpoint version 1 header layout");

using detail::ByteReader;
using detail::ByteWriter;

std::vector<unsigned char> encode_record(const std::string& backend, const CheckpointRun& run) {
  ByteWriter w;
  w.str(backend);
  w.str(run.scene_path);
  w.str(run.scene_file);
  w.put<std::uint64_t>(run.scene_hash);
  w.str(run.output_dir);
  w.str(run.output_format);
  w.put<std::uint64_t>(run.every);
  w.put<std::uint64_t>(run.total_steps);
  w.put<std::uint64_t>(run.checkpoint_every);
  w.str(run.checkpoint_dir);
  w.put<std::uint64_t>(run.series.particles_csv_bytes);
  w.put<std::uint64_t>(run.series.bodies_csv_bytes);
  w.put<std::uint64_t>(run.series.frame_times.size());
  for (const double t : run.series.frame_times) w.put<double>(t);
  // Only when there is one: a single process's record is what it was before extensions.
  if (!run.extension.empty()) {
    w.put<std::uint64_t>(run.extension.size());
    w.raw(run.extension.data(), run.extension.size());
  }
  return std::move(w.bytes);
}

bool decode_record(const unsigned char* p, std::size_t n, CheckpointInfo& info) {
  ByteReader r(p, n);
  CheckpointRun& run = info.run;
  info.backend = r.str();
  run.scene_path = r.str();
  run.scene_file = r.str();
  run.scene_hash = r.get<std::uint64_t>();
  run.output_dir = r.str();
  run.output_format = r.str();
  run.every = r.get<std::uint64_t>();
  run.total_steps = r.get<std::uint64_t>();
  run.checkpoint_every = r.get<std::uint64_t>();
  run.checkpoint_dir = r.str();
  run.series.particles_csv_bytes = r.get<std::uint64_t>();
  run.series.bodies_csv_bytes = r.get<std::uint64_t>();
  const std::uint64_t frames = r.get<std::uint64_t>();
  if (r.bad || frames > r.left() / sizeof(double)) return false;
  run.series.frame_times.resize(frames);
  for (double& t : run.series.frame_times) t = r.get<double>();
  if (!r.bad && r.left() > 0) {
    const std::uint64_t extension = r.get<std::uint64_t>();
    if (r.bad || extension > r.left()) return false;
    run.extension.resize(static_cast<std::size_t>(extension));
    r.raw(run.extension.data(), run.extension.size());
  }
  return !r.bad && r.left() == 0;
}

/// `text` with every byte outside printable ASCII shown as '?', for messages.
std::string printable(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (c < 0x20 || c > 0x7e) c = '?';
  }
  return out;
}

/// One section of a parsed version 2 or 3 file.
struct Section {
  Buffer buffer = Buffer::Count;
  std::uint32_t element_bytes = 0;
  std::size_t offset = 0;  ///< of its bytes in the file
  std::size_t bytes = 0;
};

/// A checked version 2 file, or a version 1 file's info.
struct Parsed {
  Header header;
  CheckpointInfo info;
  std::vector<Section> sections;
};

Result<std::vector<unsigned char>> read_whole_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return Status::error(fmt::format("{}: cannot read checkpoint: is a directory", path));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return Status::error(fmt::format("{}: cannot open checkpoint: {}", path, std::strerror(errno)));
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    return Status::error(fmt::format("{}: cannot read checkpoint: {}", path, std::strerror(errno)));
  }
  const std::string s = std::move(text).str();
  return std::vector<unsigned char>(s.begin(), s.end());
}

/// Magic, version, size and checksum, then the record and the section table. Version 1 files get
/// their magic, size and payload hash checked and their header returned in `info`.
Result<Parsed> parse(const std::string& path, const std::vector<unsigned char>& bytes) {
  Parsed out;
  const std::size_t size = bytes.size();
  if (size < 12 || std::memcmp(bytes.data(), kMagic.data(), kMagic.size()) != 0) {
    return Status::error(fmt::format(
        "{}: not a motes checkpoint (it does not start with \"MOTESCK1\"; {} bytes)", path, size));
  }
  std::uint32_t version = 0;
  std::memcpy(&version, bytes.data() + 8, sizeof version);
  out.info.version = version;
  out.info.file_bytes = size;
  if (version == 1) {
    HeaderV1 h{};
    if (size < kV1HeaderBytes + 8) {
      return Status::error(fmt::format("{}: truncated checkpoint ({} bytes)", path, size));
    }
    std::memcpy(&h, bytes.data(), sizeof h);
    if (h.payload_bytes != size - kV1HeaderBytes - 8) {
      return Status::error(
          fmt::format("{}: truncated or corrupt checkpoint ({} bytes; its header says {})", path,
                      size, h.payload_bytes + kV1HeaderBytes + 8));
    }
    std::uint64_t stored = 0;
    std::memcpy(&stored, bytes.data() + size - 8, sizeof stored);
    if (stored != fnv1a64(bytes.data() + kV1HeaderBytes, size - kV1HeaderBytes - 8)) {
      return Status::error(fmt::format("{}: corrupt checkpoint (checksum mismatch)", path));
    }
    out.info.step = h.step;
    out.info.time = h.time;
    out.info.particles = h.particles;
    out.info.bodies = h.bodies;
    out.info.checksum = stored;
    return out;
  }
  if (version != 2 && version != kCheckpointVersion) {
    return Status::error(
        fmt::format("{}: checkpoint format version {}; this motes reads versions 1 to {}", path,
                    version, kCheckpointVersion));
  }
  if (size < kHeaderBytes + 8) {
    return Status::error(
        fmt::format("{}: truncated checkpoint ({} bytes, less than its {}-byte header)", path, size,
                    kHeaderBytes + 8));
  }
  Header& h = out.header;
  std::memcpy(&h, bytes.data(), sizeof h);
  if (h.file_bytes > size) {
    return Status::error(
        fmt::format("{}: truncated checkpoint ({} of {} bytes)", path, size, h.file_bytes));
  }
  if (h.file_bytes != size || h.header_bytes != kHeaderBytes) {
    return Status::error(fmt::format(
        "{}: corrupt checkpoint ({} bytes, but its header says {} with a {}-byte header)", path,
        size, h.file_bytes, h.header_bytes));
  }
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + size - 8, sizeof stored);
  const std::uint64_t computed = fnv1a64(bytes.data(), size - 8);
  if (stored != computed) {
    return Status::error(fmt::format(
        "{}: corrupt checkpoint (checksum mismatch: stored {:016x}, computed {:016x}): the file "
        "was changed or damaged after it was written",
        path, stored, computed));
  }
  // The checksum is right: what follows fails only for a file made to pass it.
  const auto corrupt = [&](const char* what) {
    return Status::error(fmt::format("{}: corrupt checkpoint ({})", path, what));
  };
  const std::size_t body_end = size - 8;
  if (h.record_bytes > body_end - kHeaderBytes) return corrupt("run record size");
  if (!decode_record(bytes.data() + kHeaderBytes, h.record_bytes, out.info)) {
    return corrupt("run record");
  }
  std::size_t at = kHeaderBytes + h.record_bytes;
  if (h.section_count > kStateBuffers.size() * 4) return corrupt("section count");
  const std::size_t section_header =
      version == 2 ? kVersion2SectionHeaderBytes : kSectionHeaderBytes;
  for (std::uint32_t k = 0; k < h.section_count; ++k) {
    if (body_end - at < section_header) return corrupt("section table");
    Section s;
    std::uint64_t n = 0;
    const unsigned char* entry = bytes.data() + at;
    if (version == 2) {
      std::uint32_t number = 0;
      std::memcpy(&number, entry, 4);
      if (number >= kVersion2Buffers.size()) return corrupt("a section's buffer number");
      s.buffer = buffer_from_name(kVersion2Buffers[number]);
      std::memcpy(&s.element_bytes, entry + 4, 4);
      std::memcpy(&n, entry + 8, 8);
    } else {
      const char* name = reinterpret_cast<const char*>(entry);
      const std::string_view named(name, strnlen(name, kSectionNameBytes));
      s.buffer = buffer_from_name(named);
      if (s.buffer == Buffer::Count) {
        return Status::error(fmt::format(
            "{}: corrupt checkpoint (a section of unknown buffer '{}')", path, printable(named)));
      }
      std::memcpy(&s.element_bytes, entry + kSectionNameBytes, 4);
      std::memcpy(&n, entry + kSectionNameBytes + 8, 8);
    }
    at += section_header;
    if (n > body_end - at) return corrupt("section size");
    s.offset = at;
    s.bytes = static_cast<std::size_t>(n);
    at += s.bytes;
    out.sections.push_back(s);
  }
  if (at != body_end) return corrupt("bytes after the last section");
  out.info.step = h.step;
  out.info.time = h.time;
  out.info.particles = h.particles;
  out.info.bodies = h.bodies;
  out.info.setup_hash = h.setup_hash;
  out.info.checksum = stored;
  out.info.run.scene_hash = h.scene_hash;
  return out;
}

/// A file written through a POSIX descriptor, hashing every byte; errors name the file.
class HashedFile {
 public:
  explicit HashedFile(std::string path) : path_(std::move(path)) {}
  HashedFile(const HashedFile&) = delete;
  HashedFile& operator=(const HashedFile&) = delete;
  ~HashedFile() {
    if (fd_ >= 0) ::close(fd_);
  }

  Status open() {
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) return error("create");
    return Status::ok();
  }
  Status write(const void* data, std::size_t n, bool hashed = true) {
    if (hashed) hash_ = fnv1a64(data, n, hash_);
    const auto* p = static_cast<const unsigned char*>(data);
    while (n > 0) {
      const ::ssize_t w = ::write(fd_, p, n);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) return error("write");
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    return Status::ok();
  }
  /// fsync, then close.
  Status sync_and_close() {
    if (::fsync(fd_) != 0) return error("flush (fsync)");
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) return error("close");
    return Status::ok();
  }
  [[nodiscard]] std::uint64_t hash() const { return hash_; }

 private:
  Status error(const char* what) const {
    return Status::error(
        fmt::format("cannot {} checkpoint '{}': {}", what, path_, std::strerror(errno)));
  }
  std::string path_;
  int fd_ = -1;
  std::uint64_t hash_ = fnv1a64(nullptr, 0);
};

/// fsync on the directory that holds `path`, so that a rename in it is on the disk.
Status sync_directory_of(const std::string& path) {
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    return Status::error(fmt::format("cannot open directory '{}' to flush it: {}", dir.string(),
                                     std::strerror(errno)));
  }
  const int r = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  // Some file systems cannot fsync a directory (EINVAL): the rename is then as safe as they make
  // it.
  if (r != 0 && error != EINVAL) {
    return Status::error(
        fmt::format("cannot flush directory '{}': {}", dir.string(), std::strerror(error)));
  }
  return Status::ok();
}

/// The snapshot's arrays in the order a version 1 payload stores them.
std::array<std::vector<shared::vec4>*, 7> payload_arrays_v1(Snapshot& s) {
  return {&s.body_pos,    &s.body_quat,    &s.body_vel,    &s.body_angmom,
          &s.body_angvel, &s.particle_pos, &s.particle_vel};
}

}  // namespace

std::uint64_t fnv1a64(const void* data, std::size_t bytes, std::uint64_t seed) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t h = seed;
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

Result<std::uint64_t> scene_file_hash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::error(fmt::format("{}: cannot open: {}", path, std::strerror(errno)));
  std::uint64_t h = fnv1a64(nullptr, 0);
  std::vector<char> buf(std::size_t{1} << 16);
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    h = fnv1a64(buf.data(), static_cast<std::size_t>(in.gcount()), h);
  }
  if (in.bad())
    return Status::error(fmt::format("{}: cannot read: {}", path, std::strerror(errno)));
  return h;
}

std::vector<unsigned char> encode_checkpoint_run(const std::string& backend,
                                                 const CheckpointRun& run) {
  return encode_record(backend, run);
}

bool decode_checkpoint_run(const unsigned char* data, std::size_t bytes, std::string& backend,
                           CheckpointRun& run) {
  CheckpointInfo info;
  if (!decode_record(data, bytes, info)) return false;
  backend = std::move(info.backend);
  run = std::move(info.run);
  return true;
}

Result<CheckpointInfo> read_checkpoint_info(const std::string& path) {
  Result<std::vector<unsigned char>> bytes = read_whole_file(path);
  if (!bytes) return bytes.status();
  Result<Parsed> parsed = parse(path, bytes.value());
  if (!parsed) return parsed.status();
  return parsed->info;
}

Status Simulation::save_state(const std::string& path) { return save_state(path, CheckpointRun{}); }

Status Simulation::save_state(const std::string& path, const CheckpointRun& run) {
  if (Status s = device_->synchronize(); !s) return s;
  const std::vector<unsigned char> record = encode_record(device_->info().backend, run);
  Header h;
  h.magic = kMagic;
  h.version = kCheckpointVersion;
  h.header_bytes = kHeaderBytes;
  h.step = steps_;
  h.time = time_;
  h.setup_hash = setup_hash_;
  h.scene_hash = run.scene_hash;
  h.particles = sizes_.particles;
  h.bodies = static_cast<std::uint32_t>(bodies_.size());
  h.rigid_bodies = sizes_.bodies;
  h.rigid_particles = sizes_.rigid_particles;
  h.table = sizes_.table;
  h.neighbour_capacity = sizes_.neighbour_capacity;
  h.clusters = sizes_.clusters;
  const std::vector<Buffer> buffers = state_buffers(sizes_);
  h.section_count = static_cast<std::uint32_t>(buffers.size());
  h.record_bytes = record.size();
  std::uint64_t file_bytes = kHeaderBytes + record.size() + 8;
  for (const Buffer b : buffers) {
    file_bytes += kSectionHeaderBytes + buffer_layout(b, sizes_).bytes();
  }
  h.file_bytes = file_bytes;

  // Written beside the target and renamed over it only when complete and on the disk.
  const std::string tmp = path + ".tmp";
  Status s = [&]() -> Status {
    HashedFile file(tmp);
    if (Status st = file.open(); !st) return st;
    if (Status st = file.write(&h, sizeof h); !st) return st;
    if (Status st = file.write(record.data(), record.size()); !st) return st;
    std::vector<unsigned char> data;
    for (const Buffer b : buffers) {
      const BufferLayout layout = buffer_layout(b, sizes_);
      std::array<char, kSectionNameBytes> name{};
      const std::string_view named = buffer_name(b);
      std::copy(named.begin(), named.end(), name.begin());
      const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(layout.element_bytes), 0};
      const std::uint64_t bytes = layout.bytes();
      if (Status st = file.write(name.data(), name.size()); !st) return st;
      if (Status st = file.write(sizes, sizeof sizes); !st) return st;
      if (Status st = file.write(&bytes, sizeof bytes); !st) return st;
      if (bytes == 0) continue;
      data.resize(layout.bytes());
      if (Status st = device_->read(b, data.data(), data.size()); !st) return st;
      if (Status st = file.write(data.data(), data.size()); !st) return st;
    }
    const std::uint64_t checksum = file.hash();
    if (Status st = file.write(&checksum, sizeof checksum, false); !st) return st;
    return file.sync_and_close();
  }();
  if (s && std::rename(tmp.c_str(), path.c_str()) != 0) {
    s = Status::error(
        fmt::format("cannot rename checkpoint '{}' to '{}': {}", tmp, path, std::strerror(errno)));
  }
  if (!s) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    return s;
  }
  return sync_directory_of(path);
}

Status Simulation::load_state(const std::string& path) {
  Result<std::vector<unsigned char>> read = read_whole_file(path);
  if (!read) return read.status();
  const std::vector<unsigned char>& bytes = read.value();
  Result<Parsed> parsed = parse(path, bytes);
  if (!parsed) return parsed.status();
  if (parsed->info.version == 1) return load_state_v1(path, bytes);
  const Header& h = parsed->header;
  if (h.particles != sizes_.particles || h.bodies != bodies_.size() ||
      h.rigid_bodies != sizes_.bodies || h.rigid_particles != sizes_.rigid_particles ||
      h.table != sizes_.table || h.neighbour_capacity != sizes_.neighbour_capacity ||
      h.clusters != sizes_.clusters) {
    return Status::error(fmt::format(
        "{}: checkpoint of another scene: {} particles, {} bodies ({} rigid, {} rigid particles), "
        "{} clusters, {} list entries per particle; this simulation has {}, {} ({}, {}), {}, {}",
        path, h.particles, h.bodies, h.rigid_bodies, h.rigid_particles, h.clusters,
        h.neighbour_capacity, sizes_.particles, bodies_.size(), sizes_.bodies,
        sizes_.rigid_particles, sizes_.clusters, sizes_.neighbour_capacity));
  }
  if (h.setup_hash != setup_hash_) {
    return Status::error(fmt::format(
        "{}: checkpoint of another scene: its setup fingerprint {:016x} is not this "
        "simulation's {:016x} (same sizes, but shapes, materials, planes, constraints, clusters "
        "or settings differ)",
        path, h.setup_hash, setup_hash_));
  }
  const std::vector<Section>& sections = parsed->sections;
  const auto corrupt = [&](const std::string& what) {
    return Status::error(fmt::format("{}: corrupt checkpoint ({})", path, what));
  };
  // A rank's checkpoint of a run over MPI ranks ends with the partition reference; a single
  // process's has none.
  std::vector<Buffer> expected = state_buffers(sizes_);
  // A file written before BodyPosLow was saved: zeros there.
  const bool with_low = std::any_of(sections.begin(), sections.end(), [](const Section& s) {
    return s.buffer == Buffer::BodyPosLow;
  });
  if (!with_low) expected.erase(std::find(expected.begin(), expected.end(), Buffer::BodyPosLow));
  const std::size_t state_sections = kStateBuffers.size() - (with_low ? 0 : 1);
  const bool with_reference =
      sections.size() == state_sections + 1 && sections.back().buffer == Buffer::PartitionRefPos;
  if (sizes_.partition != 0 && !with_reference) {
    return Status::error(fmt::format(
        "{}: a single process's checkpoint: this simulation is one rank of a run over MPI ranks, "
        "whose checkpoint also holds the positions at the last partition (PartitionRefPos)",
        path));
  }
  if (sizes_.partition == 0 && with_reference) {
    return Status::error(fmt::format(
        "{}: one rank's checkpoint of a run over MPI ranks: it loads only into that rank's "
        "simulation (DistributedSimulation::resume of its checkpoint set)",
        path));
  }
  if (sections.size() != expected.size() &&
      (sizes_.partition != 0 || sections.size() != kSectionsBeforeImpulses)) {
    return corrupt("section count");
  }
  for (std::size_t k = sections.size(); k < expected.size(); ++k) {
    if (buffer_layout(expected[k], sizes_).bytes() != 0) {
      return corrupt(fmt::format("no section for {}", buffer_name(expected[k])));
    }
  }
  for (std::size_t k = 0; k < sections.size(); ++k) {
    const BufferLayout layout = buffer_layout(expected[k], sizes_);
    if (sections[k].buffer != expected[k] || sections[k].element_bytes != layout.element_bytes ||
        sections[k].bytes != layout.bytes()) {
      return corrupt(fmt::format("section {} is not {} of {} bytes", k, buffer_name(expected[k]),
                                 layout.bytes()));
    }
  }
  // Values a step uses as indices must be in range, whatever a file made to pass the checksum
  // holds; radii and masses must be the scene's.
  const auto words = [&](std::size_t k) {
    std::vector<std::uint32_t> v(sections[k].bytes / 4);
    if (!v.empty()) std::memcpy(v.data(), bytes.data() + sections[k].offset, sections[k].bytes);
    return v;
  };
  const auto vec4s = [&](std::size_t k) {
    std::vector<shared::vec4> v(sections[k].bytes / 16);
    if (!v.empty()) std::memcpy(v.data(), bytes.data() + sections[k].offset, sections[k].bytes);
    return v;
  };
  const std::size_t n = sizes_.particles;
  {
    const std::vector<shared::vec4> pos = vec4s(kPosSection);
    const std::vector<shared::vec4> vel = vec4s(kVelSection);
    if (pos.size() < n || vel.size() < n) return corrupt("the particles' sections");
    const std::uint64_t w =
        particle_w_hash(std::span(pos).first(n), std::span(vel).first(n), emitters_);
    if (w != particle_w_hash_) {
      return Status::error(fmt::format(
          "{}: checkpoint of another scene: its particles' radii or masses are not this "
          "simulation's",
          path));
    }
  }
  {
    const std::vector<std::uint32_t> list = words(kListSection);
    const std::vector<std::uint32_t> count = words(kCountSection);
    const std::vector<std::uint32_t> order = words(kOrderSection);
    const std::vector<std::uint32_t> start = words(kStartSection);
    const std::size_t capacity = sizes_.neighbour_capacity;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t listed = std::min<std::size_t>(count[i], capacity);
      for (std::size_t k = 0; k < listed; ++k) {
        if (list[k * n + i] >= n) return corrupt("a neighbour list entry out of range");
      }
      if (order[i] >= n) return corrupt("a grid entry out of range");
    }
    for (std::size_t b = 0; b < start.size(); ++b) {
      if (start[b] > n || (b > 0 && start[b] < start[b - 1])) {
        return corrupt("the grid's bucket starts");
      }
    }
  }
  Device& d = *device_;
  for (std::size_t k = 0; k < sections.size(); ++k) {
    if (sections[k].bytes == 0) continue;
    if (Status s = d.write(expected[k], bytes.data() + sections[k].offset, sections[k].bytes); !s) {
      return s;
    }
  }
  if (const std::size_t low = buffer_layout(Buffer::BodyPosLow, sizes_).bytes();
      !with_low && low != 0) {
    const std::vector<unsigned char> zeros(low, 0);
    if (Status s = d.write(Buffer::BodyPosLow, zeros.data(), zeros.size()); !s) return s;
  }
  if (Status s = d.synchronize(); !s) return s;
  steps_ = h.step;
  time_ = h.time;
  rebase_energy();  // the energy guard measures from the checkpoint's state
  return count_emitted();
}

Status Simulation::load_state_v1(const std::string& path, const std::vector<unsigned char>& bytes) {
  HeaderV1 h{};
  std::memcpy(&h, bytes.data(), sizeof h);
  if (h.particles != sizes_.particles || h.bodies != bodies_.size()) {
    return Status::error(
        fmt::format("{}: checkpoint of another scene: {} particles and {} bodies; this simulation "
                    "has {} and {}",
                    path, h.particles, h.bodies, sizes_.particles, bodies_.size()));
  }
  const std::size_t b_bytes = bodies_.size() * 16;
  const std::size_t p_bytes = std::size_t{sizes_.particles} * 16;
  if (h.payload_bytes != 5 * b_bytes + 2 * p_bytes) {
    return Status::error(fmt::format("{}: corrupt checkpoint (payload size)", path));
  }
  Snapshot state;
  std::size_t at = kV1HeaderBytes;
  for (std::vector<shared::vec4>* v : payload_arrays_v1(state)) {
    const std::size_t n = v == &state.particle_pos || v == &state.particle_vel ? p_bytes : b_bytes;
    v->resize(n / 16);
    if (n > 0) std::memcpy(v->data(), bytes.data() + at, n);
    at += n;
  }
  if (Status s = restore(state); !s) return s;
  rebase_energy();
  steps_ = h.step;
  time_ = h.time;
  return count_emitted();
}

}  // namespace motes
