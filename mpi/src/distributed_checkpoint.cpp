// Checkpoint sets of a run over MPI ranks (motes/distributed.h, docs/reliability.md "Checkpoints
// over MPI ranks"): every rank that holds bodies writes its Simulation's checkpoint with its part
// of the distribution in the run record's extension; rank 0 writes the manifest last; the set is
// written in a temporary directory, flushed, and renamed whole.
//
// Rank record (CheckpointRun::extension of rank-RRRRR.mck; the file's checksum covers it), in
// the machine's byte order:
//   magic "MOTESRK1", u32 version (kCheckpointSetVersion), u32 rank, u32 ranks, u64 step,
//   u32 L, L x u32 scene bodies of the local simulation (ascending), L x u8 owned (1) or copy (0),
//   per rank: u32 n, n x u32 local indices of the owned bodies whose state goes there,
//   per rank: u32 n, n x u32 local indices of the copies whose state comes from there,
//   per part of the halo (particles, rigid bodies): ranks x i32 vec4s sent to each rank, then
//     ranks x i32 vec4s received from each.
// Manifest (manifest.mcks):
//   header (136 bytes): magic "MOTESCKS", u32 version, u32 ranks, u64 file bytes, u64 step,
//     f64 time, u64 partitions, u64 migrations, 3 x i32 bricks, u32 halo bodies (0 or 1),
//     3 x f64 lower and 3 x f64 upper corner of the bricks, f64 margin, u64 run record bytes R;
//   run record (R bytes, encode_checkpoint_run: the backend, then rank 0's CheckpointRun);
//   per rank (64 bytes): u32 has a file, u32 0, u64 file bytes, u64 the file's checksum,
//     u64 owned bodies, u64 halo bodies, u64 owned particles, u64 halo particles, u64 halo bytes;
//   checksum: FNV-1a 64 of every byte before it.
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "distributed_internal.h"
#include "motes/backend/bytes.h"
#include "motes/distributed.h"

namespace motes {

namespace {

namespace fs = std::filesystem;

constexpr std::array<char, 8> kRankMagic = {'M', 'O', 'T', 'E', 'S', 'R', 'K', '1'};
constexpr std::array<char, 8> kManifestMagic = {'M', 'O', 'T', 'E', 'S', 'C', 'K', 'S'};
constexpr std::size_t kManifestHeaderBytes = 136;
constexpr std::size_t kManifestRankBytes = 64;

template <typename T>
Status status_of(const Result<T>& r) {
  return r ? Status::ok() : r.status();
}

using detail::ByteReader;
using detail::ByteWriter;

/// One rank's line of the manifest, as gathered on rank 0.
struct RankEntry {
  std::uint32_t has_file = 0;
  std::uint32_t zero = 0;
  std::uint64_t file_bytes = 0;
  std::uint64_t checksum = 0;
  std::uint64_t counters[5] = {};  ///< owned and halo bodies, owned and halo particles, halo bytes
  char backend[16] = {};           ///< not in the manifest: its run record names one backend
};
static_assert(offsetof(RankEntry, backend) == kManifestRankBytes, "the manifest's rank line");

std::string errno_text(int error) { return std::strerror(error); }

/// Writes `bytes` to `path` through a descriptor and flushes it to the disk (fsync).
Status write_synced(const std::string& path, const std::vector<unsigned char>& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    return Status::error(fmt::format("cannot create '{}': {}", path, errno_text(errno)));
  }
  const unsigned char* p = bytes.data();
  std::size_t n = bytes.size();
  while (n > 0) {
    const ::ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      const int error = errno;
      ::close(fd);
      return Status::error(fmt::format("cannot write '{}': {}", path, errno_text(error)));
    }
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    return Status::error(fmt::format("cannot flush '{}' (fsync): {}", path, errno_text(error)));
  }
  if (::close(fd) != 0) {
    return Status::error(fmt::format("cannot close '{}': {}", path, errno_text(errno)));
  }
  return Status::ok();
}

