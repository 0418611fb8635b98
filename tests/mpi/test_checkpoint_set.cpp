// Checkpoint sets of a run over MPI ranks (motes/distributed.h, docs/reliability.md "Checkpoints
// over MPI ranks"), at the rank count ctest runs this program with (1, 2 or 4): a run resumed from
// a set is bitwise the uninterrupted one, partitions and migrations between the checkpoint and the
// end included; a set of another rank count, a damaged or incomplete set, files of different sets
// and another scene are refused on every rank with the file and the reason.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "motes/devices.h"
#include "motes/distributed.h"
#include "motes/simulation.h"
#include "motes/workloads.h"
#include "mpi_support.h"
#include "sanitized_build.h"

namespace motes {
namespace {

namespace fs = std::filesystem;

using mpi_test::backend;
using mpi_test::example;
using mpi_test::opener;
using mpi_test::rank_in;
using mpi_test::shaken_settle;
using mpi_test::size_of;

/// A directory every rank sees (rank 0 names it), removed at the end.
class SharedDir {
 public:
  SharedDir() {
    std::string name;
    if (rank_in(MPI_COMM_WORLD) == 0) {
      std::string pattern = (fs::temp_directory_path() / "motes-set-XXXXXX").string();
      name = ::mkdtemp(pattern.data()) != nullptr ? pattern : std::string();
    }
    int length = static_cast<int>(name.size());
    MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
    name.resize(static_cast<std::size_t>(length));
    MPI_Bcast(name.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
    path_ = name;
    EXPECT_FALSE(path_.empty());
  }
  ~SharedDir() {
    MPI_Barrier(MPI_COMM_WORLD);
    std::error_code ec;
    if (rank_in(MPI_COMM_WORLD) == 0) fs::remove_all(path_, ec);
  }
  SharedDir(const SharedDir&) = delete;
  SharedDir& operator=(const SharedDir&) = delete;
  [[nodiscard]] std::string operator/(const std::string& name) const {
    return (path_ / name).string();
  }

 private:
  fs::path path_;
};

std::unique_ptr<DistributedSimulation> make(const Scene& scene, MPI_Comm comm,
                                            const DistributedOptions& options = {}) {
  Result<std::unique_ptr<DistributedSimulation>> d =
      DistributedSimulation::create(scene, comm, opener(), options);
  EXPECT_TRUE(d) << d.message();
  return d ? std::move(d).value() : nullptr;
}

/// The gathered state's arrays as bytes (rank 0; empty elsewhere).
std::vector<unsigned char> state_bytes(DistributedSimulation& d) {
  Result<Snapshot> s = d.gather(0);
  EXPECT_TRUE(s) << s.message();
  std::vector<unsigned char> out;
  if (!s) return out;
  for (const auto* v : {&s->particle_pos, &s->particle_vel, &s->body_pos, &s->body_quat,
                        &s->body_vel, &s->body_angmom, &s->body_angvel}) {
    const auto* p = reinterpret_cast<const unsigned char*>(v->data());
    out.insert(out.end(), p, p + v->size() * sizeof(shared::vec4));
  }
  return out;
}

CheckpointRun test_run() {
  CheckpointRun run;
  run.scene_path = "scene.json";
  run.scene_file = "/abs/scene.json";
  run.scene_hash = 0x1234567890abcdefull;
  run.output_dir = "/abs/out";
  run.output_format = "csv";
  run.every = 10;
  run.total_steps = 300;
  run.checkpoint_every = 100;
  run.checkpoint_dir = "/abs/out/checkpoints";
  run.series.frame_times = {0.0, 0.25, 1.0 / 3.0};
  run.series.particles_csv_bytes = 4321;
  return run;
}

std::vector<unsigned char> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

/// The words of the refusal of a set of `set` ranks over `run` ranks.
std::string fmt_set_of(int set, int run) {
  return "a checkpoint set of " + std::to_string(set) + " MPI ranks; this run has " +
         std::to_string(run);
}

/// `steps` in all against `first`, a set, a resume from it and the rest: the gathered state and
/// the partition counters equal, bit for bit; and (over several ranks) partitions and migrations
/// between the checkpoint and the end.
void expect_bitwise_resume(const Scene& scene, std::uint64_t first, std::uint64_t steps,
                           const DistributedOptions& options, bool partitions_after,
                           bool rigid_halos = false) {
  SharedDir dir;
  auto whole = make(scene, MPI_COMM_WORLD, options);
  ASSERT_TRUE(whole);
  ASSERT_TRUE(whole->step(steps));
  const std::vector<unsigned char> expected = state_bytes(*whole);
  const DistributedStats expected_stats = whole->stats();

  const std::string set = dir / "set";
  DistributedStats at_checkpoint;
  {
    auto part = make(scene, MPI_COMM_WORLD, options);
    ASSERT_TRUE(part);
    ASSERT_TRUE(part->step(first));
    at_checkpoint = part->stats();
    const Status saved = part->save_checkpoint(set, test_run());
    ASSERT_TRUE(saved) << saved.message();
  }
  Result<std::unique_ptr<DistributedSimulation>> resumed =
      DistributedSimulation::resume(scene, MPI_COMM_WORLD, opener(), set);
  ASSERT_TRUE(resumed) << resumed.message();
  DistributedSimulation& d = *resumed.value();
  EXPECT_EQ(d.steps(), first);
  EXPECT_EQ(d.stats().partitions, at_checkpoint.partitions);
  EXPECT_EQ(d.stats().halo_bytes, at_checkpoint.halo_bytes);
  ASSERT_TRUE(d.step(steps - first));
  const std::vector<unsigned char> got = state_bytes(d);
  EXPECT_EQ(d.stats().partitions, expected_stats.partitions);
  EXPECT_EQ(d.stats().migrations, expected_stats.migrations);
  EXPECT_EQ(d.stats().owned_bodies, expected_stats.owned_bodies);
  EXPECT_EQ(d.stats().halo_bytes, expected_stats.halo_bytes);
  if (rank_in(MPI_COMM_WORLD) == 0) {
    ASSERT_FALSE(expected.empty());
    EXPECT_TRUE(got == expected) << "the resumed run's state is not the uninterrupted run's";
  }
  if (size_of(MPI_COMM_WORLD) > 1 && partitions_after) {
    EXPECT_GT(expected_stats.partitions, at_checkpoint.partitions)
        << "no partition between the checkpoint and the end";
  }
  if (size_of(MPI_COMM_WORLD) > 1 && rigid_halos) {
    // Copies of rigid bodies at the checkpoint (the rank files hold their halo lists).
    std::uint64_t copies = 0;
    MPI_Allreduce(&at_checkpoint.halo_bodies, &copies, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    EXPECT_GT(copies, 0u) << "no halo copies at the checkpoint";
  }
  if (rank_in(MPI_COMM_WORLD) != 0) return;
  std::printf(
      "[ ranks %d ] %llu + %llu steps: partitions %llu at the checkpoint, %llu at the end\n",
      size_of(MPI_COMM_WORLD), static_cast<unsigned long long>(first),
      static_cast<unsigned long long>(steps - first),
      static_cast<unsigned long long>(at_checkpoint.partitions),
      static_cast<unsigned long long>(expected_stats.partitions));
}

TEST(CheckpointSet, ShakenSpheresResumeBitwise) {
  // A small margin: partitions every few steps at 2 and 4 ranks, spheres migrating between them.
  DistributedOptions often;
  often.margin = 0.002;
  expect_bitwise_resume(shaken_settle(), 60, 120, often, true);
}

TEST(CheckpointSet, EveryKindResumesBitwise) {
  // Soft bodies (cluster rotations), cloth and a rigid box (the mixed scene), dice (rigid bodies
  // copied to the other ranks), impulse contacts
  // (the plane contacts' accumulated impulses, every rigid body one group), with a small margin so
  // that the ranks partition at list rebuilds.
  const int n = size_of(MPI_COMM_WORLD);
  // The sanitizer build (tests/sanitized_build.h): a checkpoint at 50 steps of 100, the same paths.
  const std::uint64_t first = motes_test::sanitized_or<std::uint64_t>(100, 50);
  const std::uint64_t steps = 2 * first;
  DistributedOptions mixed;
  mixed.margin = 0.001;
  mixed.decomposition = std::array<int, 3>{n == 4 ? 2 : 1, 1, n == 4 ? 2 : n};
  {
    SCOPED_TRACE("mixed");
    expect_bitwise_resume(example("mixed"), first, steps, mixed, false);
  }
  {
    // Rigid bodies in the halos: their poses and momenta travel with their particles.
    SCOPED_TRACE("dice");
    expect_bitwise_resume(example("dice"), first, steps, {}, false, true);
  }
  DistributedOptions slabs;
  slabs.margin = 0.001;
  slabs.decomposition = std::array<int, 3>{n, 1, 1};
  {
    SCOPED_TRACE("impulse_dominoes");
    expect_bitwise_resume(example("impulse_dominoes"), first, steps, slabs, true);
  }
}

TEST(CheckpointSet, LayoutAndManifest) {
  SharedDir dir;
  auto d = make(shaken_settle(), MPI_COMM_WORLD);
  ASSERT_TRUE(d);
  ASSERT_TRUE(d->step(20));
  const std::string set = dir / "checkpoint-000000000020.mckset";
  ASSERT_TRUE(d->save_checkpoint(set, test_run()));
  Result<CheckpointSetInfo> info = read_checkpoint_set(set);
  ASSERT_TRUE(info) << info.message();
  EXPECT_EQ(info->version, kCheckpointSetVersion);
  EXPECT_EQ(info->ranks, size_of(MPI_COMM_WORLD));
  EXPECT_EQ(info->step, 20u);
  EXPECT_EQ(info->time, d->time());
  EXPECT_EQ(info->backend, backend());
  EXPECT_EQ(info->decomposition.cells, d->decomposition().cells);
  EXPECT_EQ(info->partitions, d->stats().partitions);
  const CheckpointRun run = test_run();
  EXPECT_EQ(info->run.scene_file, run.scene_file);
  EXPECT_EQ(info->run.scene_hash, run.scene_hash);
  EXPECT_EQ(info->run.series.frame_times, run.series.frame_times);
  EXPECT_EQ(info->run.series.particles_csv_bytes, run.series.particles_csv_bytes);
  ASSERT_EQ(info->rank.size(), static_cast<std::size_t>(size_of(MPI_COMM_WORLD)));
  // Each rank's line: its file (a checkpoint with its rank record) and its counters.
  const CheckpointSetInfo::Rank& mine =
      info->rank[static_cast<std::size_t>(rank_in(MPI_COMM_WORLD))];
  EXPECT_EQ(mine.owned_bodies, d->stats().owned_bodies);
  EXPECT_EQ(mine.halo_bytes, d->stats().halo_bytes);
  EXPECT_EQ(mine.has_file, d->stats().owned_bodies + d->stats().halo_bodies > 0);
  const std::string file = checkpoint_set_rank_file(set, rank_in(MPI_COMM_WORLD));
  EXPECT_EQ(fs::exists(file), mine.has_file);
  if (mine.has_file) {
    Result<CheckpointInfo> ck = read_checkpoint_info(file);
    ASSERT_TRUE(ck) << ck.message();
    EXPECT_EQ(ck->file_bytes, mine.file_bytes);
    EXPECT_EQ(ck->checksum, mine.checksum);
    EXPECT_EQ(ck->step, 20u);
    EXPECT_FALSE(ck->run.extension.empty());
    // The rank's own record, not rank 0's description of the run.
    EXPECT_TRUE(ck->run.series.frame_times.empty());
  }
  // Nothing left of the writing.
  EXPECT_FALSE(fs::exists(set + ".tmp"));
  for (const auto& e : fs::directory_iterator(set)) {
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(
        name == kCheckpointSetManifest ||
        (name.rfind("rank-", 0) == 0 && name.size() == 14 && name.compare(10, 4, ".mck") == 0))
        << name;
  }
  MPI_Barrier(MPI_COMM_WORLD);

  // A set of the same step written again (exchanged with the old one), and a write that a kill
  // interrupted (its .tmp directory) started again.
  if (rank_in(MPI_COMM_WORLD) == 0) {
    fs::create_directories(dir / "other.mckset.tmp");
    write_bytes(dir / "other.mckset.tmp/rank-00000.mck", {1, 2, 3});
  }
  ASSERT_TRUE(d->save_checkpoint(set, test_run()));
  ASSERT_TRUE(d->save_checkpoint(dir / "other.mckset", test_run()));
  EXPECT_FALSE(fs::exists(set + ".tmp"));
  EXPECT_FALSE(fs::exists(dir / "other.mckset.tmp"));
  for (const std::string& s : {set, dir / "other.mckset"}) {
    Result<std::unique_ptr<DistributedSimulation>> r =
        DistributedSimulation::resume(shaken_settle(), MPI_COMM_WORLD, opener(), s);
    ASSERT_TRUE(r) << r.message();
    EXPECT_EQ(r.value()->steps(), 20u);
  }
}

TEST(CheckpointSet, AnotherRankCountIsRefused) {
  const int n = size_of(MPI_COMM_WORLD);
  if (n < 2) GTEST_SKIP() << "needs 2 ranks or more";
  SharedDir dir;
  const int rank = rank_in(MPI_COMM_WORLD);
  // A set of every rank, resumed over one rank fewer; a set of rank 0 alone, resumed over all.
  auto d = make(shaken_settle(), MPI_COMM_WORLD);
  ASSERT_TRUE(d);
  ASSERT_TRUE(d->save_checkpoint(dir / "all", test_run()));
  d.reset();
  MPI_Comm fewer = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, rank < n - 1 ? 0 : MPI_UNDEFINED, rank, &fewer);
  if (fewer != MPI_COMM_NULL) {
    Result<std::unique_ptr<DistributedSimulation>> r =
        DistributedSimulation::resume(shaken_settle(), fewer, opener(), dir / "all");
    ASSERT_FALSE(r);
    EXPECT_NE(r.message().find(fmt_set_of(n, n - 1)), std::string::npos) << r.message();
    MPI_Comm_free(&fewer);
  }
  MPI_Comm alone = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, rank == 0 ? 0 : MPI_UNDEFINED, rank, &alone);
  if (alone != MPI_COMM_NULL) {
    auto one = make(shaken_settle(), alone);
    ASSERT_TRUE(one);
    ASSERT_TRUE(one->save_checkpoint(dir / "one", test_run()));
    MPI_Comm_free(&alone);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  Result<std::unique_ptr<DistributedSimulation>> r =
      DistributedSimulation::resume(shaken_settle(), MPI_COMM_WORLD, opener(), dir / "one");
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find(fmt_set_of(1, n)), std::string::npos) << r.message();
}

/// Resuming `set` is refused on every rank with the same message, which holds `what` (the file)
/// and `reason`.
void expect_refused(const Scene& scene, const std::string& set, const std::string& what,
                    const std::string& reason) {
  Result<std::unique_ptr<DistributedSimulation>> r =
      DistributedSimulation::resume(scene, MPI_COMM_WORLD, opener(), set);
  ASSERT_FALSE(r) << "accepted: " << set;
  EXPECT_NE(r.message().find(what), std::string::npos) << r.message();
  EXPECT_NE(r.message().find(reason), std::string::npos) << r.message();
  const std::uint64_t h = fnv1a64(r.message().data(), r.message().size());
  std::uint64_t low = 0;
  std::uint64_t high = 0;
  MPI_Allreduce(&h, &low, 1, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&h, &high, 1, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_EQ(low, high) << "the ranks were refused with different messages: " << r.message();
}

TEST(CheckpointSet, DamagedSetsAreRefusedOnEveryRank) {
  SharedDir dir;
  const int n = size_of(MPI_COMM_WORLD);
  const int last = n - 1;
  const Scene scene = shaken_settle();
  {
    auto d = make(scene, MPI_COMM_WORLD);
    ASSERT_TRUE(d);
    ASSERT_TRUE(d->step(30));
    ASSERT_TRUE(d->save_checkpoint(dir / "good", test_run()));
    ASSERT_TRUE(d->step(10));
    ASSERT_TRUE(d->save_checkpoint(dir / "later", test_run()));
  }
  Result<CheckpointSetInfo> info = read_checkpoint_set(dir / "good");
  ASSERT_TRUE(info) << info.message();
  ASSERT_TRUE(info->rank[static_cast<std::size_t>(last)].has_file);
  // A copy of the good set, damaged by rank 0 before any rank reads it.
  int copies = 0;
  const auto damaged = [&](const auto& damage) {
    const std::string set = dir / ("damaged" + std::to_string(++copies));
    if (rank_in(MPI_COMM_WORLD) == 0) {
      fs::copy(dir / "good", set, fs::copy_options::recursive);
      damage(set);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    return set;
  };
  const auto rank_file = [&](const std::string& set) {
    return checkpoint_set_rank_file(set, last);
  };
  const auto manifest = [](const std::string& set) {
    return (fs::path(set) / kCheckpointSetManifest).string();
  };
  const std::string prefix = n > 1 ? "rank " + std::to_string(last) + ": " : "";
  {
    SCOPED_TRACE("truncated rank file");
    const std::string set = damaged([&](const std::string& s) {
      std::vector<unsigned char> b = read_bytes(rank_file(s));
      b.resize(b.size() / 2);
      write_bytes(rank_file(s), b);
    });
    expect_refused(scene, set, prefix + rank_file(set), "truncated checkpoint");
  }
  {
    SCOPED_TRACE("bit flip in a rank file");
    const std::string set = damaged([&](const std::string& s) {
      std::vector<unsigned char> b = read_bytes(rank_file(s));
      b[b.size() / 3] ^= 0x20;
      write_bytes(rank_file(s), b);
    });
    expect_refused(scene, set, prefix + rank_file(set), "checksum mismatch");
  }
  {
    SCOPED_TRACE("missing rank file");
    const std::string set = damaged([&](const std::string& s) { fs::remove(rank_file(s)); });
    expect_refused(scene, set, prefix + rank_file(set),
                   "cannot open checkpoint: No such file or directory");
  }
  {
    SCOPED_TRACE("a rank file of another set");
    const std::string set = damaged([&](const std::string& s) {
      fs::copy_file(rank_file(dir / "later"), rank_file(s), fs::copy_options::overwrite_existing);
    });
    expect_refused(scene, set, prefix + rank_file(set), "not the file the set's manifest lists");
  }
  {
    SCOPED_TRACE("no manifest");
    const std::string set = damaged([&](const std::string& s) { fs::remove(manifest(s)); });
    expect_refused(scene, set, manifest(set), "the checkpoint set has no manifest");
  }
  {
    SCOPED_TRACE("truncated manifest");
    const std::string set = damaged([&](const std::string& s) {
      std::vector<unsigned char> b = read_bytes(manifest(s));
      b.resize(b.size() - 10);
      write_bytes(manifest(s), b);
    });
    expect_refused(scene, set, manifest(set), "truncated manifest");
  }
  {
    SCOPED_TRACE("bit flip in the manifest");
    const std::string set = damaged([&](const std::string& s) {
      std::vector<unsigned char> b = read_bytes(manifest(s));
      b[40] ^= 0x01;
      write_bytes(manifest(s), b);
    });
    expect_refused(scene, set, manifest(set), "corrupt manifest (checksum mismatch");
  }
  {
    SCOPED_TRACE("another version");
    const std::string set = damaged([&](const std::string& s) {
      std::vector<unsigned char> b = read_bytes(manifest(s));
      const std::uint32_t version = 7;
      std::memcpy(b.data() + 8, &version, 4);
      const std::uint64_t h = fnv1a64(b.data(), b.size() - 8);
      std::memcpy(b.data() + b.size() - 8, &h, 8);
      write_bytes(manifest(s), b);
    });
    expect_refused(scene, set, manifest(set),
                   "checkpoint set format version 7; this motes reads 1");
  }
  {
    SCOPED_TRACE("another scene: other materials");
    // The same bodies and bricks: each rank file's setup fingerprint.
    expect_refused(shaken_settle(1.5), dir / "good", "rank-00000.mck", "setup fingerprint");
  }
  {
    SCOPED_TRACE("another scene: other bodies");
    Scene moved = shaken_settle();
    for (BodySpec& b : moved.bodies) b.position *= 1.25;
    expect_refused(moved, dir / "good", manifest(dir / "good"),
                   "a checkpoint set of another scene");
  }
  expect_refused(scene, dir / "nowhere", dir / "nowhere", "no such checkpoint set");
}

}  // namespace
}  // namespace motes
