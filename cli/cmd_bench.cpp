// `motes bench`: the fixed workloads of docs/benchmarks.md on any backend; a table and JSON.
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/workloads.h"

namespace motes::cli {
namespace {

// W2 dominoes of 15 particles up to the scenes' default settings.max_particles (100,000,000): the
// workload is built on the host before the device check, so a larger count would only exhaust host
// memory first.
constexpr std::uint64_t kMaxDominoes = 100'000'000 / 15;

// Host memory a W1 size takes to build and run, per sphere, before the device's own check
// (Simulation::create): the scene's BodySpec (272 B), the simulation's BodyInfo (72 B) and the
// host layout. Measured with openmp on the development VM (docs/benchmarks.md, "W1 beyond host
// memory"): peak RSS 2,445 MB at 4,194,304 spheres and 672 MB at 1,048,576, 563 B a sphere
// between them, of which 196 B is the openmp device's memory (575 B on 2026-12-01); and on the
// H200 machine with CUDA, 108,126,840 KiB at 268,435,456 spheres: 412 B a sphere (2026-11-30 and
// 2026-12-01); rounded up.
constexpr std::uint64_t kW1HostBytesPerSphere = 420;
// The device memory of a W1 sphere where the device is host memory (openmp): 196 B of buffers,
// and in the dense phase 251 B of shared contact pairs (backends/openmp/contact_pairs.cpp; peak
// RSS at 65,536 spheres, 2026-11-30); rounded up.
constexpr std::uint64_t kW1OpenmpDeviceBytesPerSphere = 460;

// MemAvailable of /proc/meminfo in bytes; nothing where it cannot be read.
std::optional<std::uint64_t> available_host_memory() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::uint64_t kib = 0;
  std::string unit;
  while (in >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024u;
  }
  return std::nullopt;
}

// Refuses (fail()) a W1 size whose scene would not fit in the host's available memory: building
// it would otherwise run the machine out of memory instead of saying so.
void check_w1_host_memory(std::uint64_t spheres, bool device_on_host) {
  const std::optional<std::uint64_t> available = available_host_memory();
  if (!available) return;
  const std::uint64_t per_sphere =
      kW1HostBytesPerSphere + (device_on_host ? kW1OpenmpDeviceBytesPerSphere : 0u);
  const std::uint64_t need = spheres * per_sphere;
  if (need <= *available) return;
  constexpr double kGB = 1e9;
  fail(fmt::format(
      "W1 at {} spheres needs about {:.1f} GB of host memory ({} B a sphere: the scene, its "
      "bodies and their layout{}), and {:.1f} GB is available here (MemAvailable): refused; at "
      "most {} spheres fit",
      spheres, static_cast<double>(need) / kGB, per_sphere,
      device_on_host ? ", and the openmp device's memory" : "",
      static_cast<double>(*available) / kGB, *available / per_sphere));
}

struct BenchOptions {
  std::string workload = "all";
  std::vector<std::uint64_t> sizes = {16384, 65536, 262144, 1048576};
  std::string phase = "both";
  std::string backend = "auto";
  int device = -1;
  int threads = 0;
  int repeats = 3;
  std::uint64_t falling_steps = 2000;
  std::uint64_t dense_steps = 5000;
  std::uint64_t settle_steps = 60000;
  double skin = -1.0;  // W1's neighbour-list skin (m) in the timed runs; < 0: the scene's own
  int dominoes = 1000;
  int domino_rows = 10;
  std::uint64_t domino_steps = 2000;
  std::vector<int> cloth_sides = {256};
  std::uint64_t cloth_steps = 1000;
  std::vector<int> soft_counts = {1000};
  std::uint64_t soft_steps = 200;
  std::vector<std::uint64_t> fluid_sizes = {100000};
  std::uint64_t fluid_steps = 60;  // frames of 1/60 s: one simulated second
  std::string cache = "bench-cache";
  std::string dense_from;  // LAMMPS data file: the dense phase starts from LAMMPS's settled state
  std::string json_path;
  std::vector<std::string> scenes = {"examples/scenes"};  // realtime: scene files or folders
  double realtime_seconds = 2.0;                          // realtime: simulated seconds a run
  int frame_rate = 60;                                    // realtime: frames per simulated second
};

struct Measurement {
  std::string workload, phase;
  std::uint32_t particles = 0, bodies = 0;
  std::uint32_t rigid_particles = 0, rigid_bodies = 0;
  std::uint32_t table = 0;
  std::uint64_t constraint_sweeps = 0;  // constraints projected per step (C x iterations)
  std::uint64_t constraint_checks = 0;  // of them, in the last sweep (with the skin test)
  std::uint64_t impulse_sweeps = 0;     // impulse passes per step ((iterations + 1) x substeps)
  std::uint32_t soft_particles = 0, clusters = 0, cluster_members = 0;
  std::uint64_t steps = 0;         // per timed repeat
  std::vector<double> seconds;     // per repeat, kernel timing off
  std::uint64_t kernel_steps = 0;  // of the run with kernel timing on
  motes::KernelTimes kernels;      // of that run
  std::string backend, device, detail;
  std::uint64_t device_bytes = 0;    // what the simulation holds on the device
  motes::NeighbourStats neighbours;  // after the first timed repeat (builds: during it)
  float skin = 0.0f;                 // neighbour skin (m)
  std::uint32_t capacity = 0;        // list entries per particle
};

template <typename T>
T must(motes::Result<T> r) {
  if (!r) fail(r.message());
  return std::move(r).value();
}

void must(const motes::Status& s) {
  if (!s) fail(s.message());
}

std::unique_ptr<motes::Simulation> make_sim(const motes::Scene& scene, const BenchOptions& o) {
  motes::DeviceOptions dopt;
  dopt.cpu_threads = o.threads;
  auto device = must(motes::open_device(o.backend, o.device, dopt));
  return must(motes::Simulation::create(scene, std::move(device)));
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// W1 sizes from which bench says on stderr how long the host took to build each simulation, and
/// from which the falling phase's kernel-timing run is the warm-up (measure; the dense phase keeps
/// its warm-up): at 33,554,432 spheres and more the host's build of a simulation (the scene's
/// layout, its upload) takes tens of seconds to minutes.
constexpr std::uint64_t kW1HugeSpheres = 33'554'432;

/// Runs `steps` steps `repeats` times, each from a fresh simulation prepared by `prepare`, with
/// kernel timing off (timing may synchronize per kernel and keeps GPU backends from replaying a
/// captured step); then once more with timing on, for the time of every kernel family. Before the
/// repeats a warm-up of 50 steps (first touch of memory, thread pool start, graph capture); with
/// `huge` the timing run comes first and is the warm-up instead, so that a size whose simulation
/// takes minutes to build is built twice rather than three times. `huge` also reports each
/// simulation's build time on stderr.
template <typename Prepare>
Measurement measure(const motes::Scene& scene, const BenchOptions& o, std::uint64_t steps,
                    Prepare prepare, bool huge = false) {
  Measurement m;
  const auto fresh = [&](const char* what) {
    const auto t0 = std::chrono::steady_clock::now();
    auto sim = make_sim(scene, o);
    prepare(*sim);
    if (huge) {
      fmt::print(stderr, "  {} simulation of {} particles built in {:.1f} s\n", what,
                 sim->particle_count(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    return sim;
  };
  const auto time_kernels = [&] {
    auto sim = fresh("the kernel-timing");
    m.kernel_steps = std::min<std::uint64_t>(steps, 500);
    sim->device().set_timing(true);
    sim->device().reset_kernel_times();
    must(sim->step(m.kernel_steps));
    m.kernels = sim->device().kernel_times();
  };
  if (huge) {
    time_kernels();
  } else {  // Warm-up: first touch of memory, thread pool start, graph capture.
    auto sim = fresh("the warm-up");
    must(sim->step(std::min<std::uint64_t>(steps, 50)));
  }
  for (int r = 0; r < o.repeats; ++r) {
    auto sim = fresh("a timed");
    // A start state loaded from a checkpoint carries the list builds of the run that made it
    // (the W1 dense phase: the settle's); the column counts this repeat's own.
    const std::uint32_t builds_before = r == 0 ? must(sim->neighbour_stats()).builds : 0;
    const auto t0 = std::chrono::steady_clock::now();
    must(sim->step(steps));
    const auto t1 = std::chrono::steady_clock::now();
    m.seconds.push_back(std::chrono::duration<double>(t1 - t0).count());
    if (r == 0) {
      m.particles = sim->particle_count();
      m.bodies = sim->body_count();
      m.rigid_particles = sim->sizes().rigid_particles;
      m.rigid_bodies = sim->sizes().bodies;
      m.table = sim->sizes().table;
      m.soft_particles = sim->sizes().soft_particles;
      m.clusters = sim->sizes().clusters;
      m.cluster_members = sim->sizes().cluster_members;
      m.constraint_sweeps = std::uint64_t{sim->sizes().constraints} *
                            static_cast<std::uint64_t>(sim->settings().constraint_iterations) *
                            static_cast<std::uint64_t>(sim->settings().substeps);
      m.constraint_checks = std::uint64_t{sim->sizes().constraints} *
                            static_cast<std::uint64_t>(sim->settings().substeps);
      if (sim->sizes().impulse != 0) {
        m.impulse_sweeps = static_cast<std::uint64_t>(sim->settings().impulse_iterations + 1) *
                           static_cast<std::uint64_t>(sim->settings().substeps);
      }
      m.backend = sim->device().info().backend;
      m.device = sim->device().info().name;
      m.detail = sim->device().info().detail;
      m.device_bytes = sim->device_bytes();
      m.neighbours = must(sim->neighbour_stats());
      m.neighbours.builds -= builds_before;
      m.skin = sim->step_params().neighbour_skin;
      m.capacity = sim->step_params().neighbour_capacity;
    }
  }
  if (!huge) time_kernels();
  m.steps = steps;
  return m;
}

/// Bytes each kernel family must move per step at the least (every input read once, every output
/// written once; body data gathered per particle counted once per body): what "achieved bandwidth"
/// is computed from. docs/benchmarks.md explains each term.
double compulsory_bytes(motes::Kernel k, const Measurement& m) {
  const double n = m.particles, t = m.table;
  const double nr = m.rigid_particles, b = m.rigid_bodies, nf = n - nr;
  switch (k) {
    case motes::Kernel::NeighboursUpdate:  // read one word
      return 4;
    case motes::Kernel::GridBuild:  // read pos, body; write bucket, order, 2 sorted copies
      return 20 * n + 8 * n + 20 * n + 4 * (t + 1);
    case motes::Kernel::NeighboursBuild:  // read pos, vel, body, starts, sorted pos + body, order;
                                          // write count and ref (the entries are not counted)
      return 36 * n + 4 * (t + 1) + 24 * n + 20 * n;
    case motes::Kernel::ContactsCompute:  // read own pos, vel, material, count; write force (the
                                          // entries and the neighbours gathered are not counted)
      return 40 * n + 16 * n;
    case motes::Kernel::BodiesReduce:  // read first, com, particle pos + force; write force, torque
      return 4 * (b + 1) + 16 * b + 32 * nr + 32 * b;
    case motes::Kernel::BodiesIntegrate:  // read 8 vec4, write 5 vec4 per body
      return 13 * 16 * b;
    case motes::Kernel::ParticlesUpdate:  // read body, local, pos, vel, ref, 4 body vec4; write
                                          // pos, vel
      return (4 + 16 + 48) * nr + 64 * b + 32 * nr;
    case motes::Kernel::ParticlesIntegrate:  // read pos, vel, force, ref; write pos, vel
      return 96 * nf;
    case motes::Kernel::ClustersFit:  // read each cluster, its members and their pos; write frames
      return (368.0 + 272.0) * m.clusters + (48.0 + 32.0) * m.cluster_members;
    case motes::Kernel::ClustersGoal:  // read pos, vel, ref, gather offset per soft particle, a
                                       // gather id and member per membership, each frame once;
                                       // write pos, vel
      return (52.0 + 32.0) * m.soft_particles + 52.0 * m.cluster_members + 272.0 * m.clusters;
    case motes::Kernel::ConstraintsSolve:  // (a launch per colour, or all in one: the same)
    case motes::Kernel::ConstraintsRelax:  // per projection: read the constraint, both
                                           // particles' pos, vel; write their pos, vel; in
                                           // the last sweep also read their ref
      return (16.0 + 64.0 + 64.0) * static_cast<double>(m.constraint_sweeps) +
             32.0 * static_cast<double>(m.constraint_checks);
    case motes::Kernel::ImpulsesCompute:  // per sweep: read own pos, vel, body, material, count,
                                          // the body's 7 vec4 once; write impulse, moment (the
                                          // entries, the neighbours gathered and the contacts'
                                          // accumulated impulses are not counted)
      return ((16.0 + 16.0 + 12.0 + 32.0) * nr + 112.0 * b) * static_cast<double>(m.impulse_sweeps);
    case motes::Kernel::ImpulsesApply:  // per sweep: read first, com, quat, inertia, vel, angmom,
                                        // impulses and moments; write vel, angmom, angvel
      return (4.0 * (b + 1) + 128.0 * b + 32.0 * nr) * static_cast<double>(m.impulse_sweeps);
    case motes::Kernel::FluidDensity:    // W5 (docs/fluids.md), not counted yet:
    case motes::Kernel::FluidUpdate:     // per fluid particle and sweep (density, update) or
    case motes::Kernel::FluidVorticity:  // substep (vorticity, velocity), read own pos, vel,
    case motes::Kernel::FluidVelocity:   // material, count, state; write state, shift, the
                                         // vorticity's three or the velocity (not counted yet)
      return 0;
    case motes::Kernel::ParticlesCheck:  // not in a step (the run's guard): read pos, vel
      return 32 * n;
    case motes::Kernel::EnergyReduce:  // not in a step (the run's guard): read the free particles'
                                       // pos, vel and the bodies' pos, vel, angvel, angmom
      return 32 * nf + 64 * b;
    case motes::Kernel::ParticlesDisplacement:  // not in a step (runs over MPI ranks): read pos,
                                                // the partition's ref
      return 32 * n;
    case motes::Kernel::HaloPack:    // not in a step (runs over MPI ranks), and a benchmark has
    case motes::Kernel::HaloUnpack:  // no halo entries: per particle entry an index, pos, vel
                                     // read and written once (68 B), per body entry 164 B
      return 0;
    case motes::Kernel::Count:
      break;
  }
  return 0;
}

/// The kernel families a step runs: those before particles_check (the run's guards:
/// particles_check, energy_reduce) and the families of runs over MPI ranks (halo_pack,
/// halo_unpack, particles_displacement), none of which `motes bench` calls.
constexpr std::size_t kStepKernels = static_cast<std::size_t>(motes::Kernel::ParticlesCheck);
static_assert(static_cast<std::size_t>(motes::Kernel::EnergyReduce) == kStepKernels + 1 &&
                  static_cast<std::size_t>(motes::Kernel::HaloPack) == kStepKernels + 2 &&
                  static_cast<std::size_t>(motes::Kernel::HaloUnpack) == kStepKernels + 3 &&
                  static_cast<std::size_t>(motes::Kernel::ParticlesDisplacement) ==
                      kStepKernels + 4 &&
                  kStepKernels + 5 == motes::kKernelCount,
              "the families after a step's: the guards, then those of runs over MPI ranks");

/// Kernel time of family k per step (ms), from the timed run.
double kernel_ms(const Measurement& m, std::size_t k) {
  return m.kernel_steps == 0 ? 0.0
                             : 1e3 * m.kernels.seconds[k] / static_cast<double>(m.kernel_steps);
}

std::string settle_cache_path(const BenchOptions& o, std::uint64_t n) {
  return (std::filesystem::path(o.cache) /
          fmt::format("w1-{}-settled-{}-steps.motesck", n, o.settle_steps))
      .string();
}

/// The W1 dense-phase start state: settled once, then reloaded for every run.
std::string ensure_settled(const motes::Scene& scene, const BenchOptions& o, std::uint64_t n) {
  const std::string path = settle_cache_path(o, n);
  if (std::filesystem::exists(path)) return path;
  std::error_code ec;
  std::filesystem::create_directories(o.cache, ec);
  if (ec) fail(fmt::format("{}: cannot create cache directory: {}", o.cache, ec.message()));
  fmt::print(stderr, "settling W1 N={} for {} steps (once; cached in {})\n", n, o.settle_steps,
             path);
  auto sim = make_sim(scene, o);
  const auto t0 = std::chrono::steady_clock::now();
  const std::uint64_t chunk = std::max<std::uint64_t>(1, o.settle_steps / 20);
  for (std::uint64_t done = 0; done < o.settle_steps;) {
    const std::uint64_t k = std::min(chunk, o.settle_steps - done);
    must(sim->step(k));
    done += k;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    fmt::print(stderr, "  settle {:>3.0f}%  step {}/{}  {:.0f} s elapsed, ~{:.0f} s left\n",
               100.0 * static_cast<double>(done) / static_cast<double>(o.settle_steps), done,
               o.settle_steps, el,
               el * static_cast<double>(o.settle_steps - done) / static_cast<double>(done));
  }
  must(sim->check_finite());
  must(sim->save_state(path));
  return path;
}

/// The settled state at `path` (ensure_settled), read by a simulation of the scene it was made
/// with.
motes::Snapshot settled_state(const motes::Scene& scene, const BenchOptions& o,
                              const std::string& path) {
  auto sim = make_sim(scene, o);
  must(sim->load_state(path));
  return must(sim->snapshot());
}

nlohmann::json to_json(const Measurement& m) {
  const double med = median(m.seconds);
  nlohmann::json kernels = nlohmann::json::object();
  nlohmann::json bandwidth = nlohmann::json::object();
  for (std::size_t k = 0; k < kStepKernels; ++k) {
    const auto kernel = static_cast<motes::Kernel>(k);
    const double ms = kernel_ms(m, k);
    kernels[motes::kernel_name(kernel)] = ms;
    bandwidth[motes::kernel_name(kernel)] = ms > 0 ? compulsory_bytes(kernel, m) / (ms * 1e6) : 0.0;
  }
  return {{"workload", m.workload},
          {"phase", m.phase},
          {"particles", m.particles},
          {"bodies", m.bodies},
          {"steps", m.steps},
          {"repeat_seconds", m.seconds},
          {"median_ms_per_step", 1e3 * med / static_cast<double>(m.steps)},
          {"particle_steps_per_s",
           static_cast<double>(m.particles) * static_cast<double>(m.steps) / med},
          {"body_steps_per_s", static_cast<double>(m.bodies) * static_cast<double>(m.steps) / med},
          {"kernel_ms_per_step", kernels},
          {"kernel_timed_steps", m.kernel_steps},
          {"kernel_compulsory_gb_per_s", bandwidth},
          {"table_buckets", m.table},
          {"backend", m.backend},
          {"device", m.device},
          {"detail", m.detail},
          {"neighbour_search",
           fmt::format("neighbour lists (skin {} m, {} entries per particle) from the hashed "
                       "grid, rebuilt when a particle has moved 0.45 skin",
                       m.skin, m.capacity)},
          {"neighbour_builds", m.neighbours.builds},
          {"neighbour_max_count", m.neighbours.max_count},
          {"neighbour_over_capacity", m.neighbours.over_capacity},
          {"device_bytes", m.device_bytes},
          {"bytes_per_particle",
           m.particles == 0 ? 0.0 : static_cast<double>(m.device_bytes) / m.particles},
          {"contact_model",
           "DEM: linear spring, mass-proportional dashpot, viscous tangential "
           "force with Coulomb cap; no particle rotation"}};
}

void print_row(const Measurement& m) {
  const double med = median(m.seconds);
  const double per = 1e3 * med / static_cast<double>(m.steps);
  std::string ks;
  for (std::size_t k = 0; k < kStepKernels; ++k) ks += fmt::format(" {:>8.3f}", kernel_ms(m, k));
  fmt::print("{:<9} {:<8} {:>9} {:>6} {:>9.3f} {:>10.3e}{} {:>6.0f} {:>6}\n", m.workload, m.phase,
             m.particles, m.steps, per,
             static_cast<double>(m.particles) * static_cast<double>(m.steps) / med, ks,
             m.particles == 0 ? 0.0 : static_cast<double>(m.device_bytes) / m.particles,
             m.neighbours.builds);
  std::fflush(stdout);
}

/// Writes the rows to --json if asked, then ends with the error exit code if any workload failed
/// (its reason printed already).
void finish(const BenchOptions& o, const nlohmann::json& results, bool any_failed) {
  if (!o.json_path.empty()) {
    std::ofstream out(o.json_path);
    out << results.dump(2) << "\n";
    if (!out) fail(fmt::format("{}: cannot write JSON results", o.json_path));
    fmt::print("results written to {}\n", o.json_path);
  }
  if (any_failed) throw CLI::RuntimeError(kErrorExit);
}

/// The scene files `realtime` runs: each file of --scenes, and each .json file of each folder
/// there (sorted by name).
std::vector<std::string> realtime_scene_files(const BenchOptions& o) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  for (const std::string& path : o.scenes) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      std::vector<std::string> found;
      for (const fs::directory_entry& e : fs::directory_iterator(path, ec)) {
        if (e.is_regular_file() && e.path().extension() == ".json") {
          found.push_back(e.path().string());
        }
      }
      if (found.empty()) fail(fmt::format("--scenes: {} holds no .json scene file", path));
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(path, ec)) {
      files.push_back(path);
    } else {
      fail(
          fmt::format("--scenes: {} is neither a scene file nor a folder of them (the default, "
                      "examples/scenes, is the repository's: run from its root or name the scenes)",
                      path));
    }
  }
  return files;
}

/// One scene at frame-sized chunks: `--realtime-seconds` of simulated time, each frame
/// (1 / --frame-rate s, rounded to whole steps) one Simulation::step call that returns when the
/// device is done, as an interactive program steps; stepping only (no output, no guards).
/// Repeats from a fresh simulation each; the median wall time gives simulated seconds per second.
void run_realtime_scene(const std::string& path, const BenchOptions& o, nlohmann::json& results) {
  const motes::Scene scene = must(motes::load_scene_file(path));
  const double dt = scene.settings.dt;
  const auto frame_steps =
      static_cast<std::uint64_t>(std::max<long long>(1, std::llround(1.0 / (o.frame_rate * dt))));
  const auto frames = static_cast<std::uint64_t>(std::max<long long>(
      1, std::llround(o.realtime_seconds / (static_cast<double>(frame_steps) * dt))));
  const double simulated = static_cast<double>(frames * frame_steps) * dt;
  {  // Warm-up: first touch of memory, thread pool start, graph capture.
    auto sim = make_sim(scene, o);
    must(sim->step(std::min<std::uint64_t>(frame_steps, 50)));
  }
  std::vector<double> seconds;
  std::uint32_t particles = 0;
  for (int r = 0; r < o.repeats; ++r) {
    auto sim = make_sim(scene, o);
    particles = sim->particle_count();
    double wall = 0.0;
    for (std::uint64_t f = 0; f < frames; ++f) {
      const auto t0 = std::chrono::steady_clock::now();
      must(sim->step(frame_steps));
      wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    seconds.push_back(wall);
  }
  const double med = median(seconds);
  const std::string name = std::filesystem::path(path).stem().string();
  const motes::ContactModel model = scene.settings.contact_model;
  const char* contacts = model == motes::ContactModel::Impulses    ? "impulse"
                         : model == motes::ContactModel::Positions ? "position"
                                                                   : "force";
  fmt::print("{:<18} {:<8} {:>9} {:>8.3f} {:>6} {:>9.3f} {:>9.3f} {:>9.3f}\n", name, contacts,
             particles, 1e3 * dt, frame_steps, 1e3 * med / static_cast<double>(frames),
             simulated / med, 1e3 * med / static_cast<double>(frames * frame_steps));
  std::fflush(stdout);
  results.push_back({{"workload", "realtime"},
                     {"scene", path},
                     {"contact_model", contacts},
                     {"particles", particles},
                     {"dt", dt},
                     {"frame_rate", o.frame_rate},
                     {"steps_per_frame", frame_steps},
                     {"frames", frames},
                     {"simulated_seconds", simulated},
                     {"repeats", o.repeats},
                     {"seconds", seconds},
                     {"ms_per_frame_median", 1e3 * med / static_cast<double>(frames)},
                     {"realtime_factor_median", simulated / med}});
}

/// `--workload realtime`: every scene of --scenes at frame-sized steps (docs/benchmarks.md,
/// "Real time").
void run_realtime(const BenchOptions& o) {
  const std::vector<std::string> files = realtime_scene_files(o);
  {
    auto probe = must(motes::open_device(o.backend, o.device, {o.threads}));
    fmt::print(
        "motes bench realtime on {} device {}: {} ({}); each scene {} simulated s in frames of "
        "1/{} s (one step call each), stepping only; median of {} repeats after a warm-up\n",
        probe->info().backend, probe->info().index, probe->info().name, probe->info().detail,
        o.realtime_seconds, o.frame_rate, o.repeats);
  }
  fmt::print(
      "{:<18} {:<8} {:>9} {:>8} {:>6} {:>9} {:>9} {:>9}   (x real: simulated s per s of "
      "stepping)\n",
      "scene", "contacts", "particles", "dt ms", "steps", "ms/frame", "x real", "ms/step");
  nlohmann::json results = nlohmann::json::array();
  bool any_failed = false;
  for (const std::string& path : files) {
    try {
      run_realtime_scene(path, o, results);
    } catch (const CLI::RuntimeError&) {  // fail() has printed why
      any_failed = true;
    }
  }
  finish(o, results, any_failed);
}

void run_bench(const BenchOptions& o) {
  if (o.workload != "all" && o.workload != "settle" && o.workload != "dominoes" &&
      o.workload != "cloth" && o.workload != "soft" && o.workload != "impulse-dominoes" &&
      o.workload != "fluid" && o.workload != "realtime") {
    fail(
        fmt::format("--workload must be settle, dominoes, cloth, soft, impulse-dominoes, fluid, "
                    "realtime or all, "
                    "got '{}'",
                    o.workload));
  }
  if (o.workload == "realtime") {
    run_realtime(o);
    return;
  }
  if (o.domino_rows > o.dominoes) {  // a usage error, as CLI11's own checks report them
    throw CLI::ValidationError(
        "--domino-rows", fmt::format("{} rows for {} dominoes: at most one row per domino (see "
                                     "--dominoes)",
                                     o.domino_rows, o.dominoes));
  }
  if (o.phase != "both" && o.phase != "falling" && o.phase != "dense") {
    fail(fmt::format("--phase must be falling, dense or both, got '{}'", o.phase));
  }
  for (std::uint64_t n : o.sizes) {
    int nx = 0, ny = 0, nz = 0;
    if (!motes::settle_dimensions(n, nx, ny, nz)) {
      fail(
          fmt::format("--sizes: {} is not a W1 size (16384, 65536, 262144, 1048576, 4194304, "
                      "16777216, 67108864, 134217728, 268435456)",
                      n));
    }
  }
  std::string device_backend;
  {
    auto probe = must(motes::open_device(o.backend, o.device, {o.threads}));
    device_backend = probe->info().backend;
    fmt::print(
        "motes bench on {} device {}: {} ({}); ms/step: median of {} repeats after a warm-up; "
        "kernel columns: one more run with kernel timing on (up to 500 steps)\n",
        probe->info().backend, probe->info().index, probe->info().name, probe->info().detail,
        o.repeats);
  }
  // Column labels of the kernel families, in motes::Kernel order (JSON has the full names).
  constexpr std::array kLabels = {"nb_upd",   "grid",     "nb_build", "contacts", "b_reduce",
                                  "b_integr", "p_update", "p_integr", "cl_fit",   "cl_goal",
                                  "constr",   "c_relax",  "imp_comp", "imp_appl", "fl_dens",
                                  "fl_upd",   "fl_vort",  "fl_vel"};
  static_assert(kLabels.size() == kStepKernels, "a label per kernel family of a step");
  std::string ks;
  for (const char* label : kLabels) ks += fmt::format(" {:>8}", label);
  fmt::print(
      "{:<9} {:<8} {:>9} {:>6} {:>9} {:>10}{} {:>6} {:>6}   (kernel columns: ms/step; "
      "B/p: device bytes per particle; builds: neighbour-list builds in one repeat)\n",
      "workload", "phase", "particles", "steps", "ms/step", "p-steps/s", ks, "B/p", "builds");

  std::optional<motes::Scene> lammps_state;
  if (!o.dense_from.empty()) {
    lammps_state = must(motes::settle_workload_from_lammps(o.dense_from));
    if (o.skin > 0.0) lammps_state->settings.neighbour_skin = o.skin;
    fmt::print("dense* = the dense phase from LAMMPS's settled state {} ({} spheres)\n",
               o.dense_from, lammps_state->bodies.size());
  }
  nlohmann::json results = nlohmann::json::array();
  // A workload that cannot run (a size beyond the device's memory, say) is reported, and the
  // others still run; the command then ends with the error exit code.
  bool any_failed = false;
  const auto attempt = [&](const auto& run) {
    try {
      run();
    } catch (const CLI::RuntimeError&) {  // fail() has printed why
      any_failed = true;
    }
  };
  const bool rigid = o.workload == "all" || o.workload == "settle" || o.workload == "dominoes";
  if (rigid && o.workload != "dominoes") {
    for (std::uint64_t n : o.sizes) {
      int nx = 0, ny = 0, nz = 0;
      motes::settle_dimensions(n, nx, ny, nz);
      bool fits = false;
      attempt([&] {
        check_w1_host_memory(n, device_backend == "openmp");
        fits = true;
      });
      if (!fits) continue;
      // The timed runs take --skin's skin; the settled start state is made and read with the
      // scene's own (so that every skin starts the dense phase from the same pile). Set in
      // place: at 268,435,456 spheres a copy of the scene (about 280 B a sphere) does not fit
      // beside it on the GPU machine.
      const auto built = std::chrono::steady_clock::now();
      motes::Scene scene = motes::settle_workload(nx, ny, nz);
      const bool huge = n >= kW1HugeSpheres;
      if (huge) {
        fmt::print(stderr, "W1 at {} spheres: the scene built in {:.1f} s\n", n,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - built).count());
        const char* tunables = std::getenv("GLIBC_TUNABLES");
        if (tunables == nullptr ||
            std::string_view(tunables).find("hugetlb") == std::string_view::npos) {
          fmt::print(stderr,
                     "  (GLIBC_TUNABLES=glibc.malloc.hugetlb=1 lets transparent huge pages back "
                     "the host's build where the kernel gives them on request: about twice as "
                     "fast, docs/benchmarks.md)\n");
        }
      }
      const double own_skin = scene.settings.neighbour_skin;
      const double timed_skin = o.skin > 0.0 ? o.skin : own_skin;
      scene.settings.neighbour_skin = timed_skin;
      if (o.phase != "dense") {
        attempt([&] {
          Measurement m = measure(
              scene, o, o.falling_steps, [](motes::Simulation&) {}, huge);
          m.workload = "settle";
          m.phase = "falling";
          print_row(m);
          results.push_back(to_json(m));
        });
      }
      if (o.phase != "falling") {
        attempt([&] {
          Measurement m;
          if (lammps_state && lammps_state->bodies.size() == n) {
            m = measure(*lammps_state, o, o.dense_steps, [](motes::Simulation&) {});
            m.phase = "dense*";
          } else {
            scene.settings.neighbour_skin = own_skin;
            const std::string path = ensure_settled(scene, o, n);
            if (o.skin > 0.0) {
              // The checkpoint belongs to the scene's own settings: read there, its state is
              // written into the timed simulations with the other skin.
              const motes::Snapshot state = settled_state(scene, o, path);
              scene.settings.neighbour_skin = timed_skin;
              m = measure(scene, o, o.dense_steps,
                          [&](motes::Simulation& s) { must(s.write_state(state)); });
            } else {
              m = measure(scene, o, o.dense_steps,
                          [&](motes::Simulation& s) { must(s.load_state(path)); });
            }
            m.phase = "dense";
          }
          m.workload = "settle";
          print_row(m);
          results.push_back(to_json(m));
        });
      }
    }
  }
  if (rigid && o.workload != "settle") {
    attempt([&] {
      const motes::Scene scene = motes::dominoes_workload(o.dominoes, o.domino_rows);
      Measurement m = measure(scene, o, o.domino_steps, [](motes::Simulation&) {});
      m.workload = "dominoes";
      m.phase = "falling";
      print_row(m);
      results.push_back(to_json(m));
    });
  }
  if (o.workload == "impulse-dominoes") {
    attempt([&] {
      const motes::Scene scene = motes::impulse_dominoes_workload(o.dominoes, o.domino_rows);
      Measurement m = measure(scene, o, o.domino_steps, [](motes::Simulation&) {});
      m.workload = "imp-dom";
      m.phase = "falling";
      print_row(m);
      results.push_back(to_json(m));
    });
  }
  if (o.workload == "cloth") {
    for (const int side : o.cloth_sides) {
      attempt([&] {
        const motes::Scene scene = motes::cloth_workload(side);
        Measurement m = measure(scene, o, o.cloth_steps, [](motes::Simulation&) {});
        m.workload = "cloth";
        m.phase = "falling";
        print_row(m);
        results.push_back(to_json(m));
      });
    }
  }
  if (o.workload == "fluid") {
    for (const std::uint64_t size : o.fluid_sizes) {
      attempt([&] {
        const motes::Scene scene = motes::fluid_workload(size);
        Measurement m = measure(scene, o, o.fluid_steps, [](motes::Simulation&) {});
        m.workload = "fluid";
        m.phase = "dam-break";
        print_row(m);
        results.push_back(to_json(m));
      });
    }
  }
  if (o.workload == "soft") {
    for (const int count : o.soft_counts) {
      attempt([&] {
        const motes::Scene scene = motes::soft_workload(count);
        Measurement m = measure(scene, o, o.soft_steps, [](motes::Simulation&) {});
        m.workload = "soft";
        m.phase = "falling";
        print_row(m);
        results.push_back(to_json(m));
      });
    }
  }
  finish(o, results, any_failed);
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto opts = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Run the fixed benchmark workloads (docs/benchmarks.md): W1 settle, W2 dominoes, W3 cloth, "
      "W4 soft");
  cmd->add_option("--workload", opts->workload,
                  "settle, dominoes, all (settle and dominoes), cloth, soft, impulse-dominoes "
                  "(W2's dominoes with impulse contacts), fluid (W5: a dam break, frames of "
                  "1/60 s) or realtime (scenes at frame-sized steps)")
      ->capture_default_str();
  cmd->add_option("--scenes", opts->scenes,
                  "realtime: scene files, or folders whose .json files are scenes")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--realtime-seconds", opts->realtime_seconds,
                  "realtime: simulated seconds of each scene")
      ->check(CLI::Range(1e-3, 3600.0))
      ->capture_default_str();
  cmd->add_option("--frame-rate", opts->frame_rate, "realtime: frames per simulated second")
      ->check(whole_number_of<int>(1, 10000))
      ->capture_default_str();
  cmd->add_option("--cloth-sides", opts->cloth_sides,
                  "W3: cloth sides in particles (a side x side cloth each)")
      ->delimiter(',')
      ->check(whole_number_of<int>(2, 1024))
      ->capture_default_str();
  cmd->add_option("--cloth-steps", opts->cloth_steps, "W3: steps timed")
      ->check(whole_number(1))
      ->capture_default_str();
  cmd->add_option("--fluid-sizes", opts->fluid_sizes,
                  "W5: liquid particles of each dam break (about: a column a x 2a x a)")
      ->delimiter(',')
      ->check(whole_number_of<std::uint64_t>(1000, 100000000))
      ->capture_default_str();
  cmd->add_option("--fluid-steps", opts->fluid_steps, "W5: frames timed (1/60 s each)")
      ->check(whole_number(1))
      ->capture_default_str();
  cmd->add_option("--soft-counts", opts->soft_counts, "W4: numbers of soft cubes (392 particles)")
      ->delimiter(',')
      ->check(whole_number_of<int>(1, 100000))
      ->capture_default_str();
  cmd->add_option("--soft-steps", opts->soft_steps, "W4: steps timed")
      ->check(whole_number(1))
      ->capture_default_str();
  cmd->add_option("--sizes", opts->sizes, "W1 particle counts")
      ->delimiter(',')
      ->check(whole_number(1))
      ->capture_default_str();
  cmd->add_option("--phase", opts->phase, "W1 phase: falling, dense or both")
      ->capture_default_str();
  cmd->add_option("--backend", opts->backend, "auto, openmp, cuda or vulkan")
      ->capture_default_str();
  cmd->add_option("--device", opts->device, "device index within the backend")
      ->check(whole_number_of<int>(0));
  cmd->add_option("--threads", opts->threads,
                  "OpenMP threads, kept whatever the load (0: OpenMP's default, fewer while "
                  "other processes keep the CPUs busy)")
      ->check(whole_number_of<int>(0, kMaxThreads));
  cmd->add_option("--repeats", opts->repeats, "timed repeats (the median is reported)")
      ->check(whole_number_of<int>(1, 1000))
      ->capture_default_str();
  cmd->add_option("--falling-steps", opts->falling_steps, "steps of the W1 falling phase")
      ->check(whole_number(1))
      ->capture_default_str();
  cmd->add_option("--dense-steps", opts->dense_steps, "steps of the W1 dense phase")
      ->check(whole_number(1))
      ->capture_default_str();
  cmd->add_option("--settle-steps", opts->settle_steps,
                  "steps run once to make the W1 dense-phase start state")
      ->check(whole_number(1))
      ->capture_default_str();
  cmd->add_option("--skin", opts->skin,
                  "W1: neighbour-list skin in metres in the timed runs (lists rebuilt when a "
                  "sphere has moved 0.45 of it; default a tenth of the diameter, 0.001); the "
                  "settled start state is made with the default")
      ->check(finite_between(1e-6, 0.01));
  cmd->add_option("--dominoes", opts->dominoes,
                  "W2: number of dominoes (15 particles each; at most 100,000,000 particles)")
      ->check(whole_number_of<int>(1, kMaxDominoes))
      ->capture_default_str();
  cmd->add_option("--domino-rows", opts->domino_rows, "W2: parallel rows (at most --dominoes)")
      ->check(whole_number_of<int>(1, kMaxDominoes))
      ->capture_default_str();
  cmd->add_option("--domino-steps", opts->domino_steps, "W2: steps timed")
      ->check(whole_number(1))
      ->capture_default_str();
  cmd->add_option("--cache", opts->cache, "folder for settled W1 states")->capture_default_str();
  cmd->add_option("--dense-from", opts->dense_from,
                  "W1 dense phase from this LAMMPS data file (write_data after in.make_settled) "
                  "instead of motes's own settled state, for that file's N")
      ->check(CLI::ExistingFile);
  cmd->add_option("--json", opts->json_path, "also write the results as JSON to this file");
  cmd->callback([opts]() { run_bench(*opts); });
}

}  // namespace motes::cli