/// fsync on a directory, so that the names created or renamed in it are on the disk.
Status sync_directory(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    return Status::error(
        fmt::format("cannot open directory '{}' to flush it: {}", dir.string(), errno_text(errno)));
  }
  const int r = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  // Some file systems cannot fsync a directory (EINVAL): a rename is then as safe as they make it.
  if (r != 0 && error != EINVAL) {
    return Status::error(
        fmt::format("cannot flush directory '{}': {}", dir.string(), errno_text(error)));
  }
  return Status::ok();
}

/// A written checkpoint's size and its last 8 bytes (its checksum).
Status file_tail(const std::string& path, std::uint64_t& bytes, std::uint64_t& checksum) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st {};
  if (fd < 0 || ::fstat(fd, &st) != 0 || st.st_size < 8 ||
      ::pread(fd, &checksum, sizeof checksum, st.st_size - 8) != sizeof checksum) {
    const int error = errno;
    if (fd >= 0) ::close(fd);
    return Status::error(
        fmt::format("cannot read back checkpoint '{}': {}", path, errno_text(error)));
  }
  ::close(fd);
  bytes = static_cast<std::uint64_t>(st.st_size);
  return Status::ok();
}

/// `tmp` (complete and on the disk) becomes `set`. A set already there (of a run written into the
/// same directory before, or the one this run was resumed from) is exchanged with it atomically
/// and then removed.
Status install_set(const fs::path& tmp, const fs::path& set) {
  fs::path parent = set.parent_path();
  if (parent.empty()) parent = ".";
  int error = 0;
  if (::rename(tmp.c_str(), set.c_str()) == 0) return sync_directory(parent);
  error = errno;
  if (error == ENOTEMPTY || error == EEXIST) {
    if (::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, set.c_str(), RENAME_EXCHANGE) == 0) {
      Status synced = sync_directory(parent);
      std::error_code ec;
      fs::remove_all(tmp, ec);  // the old set, under the temporary name now
      return synced;
    }
    // A file system without an atomic exchange: the old set goes first (the sets before it
    // stay).
    std::error_code ec;
    fs::remove_all(set, ec);
    if (!ec && ::rename(tmp.c_str(), set.c_str()) == 0) return sync_directory(parent);
    error = ec ? ec.value() : errno;
  }
  return Status::error(fmt::format("cannot rename checkpoint set '{}' to '{}': {}", tmp.string(),
                                   set.string(), errno_text(error)));
}

Result<std::vector<unsigned char>> read_file(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return Status::error(fmt::format("{}: cannot open {}: {}", path, what, errno_text(errno)));
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    return Status::error(fmt::format("{}: cannot read {}: {}", path, what, errno_text(errno)));
  }
  const std::string s = std::move(text).str();
  return std::vector<unsigned char>(s.begin(), s.end());
}

/// A rank's part of the distribution, as its file's rank record holds it.
struct RankState {
  std::vector<std::uint32_t> bodies;
  std::vector<char> owned;
  std::vector<std::vector<std::uint32_t>> send, receive;
  std::array<std::vector<int>, 2> send_counts, receive_counts;
};

