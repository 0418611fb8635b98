// `motes run` and `motes resume` over MPI ranks (run_mpi_session.h): every rank steps its part in
// the same chunks (the loop is shared with the run in one process, session_loop.cpp); at frames
// and guards rank 0 gathers and checks the state and writes it; checkpoint sets every C steps (the
// last two kept); a signal on any rank stops every rank at the same step with a last set.
#ifdef MOTES_HAVE_MPI

#include "run_mpi_session.h"

#include <fmt/format.h>
#include <mpi.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <utility>
#include <vector>

#include "cli_util.h"
#include "motes/energy.h"
#include "progress.h"
#include "run_mpi.h"
#include "run_session.h"
#include "session_loop.h"

namespace motes::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kSetPrefix = "checkpoint-";
constexpr const char* kSetSuffix = ".mckset";

/// |xyz| in double.
double norm3(const shared::vec4& v) {
  const auto x = static_cast<double>(v.x);
  const auto y = static_cast<double>(v.y);
  const auto z = static_cast<double>(v.z);
  return std::sqrt(x * x + y * y + z * z);
}

/// The energy guard of a run over ranks, on the state rank 0 gathered (motes/energy.h, as
/// Simulation::check_motion does it on the device): the reference at the first check, the energy
/// and the speed bound at every check.
struct EnergyGuard {
  EnergyModel model;
  bool started = false;
  EnergyReference reference;
  /// Where potential energy is measured from: the lowest particle at the first check.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double rise = 0.0;    ///< at the last check
  double margin = 0.0;  ///< at the last check
};

