// Checkpoints (core/src/checkpoint.cpp, docs/reliability.md): a resume on the backend that wrote
// the checkpoint is bitwise the uninterrupted run, on another backend within the conformance
// tolerances; truncated, bit-flipped, wrong-version and foreign checkpoints are refused with a
// message naming the file and the reason, and leave the running state as it was.
//
// The scene (tests/data/checkpoint/mixed.json) holds every kind of state: two spinning rigid boxes,
// a free sphere, a soft cube of two quadratic clusters and a cloth with a pinned corner, all in
// contact with each other and the floor within 50 steps, so that between the checkpoint (step 100)
// and the end (step 200) the neighbour lists are rebuilt several times.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "motes/checkpoint.h"
#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/workloads.h"
#include "sanitized_build.h"
#include "shared/neighbours.h"
#include "shared/shape_matching.h"
#include "unit/test_support.h"

namespace {

namespace fs = std::filesystem;
using motes::Buffer;
using motes_test::TempDir;

using motes_test::has_device;
using motes_test::kMixedScene;

/// The device buffers a checkpoint holds (core/src/checkpoint.cpp), compared byte for byte.
constexpr Buffer kStateBuffers[] = {
    Buffer::ParticlePos,     Buffer::ParticleVel,    Buffer::BodyPos,       Buffer::BodyQuat,
    Buffer::BodyVel,         Buffer::BodyAngMom,     Buffer::BodyAngVel,    Buffer::ClusterFrames,
    Buffer::NeighbourRefPos, Buffer::NeighbourState, Buffer::NeighbourList, Buffer::NeighbourCount,
    Buffer::GridOrder,       Buffer::GridCellStart,  Buffer::SortedBody,    Buffer::ContactImpulse,
    Buffer::ImpulseStamp,
};

std::vector<unsigned char> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

std::uint64_t fnv1a(const unsigned char* p, std::size_t n) { return motes::fnv1a64(p, n); }

/// Makes a version 2 file's checksum right again after an edit (as a file made to pass it).
void fix_checksum(std::vector<unsigned char>& bytes) {
  const std::uint64_t h = fnv1a(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &h, 8);
}

/// The mixed scene, or W1 at 16 x 8 x 16 spheres pressed to 0.99 d (docs/conformance.md's
/// "settle_pressed"): 2,048 free spheres with up to six contacts each, where the order of the
/// force sums, and so the lists' order, shows in the bits; "impulse_pile": the same with impulse
/// contacts, whose accumulated impulses (the contacts' memory) are state too; "position_pile":
/// 512 spheres with position contacts at dt = 1/60 s, whose friction anchors are.
motes::Scene test_scene(const std::string& name) {
  if (name == "pressed_pile" || name == "impulse_pile" || name == "position_pile") {
    // The position pile is smaller and has 2 substeps a step: its 89 launches a frame would make
    // it the suite's slowest test on lavapipe at 2,048 spheres and 8 substeps.
    motes::Scene scene = name == "position_pile" ? motes::settle_workload(8, 8, 8)
                                                 : motes::settle_workload(16, 8, 16);
    for (motes::BodySpec& b : scene.bodies) b.position *= 0.9;
    if (name == "impulse_pile") {
      scene.settings.contact_model = motes::ContactModel::Impulses;
      for (motes::Material& m : scene.materials) m.restitution = 0.3;
      // On the floor from the start (its bottom layer's centres one radius up): with split
      // impulses the contacts keep only what the velocities need, so a pile pressed in the air
      // keeps nothing (its overlaps are pushed out by the pose alone), and the checkpoint would
      // hold no memory to restore. Resting on the floor, its contacts carry its weight.
      for (motes::BodySpec& b : scene.bodies) b.position.y() -= 0.9 * 0.011 - 0.005;
      // Its top layer rolls off across the others at 0.3 m/s: with the stack scale (2026-11-29)
      // the rest of the pile settles before the checkpoint, and the lists must still change
      // after it.
      double top = 0.0;
      for (const motes::BodySpec& b : scene.bodies) top = std::max(top, b.position.y());
      for (motes::BodySpec& b : scene.bodies) {
        if (b.position.y() > top - 0.005) b.velocity = Eigen::Vector3d(0.3, 0.0, 0.0);
      }
    }
    if (name == "position_pile") {
      scene.settings.contact_model = motes::ContactModel::Positions;
      scene.settings.dt = 1.0 / 60.0;
      scene.settings.substeps = 2;
      for (motes::Material& m : scene.materials) m.friction = 0.5;
    }
    return scene;
  }
  motes::Result<motes::Scene> scene = motes::load_scene_file(name);
  EXPECT_TRUE(scene) << scene.message();
  return scene ? scene.value() : motes::Scene{};
}

/// A simulation of a test scene on `backend` (OpenMP: 2 threads, every loop split).
std::unique_ptr<motes::Simulation> make(const std::string& backend,
                                        const std::string& scene_name = kMixedScene) {
  motes::DeviceOptions options;
  if (backend == "openmp") {
    options.cpu_threads = 2;
    options.cpu_min_parallel = 1;
  }
  auto device = motes::open_device(backend, -1, options);
  EXPECT_TRUE(device) << device.message();
  if (!device) return nullptr;
  auto sim = motes::Simulation::create(test_scene(scene_name), std::move(device).value());
  EXPECT_TRUE(sim) << sim.message();
  if (!sim) return nullptr;
  return std::move(sim).value();
}

/// Every state buffer's bytes.
std::vector<std::vector<unsigned char>> state_bytes(motes::Simulation& sim) {
  std::vector<std::vector<unsigned char>> out;
  for (const Buffer b : kStateBuffers) {
    std::vector<unsigned char> v(motes::buffer_layout(b, sim.sizes()).bytes());
    if (!v.empty()) {
      EXPECT_TRUE(sim.device().read(b, v.data(), v.size()));
    }
    out.push_back(std::move(v));
  }
  return out;
}

std::uint64_t hash_of(motes::Simulation& sim) {
  auto h = sim.state_hash();
  EXPECT_TRUE(h) << h.message();
  return h ? h.value() : 0;
}

class CheckpointResume : public ::testing::TestWithParam<std::string> {};

/// The largest |difference| of the particles' positions and velocities of two simulations.
void max_differences(motes::Simulation& a, motes::Simulation& b, double& dx, double& dv) {
  const auto sa = a.snapshot();
  const auto sb = b.snapshot();
  ASSERT_TRUE(sa && sb);
  dx = 0.0;
  dv = 0.0;
  const auto diff = [](float x, float y) { return std::fabs(double{x} - double{y}); };
  for (std::size_t i = 0; i < sa->particle_pos.size(); ++i) {
    const auto& p = sa->particle_pos[i];
    const auto& q = sb->particle_pos[i];
    const auto& u = sa->particle_vel[i];
    const auto& w = sb->particle_vel[i];
    dx = std::max({dx, diff(p.x, q.x), diff(p.y, q.y), diff(p.z, q.z)});
    dv = std::max({dv, diff(u.x, w.x), diff(u.y, w.y), diff(u.z, w.z)});
  }
}

// 200 steps against 100, a checkpoint, a new Simulation that loads it and 100 more: the same bits
// in every state buffer (and so the same state hash) on the backend that wrote it. On the mixed
// scene (every kind of state), on the pressed pile (where the lists' order shows), on the pile
// with impulse contacts (whose warm start reads the contacts' memory) and on the pile with
// position contacts (whose friction reads its anchors).
TEST_P(CheckpointResume, BitwiseAfter200StepsResumedAt100) {
  const std::string backend = GetParam();
  std::string why;
  if (!has_device(backend, why)) GTEST_SKIP() << "no " << backend << " device: " << why;
  TempDir tmp;
  // The sanitizer build (tests/sanitized_build.h): 60 steps and 60 more, the same paths (a list
  // rebuild after the checkpoint in each scene).
  const std::uint64_t half = motes_test::sanitized_or<std::uint64_t>(100, 60);
  for (const std::string& scene : {kMixedScene, std::string("pressed_pile"),
                                   std::string("impulse_pile"), std::string("position_pile")}) {
    SCOPED_TRACE(scene);
    const std::string path = tmp / "at100.mck";
    auto whole = make(backend, scene);
    ASSERT_TRUE(whole);
    ASSERT_TRUE(whole->step(half));
    const std::uint32_t builds_at_100 = whole->neighbour_stats().value().builds;
    ASSERT_TRUE(whole->save_state(path));
    ASSERT_TRUE(whole->step(half));
    const std::uint32_t builds_at_200 = whole->neighbour_stats().value().builds;
    // The test proves little unless the lists are rebuilt after the checkpoint and things touch.
    EXPECT_GE(builds_at_200 - builds_at_100, 1u) << "no list rebuild after the checkpoint";
    std::vector<motes::shared::vec4> force(whole->particle_count());
    ASSERT_TRUE(whole->device().read(Buffer::ParticleForce, force.data(), force.size() * 16));
    auto touching = std::count_if(force.begin(), force.end(), [](const auto& f) {
      return f.x != 0.0f || f.y != 0.0f || f.z != 0.0f;
    });
    if (whole->sizes().impulse != 0) {
      // Impulses: particles with a contact that pushes (an accumulated normal impulse), in any
      // of their slots (k Nr + i); positions: with a friction anchor.
      const bool positions = whole->settings().contact_model == motes::ContactModel::Positions;
      const motes::BufferLayout layout =
          motes::buffer_layout(Buffer::ContactImpulse, whole->sizes());
      std::vector<motes::shared::vec4> acc(layout.count);
      ASSERT_TRUE(whole->device().read(Buffer::ContactImpulse, acc.data(), layout.bytes()));
      const std::size_t nr = whole->sizes().rigid_particles;
      std::vector<bool> pushed(nr, false);
      for (std::size_t k = 0; k < acc.size(); ++k)
        pushed[k % nr] = pushed[k % nr] || acc[k].w > 0.0f ||
                         (positions && (acc[k].x != 0.0f || acc[k].y != 0.0f || acc[k].z != 0.0f));
      touching = std::count(pushed.begin(), pushed.end(), true);
    }
    // The pile with impulses has relaxed its pressed contacts by step 200 (the position
    // correction pushes the overlaps out): 144 of 2,048 spheres still push on openmp.
    const std::size_t at_least = whole->particle_count() / (whole->sizes().impulse != 0 ? 20 : 5);
    EXPECT_GT(touching, static_cast<std::ptrdiff_t>(at_least))
        << "too few particles in contact at step 200";

    auto resumed = make(backend, scene);
    ASSERT_TRUE(resumed);
    ASSERT_TRUE(resumed->load_state(path));
    EXPECT_EQ(resumed->steps(), half);
    EXPECT_EQ(resumed->time(), static_cast<double>(half) * resumed->settings().dt);
    ASSERT_TRUE(resumed->step(half));
    EXPECT_EQ(hash_of(*resumed), hash_of(*whole));
    const auto a = state_bytes(*whole);
    const auto b = state_bytes(*resumed);
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_TRUE(a[k] == b[k]) << motes::buffer_name(kStateBuffers[k]) << " differs";
    }
    if (scene == kMixedScene) {
      const auto snap = resumed->snapshot();
      ASSERT_TRUE(snap);
      EXPECT_EQ(snap->cluster_rotation.size(), 2u);
      for (const auto& q : snap->cluster_rotation) EXPECT_NE(q.w, 1.0f) << "a cluster never turned";
    }
  }
}

