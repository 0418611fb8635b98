// motes::DistributedSimulation: one scene over several MPI ranks, one device per rank
// (docs/scale-out.md). Each rank owns the bodies whose centre lies in its brick of the
// decomposition (motes/decomposition.h) and holds halo copies of the bodies near what it owns;
// it steps an ordinary Simulation of those on its own device, on any backend.
#pragma once

#include <mpi.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "motes/backend/device.h"
#include "motes/checkpoint.h"
#include "motes/decomposition.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/status.h"

namespace motes {

/// Opens the device of this rank, once: every partition's simulation runs on it
/// (Simulation::take_device). A rank that holds no body has none until it gets one.
using DeviceOpener = std::function<Result<std::unique_ptr<Device>>()>;

/// Collective: every rank learns whether any rank's `mine` is an error; all then return the
/// lowest failing rank's message, prefixed "rank R: " unless every rank failed.
/// With `largest`, also the largest of every rank's *largest, in the same reduction.
Status agree(MPI_Comm comm, const Status& mine, double* largest = nullptr);

struct DistributedOptions {
  /// Bricks along x, y, z (their product = the rank count); none: choose_decomposition.
  std::optional<std::array<int, 3>> decomposition;
  /// How far (m) a particle may move before bodies are re-partitioned (migration) and the halos
  /// chosen again; < 0: half the largest particle diameter. The ranks re-partition at a list
  /// rebuild where the largest displacement since the last partition plus 0.45 skin exceeds it.
  /// The halo holds every body with a particle within 2 margins (particles grown by their radii)
  /// of what a rank owns, so no contact is missed in between. Larger: rarer partitions, a wider
  /// halo. At least half the neighbour skin (a particle moves up to 0.45 skin between list
  /// builds): a smaller or non-finite margin is refused.
  double margin = -1.0;
  /// How the halo copies travel. Auto: straight from device to device (Device::share_halo_outbox:
  /// CUDA IPC, over NVLink between GPUs) when every rank runs on one host and every rank's device
  /// can, else through host memory and MPI; Host: always through host memory and MPI. The same
  /// bits either way.
  enum class Halo { Auto, Host };
  Halo halo = Halo::Auto;
};

/// What the ranks did (the same on every rank after a collective call).
struct DistributedStats {
  std::uint64_t partitions = 0;    ///< partitions so far (the first at create)
  std::uint64_t migrations = 0;    ///< bodies that changed rank, over all partitions
  std::uint64_t owned_bodies = 0;  ///< this rank's bodies now
  std::uint64_t halo_bodies = 0;   ///< this rank's halo copies now
  std::uint64_t owned_particles = 0;
  std::uint64_t halo_particles = 0;
  std::uint64_t halo_bytes = 0;  ///< bytes this rank sent in halo updates since create
  /// This rank's seconds since create: its own steps, halo updates' own work (state from and to the
  /// device, packing), their MPI calls (the transfer and the wait for slower ranks), partitions
  /// (all).
  double step_seconds = 0.0;  ///< this rank's own steps
  double copy_seconds = 0.0;
  double mpi_seconds = 0.0;
  double partition_seconds = 0.0;
  /// Whether the halo copies travel device to device (DistributedOptions::halo), and, when they go
  /// through host memory on one host with Halo::Auto, why (the first rank that could not).
  bool halo_direct = false;
  std::string halo_host_reason;
};

struct CheckpointSetInfo;  // below

class DistributedSimulation {
 public:
  /// Collective over `comm`: every rank passes the same scene. Bodies that must be stepped
  /// together stay together, owned by one rank and copied whole (a group: a cloth or rope with
  /// the bodies it is attached to; with impulse contacts, every rigid body of the scene).
  static Result<std::unique_ptr<DistributedSimulation>> create(Scene scene, MPI_Comm comm,
                                                               DeviceOpener open_device,
                                                               const DistributedOptions& options);

  /// Collective: `count` steps; the halo copies are brought up to date after every step.
  Status step(std::uint64_t count = 1);
  /// Collective: the whole state in the scene's order (as Simulation::snapshot) on rank `root`;
  /// the other ranks get an empty Snapshot (time and step set).
  Result<Snapshot> gather(int root = 0);
  /// Collective: this rank's stats, with partitions and migrations as everywhere.
  [[nodiscard]] DistributedStats stats() const { return stats_; }

  [[nodiscard]] int rank() const { return rank_; }
  [[nodiscard]] int size() const { return size_; }
  [[nodiscard]] const Decomposition& decomposition() const { return decomposition_; }
  [[nodiscard]] std::uint64_t steps() const { return steps_; }
  [[nodiscard]] double time() const { return static_cast<double>(steps_) * scene_.settings.dt; }
  [[nodiscard]] const Settings& settings() const { return scene_.settings; }
  /// The whole scene (every rank's copy).
  [[nodiscard]] const Scene& scene() const { return scene_; }
  /// Every scene body's facts in the scene's order (particle ranges as in a gathered Snapshot).
  [[nodiscard]] const std::vector<BodyInfo>& bodies() const { return bodies_; }
  [[nodiscard]] std::uint64_t particle_count() const { return particles_; }
  /// Scene bodies this rank owns now, ascending.
  [[nodiscard]] std::vector<std::uint32_t> owned() const;
  /// This rank's simulation (owned bodies and halo copies, in scene order).
  [[nodiscard]] Simulation& local() { return *local_; }
  /// The device this rank runs on.
  [[nodiscard]] const DeviceInfo& device_info() const { return device_info_; }