/// The motion guard of a run over ranks, on the state rank 0 gathered (docs/scale-out.md): a
/// non-finite particle is an error naming step, body and particle (scene indices), and so are
/// energy above the energy guard's margin and a particle faster than the energy allows; the
/// fastest particle's travel per substep beyond Simulation::kSafeTravel of its diameter is a
/// warning.
Status guard(const Snapshot& s, const DistributedSimulation& sim, EnergyGuard& energy,
             double& travel, std::string& warning) {
  const Settings& settings = sim.settings();
  const double h = settings.dt / static_cast<double>(settings.substeps);
  travel = 0.0;
  std::size_t fastest = 0;
  double fastest_speed = 0.0;
  for (std::size_t i = 0; i < s.particle_pos.size(); ++i) {
    const shared::vec4& p = s.particle_pos[i];
    const shared::vec4& v = s.particle_vel[i];
    const std::uint32_t b = s.particle_body[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(v.x) ||
        !std::isfinite(v.y) || !std::isfinite(v.z)) {
      return Status::error(fmt::format(
          "non-finite state at step {} (t = {:.6g} s): particle {} of body {} '{}': position "
          "({}, {}, {}) m, velocity ({}, {}, {}) m/s; the run has gone unstable (dt {:.4g} s at "
          "substeps {} too large for the contact stiffness?)",
          s.step, s.time, i, b, sim.bodies()[b].name, p.x, p.y, p.z, v.x, v.y, v.z, settings.dt,
          settings.substeps));
    }
    const double speed = norm3(v);
    const double t = p.w > 0.0f ? speed * h / (2.0 * static_cast<double>(p.w)) : 0.0;
    if (t > travel) {
      travel = t;
      fastest = i;
    }
    if (speed > fastest_speed) fastest_speed = speed;
  }

  // The energy guard.
  const std::vector<BodyInfo>& bodies = sim.bodies();
  if (!energy.started) {
    energy.model = energy_model(sim.scene());
    // The lowest particle along gravity (the first without gravity), as Simulation chooses it.
    for (std::size_t i = 0; i < s.particle_pos.size(); ++i) {
      const Eigen::Vector3d x(static_cast<double>(s.particle_pos[i].x),
                              static_cast<double>(s.particle_pos[i].y),
                              static_cast<double>(s.particle_pos[i].z));
      if (i == 0 || settings.gravity.dot(x) > settings.gravity.dot(energy.origin)) {
        energy.origin = x;
      }
    }
  }
  const MechanicalEnergy now = mechanical_energy(s, bodies, settings.gravity, energy.origin);
  if (!energy.started) {
    energy.reference = energy_reference(s, bodies, energy.model, settings.gravity, now);
    energy.started = true;
  }
  const EnergyReference& ref = energy.reference;
  energy.rise = now.total() - ref.energy();
  energy.margin = ref.margin_at(now.kinetic);
  const GuardPlace at{s.step, s.time, settings.dt, settings.substeps};
  std::string who = "no body has kinetic energy";
  if (now.largest_body != MechanicalEnergy::kNone) {
    const BodyInfo& info = bodies[now.largest_body];
    std::uint32_t k = now.largest_particle;
    if (k == MechanicalEnergy::kNone) {  // a rigid body: its fastest particle
      double best = -1.0;
      for (std::uint32_t j = info.first_particle; j < info.first_particle + info.particle_count;
           ++j) {
        const double u = norm3(s.particle_vel[j]);
        if (u > best) {
          best = u;
          k = j;
        }
      }
    }
    who = fmt::format(
        "body {} '{}' has the most kinetic energy, {:.4g} J (particle {} at {:.4g} "
        "m/s)",
        now.largest_body, info.name, now.largest_kinetic, k, norm3(s.particle_vel[k]));
  }
  if (std::string e = energy_error(ref, now.kinetic, now.potential, at, who); !e.empty()) {
    return Status::error(e);
  }
  // The speed bound, on every particle (the fastest decides).
  const double limit = energy_speed_limit(ref, energy.model, now.potential);
  for (std::size_t i = 0; i < s.particle_pos.size() && fastest_speed > limit; ++i) {
    const double speed = norm3(s.particle_vel[i]);
    if (speed != fastest_speed) continue;
    const std::uint32_t b = s.particle_body[i];
    return Status::error(energy_speed_error(ref, energy.model, now.potential, speed, limit,
                                            static_cast<std::uint32_t>(i), b, bodies[b].name, at));
  }

  warning.clear();
  if (travel > Simulation::kSafeTravel) {
    const shared::vec4& p = s.particle_pos[fastest];
    const std::uint32_t b = s.particle_body[fastest];
    const double diameter = 2.0 * static_cast<double>(p.w);
    const double speed = travel * diameter / h;
    warning = fmt::format(
        "step {} (t = {:.6g} s): particle {} of body {} '{}' moves {:.3g} of its diameter "
        "({:.4g} m) per substep at {:.4g} m/s, more than the {} that contacts are resolved at: "
        "contacts can be missed (tunnelling); the largest safe dt at this speed is {:.4g} s at "
        "substeps {} (dt is {:.4g} s)",
        s.step, s.time, fastest, b, sim.bodies()[b].name, travel, diameter, speed,
        Simulation::kSafeTravel,
        Simulation::kSafeTravel * diameter / speed * static_cast<double>(settings.substeps),
        settings.substeps, settings.dt);
  }
  return Status::ok();
}

class DistributedSession final : public SessionLoop {
 public:
  explicit DistributedSession(DistributedPlan plan)
      : SessionLoop(plan.record.series.frame_times, plan.writer.get(), plan.render.get(),
                    "checkpoint set"),
        p_(std::move(plan)),
        rank_(mpi_rank()),
        ranks_(mpi_ranks()) {}

  void run() {
    loop();
    summary();
    if (signal_ != 0) {
      // mpirun ends the job when the first rank exits with an error: every rank's work and
      // output is done first.
      MPI_Barrier(MPI_COMM_WORLD);
      throw CLI::RuntimeError(128 + signal_);
    }
  }

 private:
  [[nodiscard]] std::uint64_t current_step() const override { return p_.sim->steps(); }
  [[nodiscard]] double current_time() const override { return p_.sim->time(); }