// What a checkpoint without the lists gives (version 1, and every load before version 2): the
// lists rebuilt at the resume step, from other reference positions, so that later rebuilds come at
// other steps and, where a particle has crossed into another grid cell in between, list its
// neighbours in another order and sum their forces in another order. Measured on openmp: in the
// pressed pile, 6 of 12 resumes (every 37 steps from step 100) end in another state 100 steps
// later; in the mixed scene, the domino chain and soft.json none of 12 (too few particles with
// three or more contacts crossing cells). Version 2 saves the lists (and the grid of their build)
// raw instead, and the test above finds every bit equal.
TEST_P(CheckpointResume, RebuildingTheListsAtTheResumeChangesTheState) {
  const std::string backend = GetParam();
  std::string why;
  if (!has_device(backend, why)) GTEST_SKIP() << "no " << backend << " device: " << why;
  TempDir tmp;
  const std::string path = tmp / "at100.mck";
  auto whole = make(backend, "pressed_pile");
  ASSERT_TRUE(whole);
  ASSERT_TRUE(whole->step(100));
  ASSERT_TRUE(whole->save_state(path));
  ASSERT_TRUE(whole->step(100));

  auto rebuilt = make(backend, "pressed_pile");
  ASSERT_TRUE(rebuilt);
  ASSERT_TRUE(rebuilt->load_state(path));
  std::uint32_t words[4] = {};
  ASSERT_TRUE(rebuilt->device().read(Buffer::NeighbourState, words, sizeof words));
  EXPECT_EQ(words[MOTES_NEIGHBOUR_REBUILD], 0u) << "step 100 asked for no rebuild";
  words[MOTES_NEIGHBOUR_REBUILD] = 1;
  ASSERT_TRUE(rebuilt->device().write(Buffer::NeighbourState, words, sizeof words));
  ASSERT_TRUE(rebuilt->step(100));
  EXPECT_NE(hash_of(*rebuilt), hash_of(*whole));
  double dx = 0.0;
  double dv = 0.0;
  max_differences(*whole, *rebuilt, dx, dv);
  std::printf(
      "[checkpoint] %s: lists rebuilt at the resume: max |dx| %.3g m, |dv| %.3g m/s after 100 "
      "steps\n",
      backend.c_str(), dx, dv);
}