  /// A body's state as ranks exchange it: its body vectors, then its particles' positions and
  /// velocities (Snapshot layouts).
  struct Record {
    std::uint32_t body = 0;  ///< scene body index
    /// position, orientation, velocity, L, omega, the centre's part below its float (impulse
    /// contacts: Snapshot::body_pos_low; else 0)
    std::array<shared::vec4, 6> state{};
    std::vector<shared::vec4> pos, vel;
    std::vector<shared::vec4> rotations;  ///< a soft body's clusters' last rotations
    /// Impulse contacts: its particles' accumulated impulses with the planes (Snapshot).
    std::vector<shared::vec4> planes;
  };

  /// Collective: writes the run at this step as a checkpoint set, the directory `set`
  /// (docs/reliability.md, "Checkpoints over MPI ranks"): each rank holding bodies writes its
  /// simulation (Simulation::save_state, its partition reference included) with what this rank
  /// needs to go on (its bodies, which it owns, its halo lists) as rank-RRRRR.mck, then rank 0
  /// writes the manifest (rank count, step, the bricks, the margin, every rank file's size and
  /// checksum, and `run`, rank 0's description of the run). Atomic as a whole: everything is
  /// written into `set`.tmp and flushed to the disk (fsync) before rank 0 renames it to `set`
  /// (exchanging it with a set already there) and flushes the parent directory, so a crash at any
  /// moment leaves the old `set` or the new one.
  Status save_checkpoint(const std::string& set, const CheckpointRun& run);
  /// Collective: the run of `scene` (the scene of the run that wrote it) going on from the
  /// checkpoint set `set`, over as many ranks as wrote it: stepping on gives bitwise the state of
  /// the uninterrupted run at the same rank count on the same backend. Every rank checks the
  /// manifest and its own file; a missing, truncated, corrupt (checksum) or other-version
  /// manifest or rank file, a set of another rank count or of another scene, or files of
  /// different sets are refused on every rank with one message naming the file and the reason.
  /// The counters of stats() go on from the set's; its seconds count from the resume. (It
  /// creates the run as create() does, over the set's bricks and margin, then replaces each
  /// rank's simulation with the set's: one simulation of the scene's start is built and dropped.)
  /// `halo`: how the halo copies travel from now on (DistributedOptions::halo; not in the set).
  static Result<std::unique_ptr<DistributedSimulation>> resume(
      Scene scene, MPI_Comm comm, DeviceOpener open_device, const std::string& set,
      DistributedOptions::Halo halo = DistributedOptions::Halo::Auto);

 private:
  DistributedSimulation() = default;
  /// Sends owned records to their new owners, chooses the halos and builds the local
  /// simulation from `owned` (the records this rank holds, any owner).
  Status partition(std::vector<Record> owned);
  /// Brings every halo copy up to date from its owner (packed and unpacked on the devices) and
  /// rebuilds every rank's lists when any rank's are due; returns 0, or at a rebuild a bound (the
  /// same on every rank) on how far a particle can move from the partition before the next
  /// rebuild; or the first error of any rank (`stepped`: this rank's step).
  Result<double> exchange_halos(Status stepped);
  /// The packed halo through host memory: every rank's MPI_Alltoallv from halo_sent() into
  /// halo_received(); returns the seconds it took (totals of the send and receive lists'
  /// particle parts given).
  double exchange_on_host(std::size_t out_particles, std::size_t in_particles);
  /// This rank's records of its owned bodies, from the local simulation.
  Result<std::vector<Record>> owned_records();
  /// A body of the local simulation: its scene index, its state (nullptr: the scene's start) and
  /// the rank it is copied from (-1: owned here).
  struct LocalEntry {
    std::uint32_t body = 0;
    const Record* record = nullptr;
    int from = -1;
  };
  /// Collective: the local simulation of `entries` (all with records, or none) on this rank's
  /// device, the halo lists (`sent_bodies`: the scene bodies sent to each rank, ascending) and
  /// their counts.
  Status build_local(std::vector<LocalEntry> entries,
                     const std::vector<std::vector<std::uint32_t>>& sent_bodies);
  /// The local simulation of scene bodies `bodies` (ascending) with the halo lists `send` and
  /// `receive` (local indices, by rank) on `device`: the whole scene when this is the only rank.
  /// Every partition and a resume build it so.
  Result<std::unique_ptr<Simulation>> local_simulation(
      const std::vector<std::uint32_t>& bodies, const std::vector<std::vector<std::uint32_t>>& send,
      const std::vector<std::vector<std::uint32_t>>& receive,
      Result<std::unique_ptr<Device>> device) const;
  /// Collective: the partition at create, from the scene (`centres`: body_centres).
  Status first_partition(const std::vector<Eigen::Vector3d>& centres);
  /// Writes the entries' records into the local simulation (build_local).
  Status write_records(const std::vector<LocalEntry>& entries);
  /// groups_ and group_of_ from the scene.
  void group_bodies();
  /// Collective, after every change of the local simulations: the device-direct halo when
  /// DistributedOptions::halo allows it and every rank can (each opens the outboxes of the ranks
  /// it receives from), else the halo through host memory.
  Status connect_halos();