/// Reads and checks rank `rank`'s file of a set: the file itself (read_checkpoint_info), that it
/// is the one the manifest lists, and its rank record against the manifest and the scene.
Result<RankState> read_rank_file(const std::string& path, int rank, const CheckpointSetInfo& set,
                                 std::size_t scene_bodies) {
  Result<CheckpointInfo> file = read_checkpoint_info(path);
  if (!file) return file.status();
  const CheckpointSetInfo::Rank& listed = set.rank[static_cast<std::size_t>(rank)];
  if (file->file_bytes != listed.file_bytes || file->checksum != listed.checksum) {
    return Status::error(fmt::format(
        "{}: not the file the set's manifest lists ({} bytes, checksum {:016x}; the manifest "
        "says {} bytes, checksum {:016x}): a rank file of another checkpoint set?",
        path, file->file_bytes, file->checksum, listed.file_bytes, listed.checksum));
  }
  if (file->step != set.step || file->run.scene_hash != set.run.scene_hash) {
    return Status::error(fmt::format(
        "{}: a checkpoint of step {} of the scene {:016x}; the set's manifest says step {} of "
        "{:016x}",
        path, file->step, file->run.scene_hash, set.step, set.run.scene_hash));
  }
  const std::vector<unsigned char>& ext = file->run.extension;
  if (ext.empty()) {
    return Status::error(fmt::format(
        "{}: a single process's checkpoint, not a rank's file of a checkpoint set (it has no "
        "rank record)",
        path));
  }
  const auto corrupt = [&](const std::string& what) {
    return Status::error(fmt::format("{}: corrupt rank record ({})", path, what));
  };
  ByteReader r(ext.data(), ext.size());
  std::array<char, 8> magic{};
  r.raw(magic.data(), magic.size());
  if (r.bad || magic != kRankMagic) return corrupt("it does not start with \"MOTESRK1\"");
  const auto version = r.get<std::uint32_t>();
  if (version != kCheckpointSetVersion) {
    return Status::error(fmt::format("{}: rank record version {}; this motes reads version {}",
                                     path, version, kCheckpointSetVersion));
  }
  const auto its_rank = r.get<std::uint32_t>();
  const auto its_ranks = r.get<std::uint32_t>();
  const auto its_step = r.get<std::uint64_t>();
  if (r.bad) return corrupt("its header");
  if (its_rank != static_cast<std::uint32_t>(rank) ||
      its_ranks != static_cast<std::uint32_t>(set.ranks) || its_step != set.step) {
    return Status::error(fmt::format(
        "{}: the file of rank {} of {} at step {}; the set's manifest lists it as rank {} of {} "
        "at step {}",
        path, its_rank, its_ranks, its_step, rank, set.ranks, set.step));
  }
  RankState state;
  state.bodies = r.list<std::uint32_t>();
  state.owned.resize(state.bodies.size());
  for (char& o : state.owned) o = static_cast<char>(r.get<std::uint8_t>());
  const auto ranks = static_cast<std::size_t>(set.ranks);
  for (auto* lists : {&state.send, &state.receive}) {
    lists->resize(ranks);
    for (std::vector<std::uint32_t>& l : *lists) l = r.list<std::uint32_t>();
  }
  for (std::size_t part = 0; part < 2; ++part) {
    for (auto* counts : {&state.send_counts[part], &state.receive_counts[part]}) {
      counts->resize(ranks);
      for (int& c : *counts) c = r.get<std::int32_t>();
    }
  }
  if (r.bad || r.left() != 0) return corrupt("its size");
  for (std::size_t k = 0; k < state.bodies.size(); ++k) {
    if (state.bodies[k] >= scene_bodies) {
      return Status::error(fmt::format(
          "{}: its rank record names body {} of a scene of {} bodies: a checkpoint set of "
          "another scene?",
          path, state.bodies[k], scene_bodies));
    }
    if (k > 0 && state.bodies[k] <= state.bodies[k - 1]) return corrupt("bodies out of order");
    if (state.owned[k] != 0 && state.owned[k] != 1) return corrupt("ownership flags");
  }
  for (std::size_t q = 0; q < ranks; ++q) {
    for (const std::uint32_t k : state.send[q]) {
      if (k >= state.bodies.size() || state.owned[k] == 0 || q == static_cast<std::size_t>(rank)) {
        return corrupt("a halo send");
      }
    }
    for (const std::uint32_t k : state.receive[q]) {
      if (k >= state.bodies.size() || state.owned[k] != 0 || q == static_cast<std::size_t>(rank)) {
        return corrupt("a halo receive");
      }
    }
    for (std::size_t part = 0; part < 2; ++part) {
      if (state.send_counts[part][q] < 0 || state.receive_counts[part][q] < 0) {
        return corrupt("halo sizes");
      }
    }
  }
  return state;
}

std::string vector_text(const Eigen::Vector3d& v) {
  return fmt::format("({}, {}, {})", v.x(), v.y(), v.z());
}

}  // namespace