INSTANTIATE_TEST_SUITE_P(Backends, CheckpointResume, ::testing::Values("openmp", "vulkan", "cuda"),
                         [](const auto& param) { return param.param; });

class CheckpointAcrossBackends : public ::testing::TestWithParam<std::string> {};

// An OpenMP checkpoint resumed on another backend goes on within the conformance suite's
// tolerances (docs/conformance.md, "Whole scenes"), scaled to the 100 steps after it.
TEST_P(CheckpointAcrossBackends, OpenmpCheckpointGoesOnElsewhere) {
  const std::string backend = GetParam();
  std::string why;
  if (!has_device(backend, why)) GTEST_SKIP() << "no " << backend << " device: " << why;
  TempDir tmp;
  const std::string path = tmp / "at100.mck";
  auto whole = make("openmp");
  ASSERT_TRUE(whole);
  ASSERT_TRUE(whole->step(100));
  ASSERT_TRUE(whole->save_state(path));
  ASSERT_TRUE(whole->step(100));
  auto other = make(backend);
  ASSERT_TRUE(other);
  ASSERT_TRUE(other->load_state(path));
  ASSERT_TRUE(other->step(100));
  ASSERT_TRUE(other->check_finite());
  double dx = 0.0;
  double dv = 0.0;
  max_differences(*whole, *other, dx, dv);
  std::printf("[checkpoint] openmp -> %s: max |dx| %.3g m, |dv| %.3g m/s after 100 steps\n",
              backend.c_str(), dx, dv);
  // The suite's bounds after 50 steps: |dx| <= 2e-5 m; velocities of projected particles (cloth,
  // soft) 32 ulp / dt of the largest coordinate (0.06 m here: ulp 3.7e-9, dt 2.5e-5 s: 4.8e-3
  // m/s). Twice that for 100 steps.
  EXPECT_LE(dx, 4e-5);
  EXPECT_LE(dv, 1e-2);
}