  /// One collective per chunk: a signal caught by any rank stops every rank here, at the same
  /// step, and the next chunk's size follows the slowest rank (the same on every rank).
  ChunkStart start_chunk(bool /*stepped*/, double took) override {
    const double mine[2] = {static_cast<double>(InterruptSignals::caught()), took};
    double all[2] = {0.0, 0.0};
    MPI_Allreduce(mine, all, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return {static_cast<int>(all[0]), all[1], all[1] > 0.0};  // > 0: after the first chunk
  }

  void step_chunk(std::uint64_t n) override {
    if (Status s = p_.sim->step(n); !s) stop(s.message());  // the same error on every rank
  }

  void guard_state() override { check(false); }
  void write_frame() override { check(true); }

  /// The state gathered on rank 0 and checked by the motion guard; with `frame`, written as the
  /// next frame (and drawn). A guard or output error stops the run on every rank.
  void check(bool frame) {
    const Clock::time_point start = Clock::now();
    DistributedSimulation& sim = *p_.sim;
    last_guard_step_ = sim.steps();
    ++guards_;
    Result<Snapshot> snap = sim.gather(0);
    if (!snap) stop(snap.message());  // the same error on every rank
    Status ok = Status::ok();
    if (rank_ == 0) {
      double travel = 0.0;
      std::string warning;
      ok = guard(snap.value(), sim, energy_guard_, travel, warning);
      if (ok) energy_.add(energy_guard_.rise, energy_guard_.margin);
      note_warning(warning, travel);
      if (ok && frame && p_.writer) ok = p_.writer->write_frame(snap.value());
      if (ok && frame && p_.render) ok = p_.render->add_frame(snap.value());
    }
    if (Status agreed = agree(MPI_COMM_WORLD, ok); !agreed) stop(agreed.message());
    if (frame) {
      frame_times_.push_back(sim.time());
      last_frame_step_ = sim.steps();
    }
    output_seconds_ += seconds_since(start);
  }

  /// Writes the set checkpoint-<step>.mckset (atomically) and removes all but the last two;
  /// only a state the guard has passed.
  void save_checkpoint() override {
    const Clock::time_point start = Clock::now();
    DistributedSimulation& sim = *p_.sim;
    if (last_guard_step_ != sim.steps()) check(false);
    const fs::path dir = p_.record.checkpoint_dir;
    CheckpointRun record = p_.record;
    record.series.frame_times = frame_times_;
    Status ready = Status::ok();
    if (rank_ == 0) {
      ready = create_output_directory(dir.string(), "checkpoint");
      if (ready && record.output_format == "csv") {
        ready = csv_series_sizes(record.output_dir, record.series);
      }
    }
    mpi_agree_or_fail(ready);
    const std::string set = (dir / checkpoint_set_name(sim.steps())).string();
    if (Status s = sim.save_checkpoint(set, record); !s) fail(s.message());
    if (rank_ == 0) prune_numbered(dir, sim.steps(), kSetPrefix, kSetSuffix, true);
    last_checkpoint_ = set;
    ++checkpoints_;
    output_seconds_ += seconds_since(start);
  }

  /// The signal any rank has caught (0: none), the same on every rank.
  static int agreed_signal() {
    int caught = InterruptSignals::caught();
    MPI_Allreduce(MPI_IN_PLACE, &caught, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return caught;
  }

  void loop() {
    const InterruptSignals signals;
    const Clock::time_point start = Clock::now();
    DistributedSimulation& sim = *p_.sim;
    std::unique_ptr<Progress> progress;
    if (rank_ == 0) progress = std::make_unique<Progress>(p_.total, sim.steps());
    progress_ = progress.get();
    run_steps(p_.total, p_.every, p_.checkpoint_every, p_.resumed);
    if (progress_ != nullptr) progress_->finish();
    progress_ = nullptr;
    Status finished = Status::ok();
    if (p_.writer) finished = p_.writer->finish();
    if (finished && p_.render) finished = p_.render->finish();
    mpi_agree_or_fail(finished);
    if (signal_ == 0) signal_ = agreed_signal();  // came during the last chunk
    if (signal_ != 0 || p_.checkpoint_every > 0) save_checkpoint();
    wall_seconds_ = seconds_since(start);
    if (signal_ != 0 && rank_ == 0) {
      fmt::print(stderr,
                 "motes: interrupted by {} at step {} of {} (t = {:.6g} s); {}; checkpoint set {}\n"
                 "motes: continue with: mpirun -np {} motes resume {}\n",
                 signal_name(signal_), sim.steps(), p_.total, sim.time(), frames_written(),
                 last_checkpoint_, ranks_, last_checkpoint_);
      std::fflush(stderr);
    }
  }

  void summary() const {
    DistributedSimulation& sim = *p_.sim;
    // Totals over the ranks.
    const DistributedStats st = sim.stats();
    const std::uint64_t mine_counts[3] = {st.halo_bodies, st.halo_particles, st.halo_bytes};
    std::uint64_t sums[3] = {0, 0, 0};
    MPI_Reduce(mine_counts, sums, 3, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
    // The busiest rank's seconds in each part.
    const double mine_seconds[4] = {st.copy_seconds, st.mpi_seconds, st.partition_seconds,
                                    st.step_seconds};
    double most[4] = {0.0, 0.0, 0.0, 0.0};
    MPI_Reduce(mine_seconds, most, 4, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    if (rank_ != 0) return;
    const std::uint64_t steps = sim.steps() - first_step_;
    const double rate = step_seconds_ > 0.0 ? static_cast<double>(steps) / step_seconds_ : 0.0;
    fmt::print("motes: {}\n",
               signal_ != 0 ? fmt::format("interrupted ({})", signal_name(signal_)) : "done");
    fmt::print("  {:<16}{} ranks, bricks {}\n", "ranks", ranks_, sim.decomposition().describe());
    fmt::print("  {:<16}{}\n", "particles", sim.particle_count());
    fmt::print("  {:<16}{}\n", "bodies", sim.bodies().size());
    if (p_.resumed) {
      fmt::print("  {:<16}{} of {} (resumed at step {})\n", "steps", sim.steps(), p_.total,
                 first_step_);
    } else {
      fmt::print("  {:<16}{} of {}\n", "steps", sim.steps(), p_.total);
    }
    fmt::print("  {:<16}{:.6g} s\n", "simulated time", sim.time());
    fmt::print(
        "  {:<16}{} partitions, {} bodies migrated; at the end {} halo copies ({} particles)\n",
        "decomposition", st.partitions, st.migrations, sums[0], sums[1]);
    fmt::print("  {:<16}the slowest rank's own steps {}\n", "ranks' steps",
               format_seconds(most[3]));
    fmt::print(
        "  {:<16}{}B sent {}; a rank's most: {} copying state, {} in MPI (transfer and waiting "
        "for the slowest rank), {} partitioning\n",
        "halos", format_si(static_cast<double>(sums[2])),
        st.halo_direct ? "device to device" : "through host memory", format_seconds(most[0]),
        format_seconds(most[1]), format_seconds(most[2]));
    fmt::print("  {:<16}{} ({})\n", "setup", format_seconds(p_.setup_seconds),
               p_.resumed ? "scene, devices and the set's state"
                          : "scene, devices and first "
                            "partition");
    fmt::print("  {:<16}{} (stepping {}, gathering, checks and output {})\n", "wall time",
               format_seconds(wall_seconds_), format_seconds(step_seconds_),
               format_seconds(output_seconds_));
    fmt::print("  {:<16}{} steps/s, {} particle-steps/s (stepping, halos included)\n", "speed",
               format_si(rate), format_si(rate * static_cast<double>(sim.particle_count())));
    print_frames();
    if (checkpoints_ > 0) {
      fmt::print("  {:<16}{} set{} written, the last {}\n", "checkpoints", checkpoints_,
                 checkpoints_ == 1 ? "" : "s", last_checkpoint_);
    }
    print_guards(" on the gathered state");
    std::fflush(stdout);
  }

  DistributedPlan p_;
  int rank_ = 0;
  int ranks_ = 1;
  EnergyGuard energy_guard_;  // rank 0
};

}  // namespace

std::string checkpoint_set_name(std::uint64_t step) {
  return fmt::format("{}{:012}{}", kSetPrefix, step, kSetSuffix);
}

void on_rank0(const std::function<void()>& work) {
  int failed = 0;
  if (mpi_rank() == 0) {
    try {
      work();
    } catch (const CLI::RuntimeError&) {
      failed = 1;  // fail() has printed the message
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (failed != 0) throw CLI::RuntimeError(kErrorExit);
}

void run_distributed_session(DistributedPlan plan) { DistributedSession(std::move(plan)).run(); }

}  // namespace motes::cli

#endif  // MOTES_HAVE_MPI