std::string checkpoint_set_rank_file(const std::string& set, int rank) {
  return (fs::path(set) / fmt::format("rank-{:05}.mck", rank)).string();
}

Result<CheckpointSetInfo> read_checkpoint_set(const std::string& set) {
  std::error_code ec;
  if (!fs::is_directory(set, ec)) {
    if (fs::exists(set, ec)) {
      return Status::error(fmt::format(
          "{}: not a checkpoint set (a set is a directory of rank files and a manifest)", set));
    }
    return Status::error(fmt::format("{}: no such checkpoint set", set));
  }
  const std::string path = (fs::path(set) / kCheckpointSetManifest).string();
  if (!fs::exists(path, ec)) {
    return Status::error(fmt::format(
        "{}: the checkpoint set has no manifest (rank 0 writes it last: a set without one was "
        "not completed)",
        path));
  }
  Result<std::vector<unsigned char>> read = read_file(path, "the checkpoint set's manifest");
  if (!read) return read.status();
  const std::vector<unsigned char>& bytes = read.value();
  const std::size_t size = bytes.size();
  if (size < 12 || std::memcmp(bytes.data(), kManifestMagic.data(), kManifestMagic.size()) != 0) {
    return Status::error(fmt::format(
        "{}: not a motes checkpoint set manifest (it does not start with \"MOTESCKS\"; {} bytes)",
        path, size));
  }
  CheckpointSetInfo info;
  std::memcpy(&info.version, bytes.data() + 8, sizeof info.version);
  if (info.version != kCheckpointSetVersion) {
    return Status::error(fmt::format("{}: checkpoint set format version {}; this motes reads {}",
                                     path, info.version, kCheckpointSetVersion));
  }
  if (size < kManifestHeaderBytes + 8) {
    return Status::error(
        fmt::format("{}: truncated manifest ({} bytes, less than its {}-byte header)", path, size,
                    kManifestHeaderBytes + 8));
  }
  ByteReader r(bytes.data() + 12, size - 12);
  const auto ranks = r.get<std::uint32_t>();
  const auto file_bytes = r.get<std::uint64_t>();
  if (file_bytes > size) {
    return Status::error(
        fmt::format("{}: truncated manifest ({} of {} bytes)", path, size, file_bytes));
  }
  if (file_bytes != size) {
    return Status::error(fmt::format("{}: corrupt manifest ({} bytes, but its header says {})",
                                     path, size, file_bytes));
  }
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + size - 8, sizeof stored);
  const std::uint64_t computed = fnv1a64(bytes.data(), size - 8);
  if (stored != computed) {
    return Status::error(fmt::format(
        "{}: corrupt manifest (checksum mismatch: stored {:016x}, computed {:016x}): the file "
        "was changed or damaged after it was written",
        path, stored, computed));
  }
  // The checksum is right: what follows fails only for a file made to pass it.
  const auto corrupt = [&](const char* what) {
    return Status::error(fmt::format("{}: corrupt manifest ({})", path, what));
  };
  info.step = r.get<std::uint64_t>();
  info.time = r.get<double>();
  info.partitions = r.get<std::uint64_t>();
  info.migrations = r.get<std::uint64_t>();
  for (int& c : info.decomposition.cells) c = r.get<std::int32_t>();
  info.halo_bodies = r.get<std::uint32_t>() != 0;
  for (int a = 0; a < 3; ++a) info.decomposition.lower[a] = r.get<double>();
  for (int a = 0; a < 3; ++a) info.decomposition.upper[a] = r.get<double>();
  info.margin = r.get<double>();
  const auto record = r.get<std::uint64_t>();
  if (r.bad || r.at() + 12 != kManifestHeaderBytes) return corrupt("header");
  if (ranks < 1 || ranks > static_cast<std::uint32_t>(std::numeric_limits<int>::max()) ||
      info.decomposition.cells[0] < 1 || info.decomposition.cells[1] < 1 ||
      info.decomposition.cells[2] < 1 ||
      static_cast<std::uint64_t>(info.decomposition.cells[0]) *
              static_cast<std::uint64_t>(info.decomposition.cells[1]) *
              static_cast<std::uint64_t>(info.decomposition.cells[2]) !=
          ranks) {
    return corrupt("rank count and bricks");
  }
  info.ranks = static_cast<int>(ranks);
  const std::size_t body = size - 8 - kManifestHeaderBytes;
  if (record > body || (body - record) / kManifestRankBytes != ranks ||
      (body - record) % kManifestRankBytes != 0) {
    return corrupt("run record or rank table size");
  }
  if (!decode_checkpoint_run(bytes.data() + kManifestHeaderBytes, record, info.backend, info.run)) {
    return corrupt("run record");
  }
  ByteReader table(bytes.data() + kManifestHeaderBytes + record, body - record);
  info.rank.resize(ranks);
  for (CheckpointSetInfo::Rank& k : info.rank) {
    const auto has_file = table.get<std::uint32_t>();
    (void)table.get<std::uint32_t>();
    k.has_file = has_file != 0;
    k.file_bytes = table.get<std::uint64_t>();
    k.checksum = table.get<std::uint64_t>();
    k.owned_bodies = table.get<std::uint64_t>();
    k.halo_bodies = table.get<std::uint64_t>();
    k.owned_particles = table.get<std::uint64_t>();
    k.halo_particles = table.get<std::uint64_t>();
    k.halo_bytes = table.get<std::uint64_t>();
    if (has_file > 1) return corrupt("rank table");
  }
  if (table.bad) return corrupt("rank table");
  return info;
}