INSTANTIATE_TEST_SUITE_P(Backends, CheckpointAcrossBackends, ::testing::Values("vulkan", "cuda"),
                         [](const auto& param) { return param.param; });

/// A checkpoint of the mixed scene at step 60 on OpenMP, and the simulation that wrote it.
struct Saved {
  std::unique_ptr<motes::Simulation> sim;
  std::string path;
};

Saved saved_at_60(const TempDir& tmp) {
  Saved s;
  s.sim = make("openmp");
  s.path = tmp / "at60.mck";
  EXPECT_TRUE(s.sim->step(60));
  motes::CheckpointRun run;
  run.scene_path = "mixed.json";
  run.scene_file = kMixedScene;
  run.scene_hash = motes::scene_file_hash(kMixedScene).value();
  run.output_dir = "/some/out";
  run.output_format = "csv";
  run.every = 7;
  run.total_steps = 1000;
  run.checkpoint_every = 30;
  run.checkpoint_dir = "/some/out/checkpoints";
  run.series.frame_times = {0.0, 0.5, 1.0 / 3.0};
  run.series.particles_csv_bytes = 12345;
  run.series.bodies_csv_bytes = 678;
  EXPECT_TRUE(s.sim->save_state(s.path, run));
  return s;
}

TEST(Checkpoint, InfoReadsBackWithoutASimulation) {
  TempDir tmp;
  const Saved s = saved_at_60(tmp);
  auto info = motes::read_checkpoint_info(s.path);
  ASSERT_TRUE(info) << info.message();
  EXPECT_EQ(info->version, motes::kCheckpointVersion);
  EXPECT_EQ(info->step, 60u);
  EXPECT_EQ(info->particles, s.sim->particle_count());
  EXPECT_EQ(info->bodies, s.sim->body_count());
  EXPECT_EQ(info->setup_hash, s.sim->setup_hash());
  EXPECT_EQ(info->backend, "openmp");
  EXPECT_EQ(info->file_bytes, fs::file_size(s.path));
  EXPECT_EQ(info->run.scene_path, "mixed.json");
  EXPECT_EQ(info->run.scene_file, kMixedScene);
  EXPECT_EQ(info->run.scene_hash, motes::scene_file_hash(kMixedScene).value());
  EXPECT_EQ(info->run.output_dir, "/some/out");
  EXPECT_EQ(info->run.output_format, "csv");
  EXPECT_EQ(info->run.every, 7u);
  EXPECT_EQ(info->run.total_steps, 1000u);
  EXPECT_EQ(info->run.checkpoint_every, 30u);
  EXPECT_EQ(info->run.checkpoint_dir, "/some/out/checkpoints");
  EXPECT_EQ(info->run.series.frame_times, (std::vector<double>{0.0, 0.5, 1.0 / 3.0}));
  EXPECT_EQ(info->run.series.particles_csv_bytes, 12345u);
  EXPECT_EQ(info->run.series.bodies_csv_bytes, 678u);
  // Atomic write: nothing left beside it.
  EXPECT_FALSE(fs::exists(s.path + ".tmp"));
}

/// load_state refuses `path` with a message holding the file's name and `reason`, and leaves the
/// simulation's state as it was; read_checkpoint_info refuses it too unless the file is sound
/// (`sound`: only its content does not fit this simulation).
void expect_refused(motes::Simulation& sim, const std::string& path, const std::string& reason,
                    bool sound = false) {
  const std::uint64_t before = hash_of(sim);
  const std::uint64_t steps = sim.steps();
  const motes::Status s = sim.load_state(path);
  ASSERT_FALSE(s) << "accepted: " << path;
  EXPECT_NE(s.message().find(path), std::string::npos) << s.message();
  EXPECT_NE(s.message().find(reason), std::string::npos) << s.message();
  EXPECT_EQ(hash_of(sim), before);
  EXPECT_EQ(sim.steps(), steps);
  auto info = motes::read_checkpoint_info(path);
  if (!sound) {
    ASSERT_FALSE(info);
    EXPECT_NE(info.message().find(reason), std::string::npos) << info.message();
  }
}