  Scene scene_;
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0;
  int size_ = 1;
  DeviceOpener open_device_;
  Decomposition decomposition_;
  double margin_ = 0.0;
  double scene_diameter_ = 0.0;  ///< the scene's largest particle diameter
  double halo_width_ = 0.0;
  std::vector<BodyInfo> bodies_;
  /// Bodies owned and copied together (scene body indices, ascending), and each scene body's
  /// group (kAlone: a body on its own).
  static constexpr std::uint32_t kAlone = UINT32_MAX;
  std::vector<std::vector<std::uint32_t>> groups_;
  std::vector<std::uint32_t> group_of_;
  std::uint64_t particles_ = 0;
  std::uint64_t steps_ = 0;

  std::unique_ptr<Simulation> local_;
  std::unique_ptr<Device> spare_;  ///< this rank's device while it holds no body
  DeviceInfo device_info_;
  /// Scene bodies in the local simulation (ascending) and whether this rank owns each.
  std::vector<std::uint32_t> local_bodies_;
  std::vector<char> local_owned_;
  /// Halo sends: for each rank, the local indices of owned bodies it holds copies of (ascending
  /// scene order); halo receives: for each rank, the local indices of its copies here.
  std::vector<std::vector<std::uint32_t>> send_;
  std::vector<std::vector<std::uint32_t>> receive_;
  /// Each rank's part of the packed halo (shared/halo.h) in vec4s: [0] the particles' part,
  /// [1] the rigid bodies' part; sent to and received from each rank.
  std::array<std::vector<int>, 2> send_counts_;
  std::array<std::vector<int>, 2> receive_counts_;
  /// Whether any rank's halo has rigid bodies (else their part is not exchanged).
  bool halo_bodies_ = false;
  /// The neighbour-list skin (the same on every rank: the scene's).
  double skin_ = 0.0;
  /// Whether every rank runs on this host (MPI_COMM_TYPE_SHARED), what the options allow, and
  /// with the device-direct halo, the parts this rank copies from its neighbours' outboxes.
  bool one_host_ = false;
  DistributedOptions::Halo halo_mode_ = DistributedOptions::Halo::Auto;
  bool direct_ = false;
  std::vector<Simulation::HaloFetch> fetches_;
  DistributedStats stats_;

  // Checkpoint sets (distributed_checkpoint.cpp).
  /// What this rank needs to go on from its checkpoint (CheckpointRun::extension of its file).
  [[nodiscard]] std::vector<unsigned char> rank_record() const;
  /// resume() after create(): this rank's file of `set` (described by `info`) replaces the state.
  Status load_checkpoint(const std::string& set, const CheckpointSetInfo& info);
};

/// What a checkpoint set's manifest says (read_checkpoint_set).
struct CheckpointSetInfo {
  std::uint32_t version = 0;
  int ranks = 0;
  std::uint64_t step = 0;
  double time = 0.0;
  std::string backend;  ///< the backend of the ranks that wrote it
  /// The run as rank 0 described it (the motes command: scene, outputs, series so far).
  CheckpointRun run;
  Decomposition decomposition;
  double margin = 0.0;
  bool halo_bodies = false;  ///< whether the rigid bodies' part of the halo travels
  std::uint64_t partitions = 0;
  std::uint64_t migrations = 0;
  /// Per rank: its file (none when it held no body), and its counters of DistributedStats.
  struct Rank {
    bool has_file = false;
    std::uint64_t file_bytes = 0;
    std::uint64_t checksum = 0;  ///< the file's own checksum (its last 8 bytes)
    std::uint64_t owned_bodies = 0;
    std::uint64_t halo_bodies = 0;
    std::uint64_t owned_particles = 0;
    std::uint64_t halo_particles = 0;
    std::uint64_t halo_bytes = 0;
  };
  std::vector<Rank> rank;
};

/// The format of checkpoint sets this motes writes and reads.
constexpr std::uint32_t kCheckpointSetVersion = 1;
/// The manifest's name in a set.
constexpr const char* kCheckpointSetManifest = "manifest.mcks";
/// Rank `rank`'s file in the set `set`: `set`/rank-RRRRR.mck.
std::string checkpoint_set_rank_file(const std::string& set, int rank);
/// Reads and checks a set's manifest (not collective; no rank file is read). Errors name the
/// manifest and the reason: missing, not a manifest, another version, truncated, corrupt.
Result<CheckpointSetInfo> read_checkpoint_set(const std::string& set);

}  // namespace motes