std::vector<unsigned char> DistributedSimulation::rank_record() const {
  ByteWriter w;
  w.raw(kRankMagic.data(), kRankMagic.size());
  w.put(kCheckpointSetVersion);
  w.put(static_cast<std::uint32_t>(rank_));
  w.put(static_cast<std::uint32_t>(size_));
  w.put(steps_);
  w.list(local_bodies_);
  for (const char o : local_owned_) w.put(static_cast<std::uint8_t>(o != 0 ? 1 : 0));
  for (const auto* lists : {&send_, &receive_}) {
    for (const std::vector<std::uint32_t>& l : *lists) w.list(l);
  }
  for (std::size_t part = 0; part < 2; ++part) {
    for (const auto* counts : {&send_counts_[part], &receive_counts_[part]}) {
      for (const int c : *counts) w.put(static_cast<std::int32_t>(c));
    }
  }
  return std::move(w.bytes);
}

Status DistributedSimulation::save_checkpoint(const std::string& set, const CheckpointRun& run) {
  const fs::path final_path(set);
  const fs::path tmp(set + ".tmp");
  Status status = Status::ok();
  if (rank_ == 0) {
    // What a run killed while it wrote a set of this step left is started again.
    std::error_code ec;
    fs::remove_all(tmp, ec);
    if (!ec) fs::create_directories(tmp, ec);
    if (ec) {
      status = Status::error(fmt::format("cannot create checkpoint set directory '{}': {}",
                                         tmp.string(), ec.message()));
    }
  }
  if (Status s = agree(comm_, status); !s) return s;

  RankEntry entry;
  if (local_) {
    CheckpointRun mine;
    mine.scene_path = run.scene_path;
    mine.scene_file = run.scene_file;
    mine.scene_hash = run.scene_hash;
    mine.extension = rank_record();
    const std::string path = checkpoint_set_rank_file(tmp.string(), rank_);
    // Written beside its final name, flushed, renamed, and the directory flushed.
    status = local_->save_state(path, mine);
    if (status) status = file_tail(path, entry.file_bytes, entry.checksum);
    entry.has_file = 1;
  }
  entry.counters[0] = stats_.owned_bodies;
  entry.counters[1] = stats_.halo_bodies;
  entry.counters[2] = stats_.owned_particles;
  entry.counters[3] = stats_.halo_particles;
  entry.counters[4] = stats_.halo_bytes;
  const std::string& backend = device_info_.backend;
  std::copy_n(backend.begin(), std::min(backend.size(), sizeof entry.backend - 1), entry.backend);
  if (Status s = agree(comm_, status); !s) return s;
  std::vector<RankEntry> entries(rank_ == 0 ? static_cast<std::size_t>(size_) : 0);
  MPI_Gather(&entry, sizeof entry, MPI_BYTE, entries.data(), sizeof entry, MPI_BYTE, 0, comm_);

  if (rank_ == 0) {
    std::string written_on;
    for (const RankEntry& e : entries) {
      if (written_on.empty()) written_on = std::string(e.backend);
    }
    const std::vector<unsigned char> record = encode_checkpoint_run(written_on, run);
    ByteWriter w;
    w.raw(kManifestMagic.data(), kManifestMagic.size());
    w.put(kCheckpointSetVersion);
    w.put(static_cast<std::uint32_t>(size_));
    const std::uint64_t file_bytes =
        kManifestHeaderBytes + record.size() + kManifestRankBytes * entries.size() + 8;
    w.put(file_bytes);
    w.put(steps_);
    w.put(time());
    w.put(stats_.partitions);
    w.put(stats_.migrations);
    for (const int c : decomposition_.cells) w.put(static_cast<std::int32_t>(c));
    w.put(static_cast<std::uint32_t>(halo_bodies_ ? 1 : 0));
    for (int a = 0; a < 3; ++a) w.put(decomposition_.lower[a]);
    for (int a = 0; a < 3; ++a) w.put(decomposition_.upper[a]);
    w.put(margin_);
    w.put(static_cast<std::uint64_t>(record.size()));
    w.raw(record.data(), record.size());
    for (const RankEntry& e : entries) w.raw(&e, kManifestRankBytes);
    w.put(fnv1a64(w.bytes.data(), w.bytes.size()));
    const std::string manifest = (tmp / kCheckpointSetManifest).string();
    status = w.bytes.size() == file_bytes
                 ? write_synced(manifest, w.bytes)
                 : Status::error(fmt::format("{}: {} bytes written for {}", manifest,
                                             w.bytes.size(), file_bytes));
    // Every rank file and the manifest are on the disk, and so are their names: the set is
    // complete before it gets its name.
    if (status) status = sync_directory(tmp);
    if (status) status = install_set(tmp, final_path);
  }
  return agree(comm_, status);
}