TEST(Checkpoint, TruncatedIsRefused) {
  TempDir tmp;
  const Saved s = saved_at_60(tmp);
  const std::vector<unsigned char> bytes = read_bytes(s.path);
  for (const std::size_t keep :
       {bytes.size() - 1, bytes.size() / 2, std::size_t{100}, std::size_t{40}}) {
    SCOPED_TRACE(keep);
    const std::string cut = tmp / "cut.mck";
    write_bytes(cut, std::vector<unsigned char>(bytes.begin(), bytes.begin() + keep));
    expect_refused(*s.sim, cut, "truncated");
  }
  write_bytes(tmp / "short.mck", std::vector<unsigned char>(bytes.begin(), bytes.begin() + 5));
  expect_refused(*s.sim, tmp / "short.mck", "not a motes checkpoint");
  write_bytes(tmp / "empty.mck", {});
  expect_refused(*s.sim, tmp / "empty.mck", "not a motes checkpoint");
  expect_refused(*s.sim, tmp / "missing.mck", "cannot open");
}

TEST(Checkpoint, BitFlipsAreRefused) {
  TempDir tmp;
  const Saved s = saved_at_60(tmp);
  const std::vector<unsigned char> bytes = read_bytes(s.path);
  // One bit in the payload (a particle position), in the run record, in the step, in the checksum.
  for (const std::size_t at :
       {bytes.size() / 2, std::size_t{100}, std::size_t{24}, bytes.size() - 3}) {
    SCOPED_TRACE(at);
    std::vector<unsigned char> flipped = bytes;
    flipped[at] ^= 0x10;
    write_bytes(tmp / "flipped.mck", flipped);
    expect_refused(*s.sim, tmp / "flipped.mck", "checksum mismatch");
  }
}

TEST(Checkpoint, OtherVersionsAreRefused) {
  TempDir tmp;
  const Saved s = saved_at_60(tmp);
  std::vector<unsigned char> bytes = read_bytes(s.path);
  for (const std::uint32_t version : {0u, 4u, 0x03000000u}) {
    SCOPED_TRACE(version);
    std::memcpy(bytes.data() + 8, &version, 4);
    fix_checksum(bytes);
    write_bytes(tmp / "version.mck", bytes);
    expect_refused(*s.sim, tmp / "version.mck",
                   "checkpoint format version " + std::to_string(version) +
                       "; this motes reads versions 1 to 3");
  }
  std::vector<unsigned char> foreign = read_bytes(s.path);
  foreign[3] = 'X';
  write_bytes(tmp / "foreign.mck", foreign);
  expect_refused(*s.sim, tmp / "foreign.mck", "not a motes checkpoint");
}

TEST(Checkpoint, AnotherScenesCheckpointIsRefused) {
  TempDir tmp;
  const Saved s = saved_at_60(tmp);
  // Other sizes.
  auto small = make("openmp", std::string(MOTES_TEST_DATA_DIR) + "/cli/small.json");
  ASSERT_TRUE(small);
  expect_refused(*small, s.path, "checkpoint of another scene", true);
  // The same sizes, another stiffness: the setup fingerprint.
  motes::Result<motes::Scene> scene = motes::load_scene_file(kMixedScene);
  ASSERT_TRUE(scene);
  for (motes::Material& m : scene->materials) m.stiffness *= 1.5;
  auto stiffer = motes::Simulation::create(scene.value(), motes::open_device("openmp").value());
  ASSERT_TRUE(stiffer);
  EXPECT_NE(stiffer.value()->setup_hash(), s.sim->setup_hash());
  expect_refused(*stiffer.value(), s.path, "setup fingerprint", true);
  // The same scene on another backend has the same fingerprint.
  std::string why;
  if (has_device("vulkan", why)) {
    auto vulkan = make("vulkan");
    ASSERT_TRUE(vulkan);
    EXPECT_EQ(vulkan->setup_hash(), s.sim->setup_hash());
  }
}

TEST(Checkpoint, HashCorrectButImpossibleContentIsRefused) {
  TempDir tmp;
  const Saved s = saved_at_60(tmp);
  const std::vector<unsigned char> bytes = read_bytes(s.path);
  auto info = motes::read_checkpoint_info(s.path);
  ASSERT_TRUE(info);
  // The first particle's radius (ParticlePos.w): the first section's data starts after the
  // header, the run record and the section's 48-byte header (its buffer's name in 32 bytes,
  // element bytes, 0, bytes).
  std::uint64_t record = 0;
  std::memcpy(&record, bytes.data() + 88, 8);
  const std::size_t first_particle = 96 + record + 48;
  std::vector<unsigned char> radius = bytes;
  const float big = 1.0f;
  std::memcpy(radius.data() + first_particle + 12, &big, 4);
  fix_checksum(radius);
  write_bytes(tmp / "radius.mck", radius);
  expect_refused(*s.sim, tmp / "radius.mck", "radii or masses", true);
  // A neighbour list entry beyond the particles: find the NeighbourList section.
  std::size_t at = 96 + record;
  std::vector<unsigned char> list = bytes;
  const std::uint32_t n = s.sim->particle_count();
  bool found = false;
  while (at + 48 <= bytes.size() - 8) {
    const std::string buffer(reinterpret_cast<const char*>(bytes.data() + at));
    std::uint64_t size = 0;
    std::memcpy(&size, bytes.data() + at + 40, 8);
    if (buffer == "NeighbourCount") {
      // Give particle 0 one listed neighbour, and make that entry n (out of range).
      const std::uint32_t one = 1;
      std::memcpy(list.data() + at + 48, &one, 4);
      found = true;
    }
    if (buffer == "NeighbourList") std::memcpy(list.data() + at + 48, &n, 4);
    at += 48 + size;
  }
  ASSERT_TRUE(found);
  fix_checksum(list);
  write_bytes(tmp / "list.mck", list);
  expect_refused(*s.sim, tmp / "list.mck", "neighbour list entry out of range", true);
}

