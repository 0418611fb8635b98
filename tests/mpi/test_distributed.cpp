// One scene over 1, 2 and 4 MPI ranks against the same scene on one Simulation (docs/scale-out.md):
// ctest runs this program under mpirun at each rank count (tests/CMakeLists.txt). Backend:
// MOTES_MPI_BACKEND (default openmp).
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "motes/decomposition.h"
#include "motes/devices.h"
#include "motes/distributed.h"
#include "motes/simulation.h"
#include "motes/workloads.h"
#include "mpi_support.h"
#include "sanitized_build.h"

namespace motes {
namespace {

using mpi_test::backend;
using mpi_test::example;
using mpi_test::opener;
using mpi_test::shaken_settle;

int world_rank() { return mpi_test::rank_in(MPI_COMM_WORLD); }
int world_size() { return mpi_test::size_of(MPI_COMM_WORLD); }

/// The scene's first `count` dominoes (examples/scenes/dominoes.json): the chain falls across
/// the rank boundaries along x within the steps the test runs.
Scene short_domino_chain(std::size_t count) {
  Result<Scene> scene = load_scene_file(MOTES_SOURCE_DIR "/examples/scenes/dominoes.json");
  EXPECT_TRUE(scene) << scene.message();
  Scene s = scene.value();
  std::vector<BodySpec> kept;
  for (const BodySpec& b : s.bodies) {
    // The floor and other static bodies stay; dynamic dominoes up to `count`.
    if (b.kind == BodyKind::Static || kept.size() < count) kept.push_back(b);
  }
  s.bodies = kept;
  return s;
}

/// Pairs of particles that touch (centre distance below the sum of the radii), by a sweep along x:
/// the particles in order of x, each against those after it within its radius and the largest.
std::set<std::pair<std::uint32_t, std::uint32_t>> touching(const Snapshot& s) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  const std::size_t n = s.particle_pos.size();
  std::vector<std::uint32_t> order(n);
  std::vector<float> key(n);  // x, with NaN last (the comparison needs an order)
  double largest = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    order[i] = i;
    const float x = s.particle_pos[i].x;
    key[i] = std::isnan(x) ? std::numeric_limits<float>::infinity() : x;
    largest = std::max(largest, static_cast<double>(s.particle_pos[i].w));
  }
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t i, std::uint32_t j) { return key[i] < key[j]; });
  for (std::size_t u = 0; u < n; ++u) {
    const shared::vec4& a = s.particle_pos[order[u]];
    const double reach = static_cast<double>(a.w) + largest;
    for (std::size_t w = u + 1; w < n; ++w) {
      const shared::vec4& b = s.particle_pos[order[w]];
      const double dx = static_cast<double>(b.x) - static_cast<double>(a.x);
      if (dx >= reach) break;
      const double dy = static_cast<double>(a.y) - static_cast<double>(b.y);
      const double dz = static_cast<double>(a.z) - static_cast<double>(b.z);
      const double r = static_cast<double>(a.w) + static_cast<double>(b.w);
      if (dx * dx + dy * dy + dz * dz < r * r) {
        pairs.insert(std::minmax(order[u], order[w]));
      }
    }
  }
  return pairs;
}

struct Comparison {
  double dx = 0.0;            ///< largest position difference (m)
  double dv = 0.0;            ///< largest velocity difference (m/s)
  std::size_t differing = 0;  ///< particles not bitwise equal
};

Comparison compare(const Snapshot& a, const Snapshot& b) {
  Comparison c;
  for (std::size_t i = 0; i < a.particle_pos.size(); ++i) {
    const shared::vec4& p = a.particle_pos[i];
    const shared::vec4& q = b.particle_pos[i];
    const shared::vec4& v = a.particle_vel[i];
    const shared::vec4& w = b.particle_vel[i];
    c.dx = std::max({c.dx, std::abs(static_cast<double>(p.x - q.x)),
                     std::abs(static_cast<double>(p.y - q.y)),
                     std::abs(static_cast<double>(p.z - q.z))});
    c.dv = std::max({c.dv, std::abs(static_cast<double>(v.x - w.x)),
                     std::abs(static_cast<double>(v.y - w.y)),
                     std::abs(static_cast<double>(v.z - w.z))});
    if (std::memcmp(&p, &q, sizeof p) != 0 || std::memcmp(&v, &w, sizeof v) != 0) ++c.differing;
  }
  return c;
}