Result<std::unique_ptr<DistributedSimulation>> DistributedSimulation::resume(
    Scene scene, MPI_Comm comm, DeviceOpener open_device, const std::string& set,
    DistributedOptions::Halo halo) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  Result<CheckpointSetInfo> info = read_checkpoint_set(set);
  Status status = status_of(info);
  if (status && info->ranks != size) {
    status = Status::error(fmt::format(
        "{}: a checkpoint set of {} MPI ranks; this run has {}: a set goes on only over the rank "
        "count that wrote it (mpirun -np {})",
        set, info->ranks, size, info->ranks));
  }
  if (Status s = agree(comm, status); !s) return s;
  // The same bricks and margin as the run that wrote it; create() partitions the scene's start,
  // which the set's state then replaces.
  DistributedOptions options;
  options.decomposition = info->decomposition.cells;
  options.margin = info->margin;
  options.halo = halo;
  Result<std::unique_ptr<DistributedSimulation>> d =
      create(std::move(scene), comm, std::move(open_device), options);
  if (!d) return d.status();
  if (Status s = d.value()->load_checkpoint(set, info.value()); !s) return s;
  return d;
}

Status DistributedSimulation::load_checkpoint(const std::string& set,
                                              const CheckpointSetInfo& info) {
  const std::string manifest = (fs::path(set) / kCheckpointSetManifest).string();
  // The bricks come from the scene's start: another scene has other bounds. (The same on every
  // rank when every rank read the same manifest; agreed all the same.)
  Status status = Status::ok();
  if (decomposition_.lower != info.decomposition.lower ||
      decomposition_.upper != info.decomposition.upper) {
    status = Status::error(fmt::format(
        "{}: the set's bricks span {} to {} m, this scene's start {} to {} m: a checkpoint set of "
        "another scene",
        manifest, vector_text(info.decomposition.lower), vector_text(info.decomposition.upper),
        vector_text(decomposition_.lower), vector_text(decomposition_.upper)));
  }
  if (Status s = agree(comm_, status); !s) return s;

  // This rank's file.
  const CheckpointSetInfo::Rank& listed = info.rank[static_cast<std::size_t>(rank_)];
  const std::string path = checkpoint_set_rank_file(set, rank_);
  const auto ranks = static_cast<std::size_t>(size_);
  RankState state;
  if (listed.has_file) {
    Result<RankState> read = read_rank_file(path, rank_, info, bodies_.size());
    if (read) {
      state = std::move(read).value();
    } else {
      status = read.status();
    }
  } else {
    state.send.assign(ranks, {});
    state.receive.assign(ranks, {});
    for (std::size_t part = 0; part < 2; ++part) {
      state.send_counts[part].assign(ranks, 0);
      state.receive_counts[part].assign(ranks, 0);
    }
  }
  if (Status s = agree(comm_, status); !s) return s;

  // The files together: every scene body owned by one rank, and each rank receiving what the
  // others send it.
  std::vector<int> owners(bodies_.size(), 0);
  for (std::size_t k = 0; k < state.bodies.size(); ++k) owners[state.bodies[k]] += state.owned[k];
  MPI_Allreduce(MPI_IN_PLACE, owners.data(), static_cast<int>(owners.size()), MPI_INT, MPI_SUM,
                comm_);
  for (std::size_t b = 0; b < owners.size() && status; ++b) {
    if (owners[b] != 1) {
      status = Status::error(fmt::format(
          "{}: scene body {} '{}' is owned by {} ranks in the set's rank files: files of "
          "different checkpoint sets?",
          set, b, bodies_[b].name, owners[b]));
    }
  }
  for (std::size_t part = 0; part < 2; ++part) {
    std::vector<int> incoming(ranks, 0);
    MPI_Alltoall(state.send_counts[part].data(), 1, MPI_INT, incoming.data(), 1, MPI_INT, comm_);
    for (std::size_t q = 0; q < ranks && status; ++q) {
      if (incoming[q] != state.receive_counts[part][q]) {
        status = Status::error(fmt::format(
            "{}: its halo receives {} vec4s from rank {}, which sends {}: files of different "
            "checkpoint sets?",
            path, state.receive_counts[part][q], q, incoming[q]));
      }
    }
  }
  if (Status s = agree(comm_, status); !s) return s;

  // The local simulation of the set's bodies, on this rank's device, with the set's state.
  std::unique_ptr<Device> device =
      local_ ? Simulation::take_device(std::move(local_)) : std::move(spare_);
  if (listed.has_file) {
    Result<std::unique_ptr<Simulation>> sim = local_simulation(
        state.bodies, state.send, state.receive,
        device ? Result<std::unique_ptr<Device>>(std::move(device)) : open_device_());
    if (sim) status = sim.value()->load_state(path);
    if (sim && status) {
      local_ = std::move(sim).value();
      device_info_ = local_->device().info();
    } else if (status) {
      status = sim.status();
    }
  } else {
    spare_ = std::move(device);
  }
  if (Status s = agree(comm_, status); !s) return s;

  local_bodies_ = std::move(state.bodies);
  local_owned_ = std::move(state.owned);
  send_ = std::move(state.send);
  receive_ = std::move(state.receive);
  send_counts_ = std::move(state.send_counts);
  receive_counts_ = std::move(state.receive_counts);
  halo_bodies_ = info.halo_bodies;
  steps_ = info.step;
  stats_ = DistributedStats{};
  stats_.partitions = info.partitions;
  stats_.migrations = info.migrations;
  stats_.owned_bodies = listed.owned_bodies;
  stats_.halo_bodies = listed.halo_bodies;
  stats_.owned_particles = listed.owned_particles;
  stats_.halo_particles = listed.halo_particles;
  stats_.halo_bytes = listed.halo_bytes;
  return connect_halos();
}

}  // namespace motes