/// A version 2 run record by the documented layout (docs/reliability.md): strings as a u32
/// length and the bytes, counts as u64, frame times as doubles.
std::vector<unsigned char> record_by_hand(const std::string& backend,
                                          const motes::CheckpointRun& run) {
  std::vector<unsigned char> out;
  const auto raw = [&out](const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    out.insert(out.end(), c, c + n);
  };
  const auto str = [&](const std::string& s) {
    const auto n = static_cast<std::uint32_t>(s.size());
    raw(&n, 4);
    raw(s.data(), s.size());
  };
  const auto u64 = [&](std::uint64_t v) { raw(&v, 8); };
  str(backend);
  str(run.scene_path);
  str(run.scene_file);
  u64(run.scene_hash);
  str(run.output_dir);
  str(run.output_format);
  u64(run.every);
  u64(run.total_steps);
  u64(run.checkpoint_every);
  str(run.checkpoint_dir);
  u64(run.series.particles_csv_bytes);
  u64(run.series.bodies_csv_bytes);
  u64(run.series.frame_times.size());
  for (const double t : run.series.frame_times) raw(&t, 8);
  return out;
}

// A single process's run record ends where it did before extensions existed (so its checkpoints
// keep their bytes); an extension follows it as a u64 length and its bytes, and reads back.
TEST(Checkpoint, RunRecordExtensionOnlyWhenGiven) {
  TempDir tmp;
  const Saved s = saved_at_60(tmp);
  auto info = motes::read_checkpoint_info(s.path);
  ASSERT_TRUE(info) << info.message();
  EXPECT_TRUE(info->run.extension.empty());
  const std::vector<unsigned char> plain = record_by_hand("openmp", info->run);
  EXPECT_EQ(motes::encode_checkpoint_run("openmp", info->run), plain);
  const std::vector<unsigned char> bytes = read_bytes(s.path);
  std::uint64_t record = 0;
  std::uint32_t sections = 0;
  std::memcpy(&record, bytes.data() + 88, 8);
  std::memcpy(&sections, bytes.data() + 84, 4);
  EXPECT_EQ(record, plain.size());
  EXPECT_EQ(sections, 18u);
  EXPECT_TRUE(std::equal(plain.begin(), plain.end(), bytes.begin() + 96));
  std::uint64_t last = 0;
  std::memcpy(&last, bytes.data() + bytes.size() - 8, 8);
  EXPECT_EQ(info->checksum, last);

  motes::CheckpointRun run = info->run;
  run.extension = {1, 2, 3, 0, 255};
  std::vector<unsigned char> extended = plain;
  const std::uint64_t n = run.extension.size();
  extended.insert(extended.end(), reinterpret_cast<const unsigned char*>(&n),
                  reinterpret_cast<const unsigned char*>(&n) + 8);
  extended.insert(extended.end(), run.extension.begin(), run.extension.end());
  EXPECT_EQ(motes::encode_checkpoint_run("openmp", run), extended);
  std::string backend;
  motes::CheckpointRun back;
  ASSERT_TRUE(motes::decode_checkpoint_run(extended.data(), extended.size(), backend, back));
  EXPECT_EQ(backend, "openmp");
  EXPECT_EQ(back.extension, run.extension);
  EXPECT_EQ(back.series.frame_times, run.series.frame_times);
  // A cut extension, or bytes after it, is not a record.
  EXPECT_FALSE(motes::decode_checkpoint_run(extended.data(), extended.size() - 1, backend, back));
  extended.push_back(0);
  EXPECT_FALSE(motes::decode_checkpoint_run(extended.data(), extended.size(), backend, back));

  // Saved with it, the file holds it and loads as before.
  const std::string path = tmp / "extended.mck";
  ASSERT_TRUE(s.sim->save_state(path, run));
  auto with = motes::read_checkpoint_info(path);
  ASSERT_TRUE(with) << with.message();
  EXPECT_EQ(with->run.extension, run.extension);
  EXPECT_EQ(with->file_bytes, bytes.size() + 8 + run.extension.size());
  auto other = make("openmp");
  ASSERT_TRUE(other);
  ASSERT_TRUE(other->load_state(path));
  EXPECT_EQ(hash_of(*other), hash_of(*s.sim));
}