/// What must happen on the way over more than one rank.
struct Expected {
  bool partitions = true;  ///< partitions after the first
  bool halo = true;        ///< halo copies somewhere
  bool migrating = false;  ///< bodies changing rank
};

/// Runs `scene` for `steps` over every rank and (rank 0) on one Simulation; checks the same
/// contacts, bitwise the same positions and velocities, and every body owned once.
Snapshot expect_rank_independent(const Scene& scene, std::uint64_t steps, Expected expected,
                                 const DistributedOptions& options = {}) {
  Snapshot result;
  Result<std::unique_ptr<DistributedSimulation>> d =
      DistributedSimulation::create(scene, MPI_COMM_WORLD, opener(), options);
  EXPECT_TRUE(d) << d.message();
  if (!d) return result;
  EXPECT_EQ(d.value()->decomposition().ranks(), world_size());
  const Status stepped = d.value()->step(steps);
  EXPECT_TRUE(stepped) << stepped.message();
  const Result<Snapshot> gathered = d.value()->gather(0);
  EXPECT_TRUE(gathered) << gathered.message();
  if (!stepped || !gathered) return result;
  const DistributedStats stats = d.value()->stats();
  if (world_size() > 1) {
    // The run re-partitioned and moved bodies between ranks, and the ranks held halo copies.
    if (expected.partitions) {
      EXPECT_GT(stats.partitions, 1u);
    }
    if (expected.migrating) {
      EXPECT_GT(stats.migrations, 0u);
    }
    std::uint64_t halo = stats.halo_bodies;
    std::uint64_t total = 0;
    MPI_Allreduce(&halo, &total, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    if (expected.halo) {
      EXPECT_GT(total, 0u);
    }
    // All ranks run on this host: the halo goes device to device where the backend can share
    // device memory between processes (CUDA), else through host memory.
    const bool direct = options.halo == DistributedOptions::Halo::Auto && backend() == "cuda";
    EXPECT_EQ(stats.halo_direct, direct) << stats.halo_host_reason;
    if (!direct) {
      EXPECT_EQ(stats.halo_host_reason.empty(), options.halo == DistributedOptions::Halo::Host);
    }
  }
  if (world_rank() != 0) return result;

  DeviceOptions options1;
  options1.cpu_threads = 1;
  Result<std::unique_ptr<Device>> device = open_device(backend(), -1, options1);
  EXPECT_TRUE(device) << device.message();
  if (!device) return result;
  // Runs over ranks drop the impulse contacts' memory at list builds (docs/scale-out.md): one
  // process, the same.
  Scene alone = scene;
  alone.settings.impulse_memory_across_builds = false;
  Result<std::unique_ptr<Simulation>> one = Simulation::create(alone, std::move(device).value());
  EXPECT_TRUE(one) << one.message();
  if (!one || !one.value()->step(steps)) return result;
  const Result<Snapshot> single = one.value()->snapshot();
  if (!single) return result;
  EXPECT_EQ(gathered->particle_pos.size(), single->particle_pos.size());
  if (gathered->particle_pos.size() != single->particle_pos.size()) return result;
  EXPECT_EQ(gathered->particle_body, single->particle_body);
  const auto contacts = touching(single.value());
  EXPECT_GT(contacts.size(), 0u);
  EXPECT_EQ(touching(gathered.value()), contacts) << "the touching pairs differ";
  // Each rank holds every partner of its particles, builds the grid one process builds and
  // rebuilds its lists at the same steps: each particle's forces are summed over the same
  // partners in the same order, so the run is bitwise the one of one process.
  const Comparison c = compare(gathered.value(), single.value());
  EXPECT_EQ(c.differing, 0u) << "|dx| " << c.dx << " m, |dv| " << c.dv << " m/s";
  std::printf(
      "[ ranks %d ] %zu particles, %llu steps, %zu touching pairs: |dx| %.3g m, |dv| %.3g "
      "m/s, %zu particles not bitwise equal; %llu partitions, %llu migrations\n",
      world_size(), single->particle_pos.size(), static_cast<unsigned long long>(steps),
      contacts.size(), c.dx, c.dv, c.differing, static_cast<unsigned long long>(stats.partitions),
      static_cast<unsigned long long>(stats.migrations));
  result = single.value();
  return result;
}

TEST(Distributed, ShakenSettleMatchesOneRank) {
  expect_rank_independent(shaken_settle(), 400, {.migrating = true});
}

TEST(Distributed, ShakenSettleWithTheHaloThroughHostMemoryMatchesOneRank) {
  // Where the halo can go device to device (CUDA), the host path is still there: the same bits.
  if (backend() != "cuda") {
    GTEST_SKIP() << "the halo of " << backend()
                 << " always goes through host memory (ShakenSettleMatchesOneRank)";
  }
  DistributedOptions host;
  host.halo = DistributedOptions::Halo::Host;
  expect_rank_independent(shaken_settle(), 400, {.migrating = true}, host);
}

TEST(Distributed, DominoChainMatchesOneRank) {
  // Slabs along the chain: each domino falls onto the next across every rank boundary, the force
  // of a contact between two ranks' dominoes computed by each owner from its halo copy.
  DistributedOptions slabs;
  slabs.decomposition = std::array<int, 3>{world_size(), 1, 1};
  const Scene chain = short_domino_chain(6);
  const Snapshot end = expect_rank_independent(chain, 20000, {}, slabs);
  if (world_rank() != 0 || end.body_quat.empty()) return;
  // The wave reached the last domino: it has turned by more than 20 degrees.
  std::size_t last = 0;
  for (std::size_t b = 0; b < chain.bodies.size(); ++b) {
    if (chain.bodies[b].kind == BodyKind::Dynamic) last = b;
  }
  const shared::vec4& q = end.body_quat[last];
  const Eigen::Quaterniond turned(static_cast<double>(q.w), static_cast<double>(q.x),
                                  static_cast<double>(q.y), static_cast<double>(q.z));
  EXPECT_GT(turned.angularDistance(chain.bodies[last].rotation), 20.0 * 3.14159265 / 180.0);
}

TEST(Distributed, RefusesAWrongDecomposition) {
  DistributedOptions wrong;
  wrong.decomposition = std::array<int, 3>{world_size() + 1, 1, 1};
  Result<std::unique_ptr<DistributedSimulation>> d =
      DistributedSimulation::create(shaken_settle(), MPI_COMM_WORLD, opener(), wrong);
  ASSERT_FALSE(d);
  EXPECT_NE(d.message().find("must multiply to the"), std::string::npos) << d.message();
}

TEST(Distributed, RefusesAMarginBelowHalfTheSkin) {
  // shaken_settle's spheres are 1 cm: a skin of 1 mm, so a margin of at least 0.5 mm.
  for (const double margin : {0.0, 0.0004, std::numeric_limits<double>::quiet_NaN(),
                              std::numeric_limits<double>::infinity()}) {
    DistributedOptions small;
    small.margin = margin;
    Result<std::unique_ptr<DistributedSimulation>> d =
        DistributedSimulation::create(shaken_settle(), MPI_COMM_WORLD, opener(), small);
    ASSERT_FALSE(d) << margin;
    EXPECT_NE(d.message().find("at least half the neighbour skin (0.0005 m"), std::string::npos)
        << d.message();
  }
  DistributedOptions enough;
  enough.margin = 0.0005;
  EXPECT_TRUE(DistributedSimulation::create(shaken_settle(), MPI_COMM_WORLD, opener(), enough));
}

/// The domino row of impulse_dominoes.json sliding along -x at 0.5 m/s (with friction on the
/// floor plane): the group of every rigid body crosses into the next brick.
Scene sliding_impulse_dominoes() {
  Scene scene = example("impulse_dominoes");
  for (BodySpec& b : scene.bodies) {
    if (b.kind == BodyKind::Dynamic) b.velocity = {-0.5, 0.0, 0.0};
  }
  return scene;
}

/// Every kind of object over the ranks, against one process, bitwise: soft bodies (their
/// clusters' rotations travel with them; bricks across the three cubes, which each rank holds
/// copies of), a rope and cloth attached to rigid bodies (owned and copied together with them:
/// the pendulum is one group), impulse contacts (every rigid body owned together; the plane
/// contacts' accumulated impulses travel with them when the group changes rank, as the sliding
/// row does). A small margin makes the ranks partition at most list rebuilds.
TEST(Distributed, EveryKindMatchesOneRank) {
  const int n = world_size();
  struct Case {
    const char* name;
    std::array<int, 3> bricks;
    Expected expected;
  };
  const Case cases[] = {
      {"soft", {n, 1, 1}, {.partitions = false}},
      {"pendulum", {n, 1, 1}, {.partitions = false, .halo = false}},
      {"mixed", {n == 4 ? 2 : 1, 1, n == 4 ? 2 : n}, {.partitions = false}},
      {"sliding impulse_dominoes", {n, 1, 1}, {.halo = false, .migrating = true}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    DistributedOptions options;
    options.margin = 0.001;
    options.decomposition = c.bricks;
    const std::string name = c.name;
    const Scene scene =
        name == "sliding impulse_dominoes" ? sliding_impulse_dominoes() : example(name);
    // The sanitizer build (tests/sanitized_build.h): 200 steps, every kind's paths.
    expect_rank_independent(scene, motes_test::sanitized_or(600u, 200u), c.expected, options);
  }
}

/// Bodies stepped together are owned by one rank: a cloth or rope and what it is attached to,
/// and with impulse contacts every rigid body.
TEST(Distributed, GroupsAreOwnedTogether) {
  for (const char* name : {"pendulum", "impulse_dominoes"}) {
    SCOPED_TRACE(name);
    const Scene scene = example(name);
    Result<std::unique_ptr<DistributedSimulation>> d =
        DistributedSimulation::create(scene, MPI_COMM_WORLD, opener(), {});
    ASSERT_TRUE(d) << d.message();
    ASSERT_TRUE(d.value()->step(200));
    // Every body's owner, gathered: -1 where a rank does not own it.
    const std::size_t bodies = d.value()->bodies().size();
    std::vector<int> mine(bodies, -1), owner(bodies, -1);
    for (const std::uint32_t b : d.value()->owned()) mine[b] = world_rank();
    MPI_Allreduce(mine.data(), owner.data(), static_cast<int>(bodies), MPI_INT, MPI_MAX,
                  MPI_COMM_WORLD);
    const auto rank_of = [&](const std::string& body) {
      for (std::size_t b = 0; b < bodies; ++b) {
        if (d.value()->bodies()[b].name == body) return owner[b];
      }
      ADD_FAILURE() << "no body " << body;
      return -2;
    };
    for (std::size_t l = 0; l < scene.linked.size(); ++l) {
      for (const LinkAttachment& a : scene.linked[l].attached) {
        EXPECT_EQ(owner[scene.bodies.size() + l], rank_of(a.body))
            << scene.linked[l].name << " and " << a.body;
      }
    }
    if (scene.settings.contact_model == ContactModel::Impulses) {
      for (std::size_t b = 0; b < scene.bodies.size(); ++b) EXPECT_EQ(owner[b], owner[0]);
    }
    for (std::size_t b = 0; b < bodies; ++b) EXPECT_GE(owner[b], 0) << "body " << b;
  }
}

TEST(Distributed, DeviceErrorOnOneRankReachesEveryRank) {
  // Rank size-1 cannot open its device: every rank gets its message, none hangs.
  const int last = world_size() - 1;
  DeviceOpener failing = [last]() -> Result<std::unique_ptr<Device>> {
    if (world_rank() == last) return Status::error("no device here");
    return opener()();
  };
  Result<std::unique_ptr<DistributedSimulation>> d =
      DistributedSimulation::create(shaken_settle(), MPI_COMM_WORLD, failing, {});
  ASSERT_FALSE(d);
  EXPECT_NE(d.message().find("no device here"), std::string::npos) << d.message();
}

}  // namespace
}  // namespace motes