// One rank's simulation of a run over MPI ranks (created with HaloLists) has a partition
// reference, from which particles_displacement decides the next partition: its checkpoint holds
// it as a 19th section, a resume gets the same displacements, and the two kinds of checkpoint do
// not load into each other's simulations.
TEST(Checkpoint, ARanksCheckpointKeepsThePartitionReference) {
  TempDir tmp;
  const motes::Scene scene = test_scene(kMixedScene);
  motes::HaloLists lists;  // no halo: a rank that holds the whole scene
  const auto rank_sim = [&]() -> std::unique_ptr<motes::Simulation> {
    auto sim = motes::Simulation::create(scene, motes::open_device("openmp").value(), lists);
    EXPECT_TRUE(sim) << sim.message();
    return sim ? std::move(sim).value() : nullptr;
  };
  auto a = rank_sim();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->sizes().partition, 1u);
  ASSERT_TRUE(a->step(30));
  // A partition at step 30: the reference becomes the positions there.
  auto at30 = a->snapshot();
  ASSERT_TRUE(at30);
  ASSERT_TRUE(a->write_state(at30.value()));
  ASSERT_TRUE(a->step(30));
  const std::string path = tmp / "rank.mck";
  ASSERT_TRUE(a->save_state(path));
  const std::vector<unsigned char> bytes = read_bytes(path);
  std::uint32_t sections = 0;
  std::memcpy(&sections, bytes.data() + 84, 4);
  EXPECT_EQ(sections, 19u);

  // The same 60 steps without the partition: displacements from the start.
  auto unpartitioned = rank_sim();
  ASSERT_TRUE(unpartitioned);
  ASSERT_TRUE(unpartitioned->step(60));
  EXPECT_EQ(hash_of(*unpartitioned), hash_of(*a));
  auto from_start = unpartitioned->partition_displacement();

  auto b = rank_sim();
  ASSERT_TRUE(b);
  ASSERT_TRUE(b->load_state(path)) << path;
  auto da = a->partition_displacement();
  auto db = b->partition_displacement();
  ASSERT_TRUE(da && db && from_start);
  EXPECT_GT(da.value(), 0.0);
  EXPECT_EQ(da.value(), db.value());
  EXPECT_NE(from_start.value(), db.value()) << "the reference is the start's, not step 30's";
  ASSERT_TRUE(a->step(40));
  ASSERT_TRUE(b->step(40));
  EXPECT_EQ(hash_of(*a), hash_of(*b));
  EXPECT_EQ(a->partition_displacement().value(), b->partition_displacement().value());

  auto plain = make("openmp");
  ASSERT_TRUE(plain);
  expect_refused(*plain, path, "one rank's checkpoint of a run over MPI ranks", true);
  const Saved s = saved_at_60(tmp);
  auto c = rank_sim();
  ASSERT_TRUE(c);
  expect_refused(*c, s.path, "a single process's checkpoint", true);
}

// A section names its buffer (version 3); a name that is no buffer's is refused, naming it.
TEST(Checkpoint, SectionsNameTheirBuffers) {
  for (std::size_t i = 0; i < motes::kBufferCount; ++i) {
    const std::string name = motes::buffer_name(static_cast<Buffer>(i));
    EXPECT_LT(name.size(), 32u) << name << ": longer than a section's name field";
    EXPECT_EQ(motes::buffer_from_name(name), static_cast<Buffer>(i)) << name;
  }
  TempDir tmp;
  const Saved s = saved_at_60(tmp);
  std::vector<unsigned char> bytes = read_bytes(s.path);
  std::uint64_t record = 0;
  std::memcpy(&record, bytes.data() + 88, 8);
  const std::size_t first = 96 + record;
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(bytes.data() + first)), "ParticlePos");
  std::memcpy(bytes.data() + first, "ParticlePosition", 16);
  fix_checksum(bytes);
  write_bytes(tmp / "renamed.mck", bytes);
  expect_refused(*s.sim, tmp / "renamed.mck", "a section of unknown buffer 'ParticlePosition'",
                 true);
}

// A file written before BodyPosLow was saved (its last section, the centres' parts below their
// floats, which impulse contacts keep) still loads, with zeros there: the impulse pile's
// checkpoint without that section loads into the same state but BodyPosLow, which reads zero.
TEST(Checkpoint, FilesWithoutBodyPosLowLoadWithZeros) {
  TempDir tmp;
  auto a = make("openmp", "impulse_pile");
  ASSERT_TRUE(a);
  ASSERT_TRUE(a->step(40));
  const std::string path = tmp / "full.mck";
  ASSERT_TRUE(a->save_state(path));
  std::vector<unsigned char> bytes = read_bytes(path);
  const std::size_t bodies = a->sizes().bodies;
  ASSERT_GT(bodies, 0u);
  // The last section: a 48-byte header (name, element bytes, 0, bytes), then its bytes.
  const std::size_t last = bytes.size() - 8 - (48 + 16 * bodies);
  ASSERT_EQ(std::string(reinterpret_cast<const char*>(bytes.data() + last)), "BodyPosLow");
  bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(last), bytes.end() - 8);
  const std::uint32_t sections = 17;
  std::memcpy(bytes.data() + 84, &sections, 4);
  const std::uint64_t file_bytes = bytes.size();
  std::memcpy(bytes.data() + 16, &file_bytes, 8);
  fix_checksum(bytes);
  write_bytes(tmp / "old.mck", bytes);
  std::vector<motes::shared::vec4> low(bodies, motes::shared::vec4(1.0f));
  auto b = make("openmp", "impulse_pile");
  ASSERT_TRUE(b);
  ASSERT_TRUE(b->step(3));  // its own BodyPosLow, which the load must clear
  ASSERT_TRUE(b->load_state(tmp / "old.mck")) << "a file without BodyPosLow";
  ASSERT_TRUE(b->device().read(Buffer::BodyPosLow, low.data(), low.size() * 16));
  for (const motes::shared::vec4& v : low) {
    EXPECT_EQ(v.x, 0.0f);
    EXPECT_EQ(v.y, 0.0f);
    EXPECT_EQ(v.z, 0.0f);
  }
  const auto want = a->snapshot();
  const auto got = b->snapshot();
  ASSERT_TRUE(want && got);
  EXPECT_EQ(got->particle_pos.size(), want->particle_pos.size());
  for (std::size_t i = 0; i < want->particle_pos.size(); ++i) {
    EXPECT_EQ(got->particle_pos[i].x, want->particle_pos[i].x) << i;
  }
  EXPECT_TRUE(b->step(10));
}

// tests/data/checkpoint/mixed-v2-step300.mck: a version 2 checkpoint (sections numbered by the
// Buffer enum of its day) that motes 3827e7f wrote of mixed.json after 300 steps on openmp
// (`motes run mixed.json --backend openmp --threads 1 --steps 300 --checkpoint-every 300`). It
// loads into the same bits as 300 steps run here, and goes on the same.
TEST(Checkpoint, Version2FilesResumeBitwise) {
  const std::string path = std::string(MOTES_TEST_DATA_DIR) + "/checkpoint/mixed-v2-step300.mck";
  auto info = motes::read_checkpoint_info(path);
  ASSERT_TRUE(info) << info.message();
  EXPECT_EQ(info->version, 2u);
  EXPECT_EQ(info->step, 300u);
  auto whole = make("openmp");
  ASSERT_TRUE(whole);
  ASSERT_TRUE(whole->step(300));
  auto resumed = make("openmp");
  ASSERT_TRUE(resumed);
  ASSERT_TRUE(resumed->load_state(path));
  EXPECT_EQ(resumed->steps(), 300u);
  const auto a = state_bytes(*whole);
  const auto b = state_bytes(*resumed);
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_TRUE(a[k] == b[k]) << motes::buffer_name(kStateBuffers[k]) << " differs";
  }
  ASSERT_TRUE(whole->step(100));
  ASSERT_TRUE(resumed->step(100));
  EXPECT_EQ(hash_of(*resumed), hash_of(*whole));
}

TEST(Checkpoint, Version1FilesStillLoad) {
  // motes bench's cached states: the scene-ordered body and particle arrays (no lists, no cluster
  // rotations); the lists are rebuilt at the next step.
  TempDir tmp;
  auto sim = make("openmp");
  ASSERT_TRUE(sim);
  ASSERT_TRUE(sim->step(30));
  const auto snap = sim->snapshot();
  ASSERT_TRUE(snap);
  std::vector<unsigned char> payload;
  for (const auto* v : {&snap->body_pos, &snap->body_quat, &snap->body_vel, &snap->body_angmom,
                        &snap->body_angvel, &snap->particle_pos, &snap->particle_vel}) {
    const auto* p = reinterpret_cast<const unsigned char*>(v->data());
    payload.insert(payload.end(), p, p + v->size() * 16);
  }
  std::vector<unsigned char> file(48, 0);
  const std::uint32_t words[4] = {1, sim->particle_count(), sim->body_count(), 0};
  const std::uint64_t step = 30;
  const double time = sim->time();
  const std::uint64_t bytes = payload.size();
  std::memcpy(file.data(), "MOTESCK1", 8);
  std::memcpy(file.data() + 8, words, 16);
  std::memcpy(file.data() + 24, &step, 8);
  std::memcpy(file.data() + 32, &time, 8);
  std::memcpy(file.data() + 40, &bytes, 8);
  file.insert(file.end(), payload.begin(), payload.end());
  const std::uint64_t h = fnv1a(payload.data(), payload.size());
  file.insert(file.end(), reinterpret_cast<const unsigned char*>(&h),
              reinterpret_cast<const unsigned char*>(&h) + 8);
  write_bytes(tmp / "v1.mck", file);
  auto other = make("openmp");
  ASSERT_TRUE(other);
  ASSERT_TRUE(other->load_state(tmp / "v1.mck"));
  EXPECT_EQ(other->steps(), 30u);
  EXPECT_EQ(hash_of(*other), hash_of(*sim));
  auto info = motes::read_checkpoint_info(tmp / "v1.mck");
  ASSERT_TRUE(info) << info.message();
  EXPECT_EQ(info->version, 1u);
  EXPECT_EQ(info->step, 30u);
  file[60] ^= 1;
  write_bytes(tmp / "v1.mck", file);
  expect_refused(*other, tmp / "v1.mck", "checksum mismatch");
}

}  // namespace
