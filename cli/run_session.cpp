// `motes run` and `motes resume` in one process: frames every K steps, checkpoints every C steps
// (the last two kept), progress, SIGINT/SIGTERM (a last checkpoint, then a non-zero exit), and the
// summary. The loop itself is shared with the run over MPI ranks (session_loop.cpp).
#include "run_session.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "cli_util.h"
#include "progress.h"
#include "session_loop.h"

namespace motes::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kCheckpointPrefix = "checkpoint-";
constexpr const char* kCheckpointSuffix = ".mck";

volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_signal(int signal) {
  g_signal = signal;
  // A second Ctrl-C (or SIGTERM) ends the process at once.
  std::signal(signal, SIG_DFL);
}

/// The step of a name PREFIX<digits>SUFFIX, or nothing; `tmp`: the name of one being written
/// (SUFFIX.tmp).
bool numbered_step(const std::string& name, const std::string& prefix, const std::string& suffix,
                   std::uint64_t& step, bool& tmp) {
  if (name.rfind(prefix, 0) != 0) return false;
  std::string rest = name.substr(prefix.size());
  tmp = rest.size() > 4 && rest.compare(rest.size() - 4, 4, ".tmp") == 0;
  if (tmp) rest.resize(rest.size() - 4);
  if (rest.size() <= suffix.size() ||
      rest.compare(rest.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return false;
  }
  rest.resize(rest.size() - suffix.size());
  if (rest.empty() || rest.size() > 19 ||
      !std::all_of(rest.begin(), rest.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return false;
  }
  step = std::stoull(rest);
  return true;
}
}  // namespace

void prune_numbered(const fs::path& dir, std::uint64_t newest, const std::string& prefix,
                    const std::string& suffix, bool directories) {
  std::vector<std::pair<std::uint64_t, fs::path>> older;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    std::uint64_t step = 0;
    bool tmp = false;
    if (e.is_directory(ec) != directories ||
        !numbered_step(e.path().filename().string(), prefix, suffix, step, tmp)) {
      continue;
    }
    if (tmp) {
      fs::remove_all(e.path(), ec);
    } else if (step < newest) {
      older.emplace_back(step, e.path());
    }
  }
  std::sort(older.begin(), older.end(), [](const auto& a, const auto& b) { return a > b; });
  for (std::size_t k = 1; k < older.size(); ++k) fs::remove_all(older[k].second, ec);
}

void EnergyRise::add(double rise, double margin) {
  const double fraction = margin > 0.0 ? rise / margin : (rise > 0.0 ? HUGE_VAL : 0.0);
  if (!any_ || fraction > fraction_) {
    fraction_ = fraction;
    rise_ = rise;
    margin_ = margin;
  }
  any_ = true;
}

std::string EnergyRise::summary() const {
  if (!any_) return "no energy check";
  if (rise_ <= 0.0) return fmt::format("energy never above its start (margin {:.3g} J)", margin_);
  return fmt::format("energy at most {:.3g} of its margin above its start ({:.3g} J of {:.3g} J)",
                     fraction_, rise_, margin_);
}

namespace {

class Session final : public SessionLoop {
 public:
  explicit Session(SessionPlan plan)
      : SessionLoop(plan.record.series.frame_times, plan.writer.get(), plan.render.get(),
                    "checkpoint"),
        p_(std::move(plan)) {}

  void run() {
    loop();
    summary();
    if (signal_ != 0) throw CLI::RuntimeError(128 + signal_);
  }

 private:
  [[nodiscard]] std::uint64_t current_step() const override { return p_.sim->steps(); }
  [[nodiscard]] double current_time() const override { return p_.sim->time(); }

  ChunkStart start_chunk(bool stepped, double took) override {
    return {InterruptSignals::caught(), took, stepped};
  }

  void step_chunk(std::uint64_t n) override {
    Simulation& sim = *p_.sim;
    if (Status s = sim.step(n); !s) fail(s.message());
    if (Status s = sim.device().synchronize(); !s) fail(s.message());
  }

  /// The motion guard (Simulation::check_motion): prints a tunnelling warning the first time
  /// and whenever it is twice as bad as the last one printed; stops the run on an error.
  void guard_state() override {
    Simulation& sim = *p_.sim;
    last_guard_step_ = sim.steps();
    ++guards_;
    Result<MotionReport> r = sim.check_motion();
    if (!r) stop(r.message());
    energy_.add(r->rise, r->reference.margin_at(r->kinetic_energy));
    note_warning(r->warning, r->travel);
  }

  /// Checks the state and writes it as the next frame.
  void write_frame() override {
    const Clock::time_point start = Clock::now();
    Simulation& sim = *p_.sim;
    guard_state();
    if (p_.writer || p_.render) {
      Result<Snapshot> snapshot = sim.snapshot();
      if (!snapshot) fail(snapshot.message());
      sim.hide_parked(snapshot.value());  // an emitter's waiting particles are not drawn
      if (p_.writer) {
        if (Status s = p_.writer->write_frame(snapshot.value()); !s) fail(s.message());
      }
      if (p_.render) {
        if (Status s = p_.render->add_frame(snapshot.value()); !s) fail(s.message());
      }
    }
    frame_times_.push_back(sim.time());
    last_frame_step_ = sim.steps();
    output_seconds_ += seconds_since(start);
  }

  /// Writes checkpoint-<step>.mck (atomically) and removes all but the last two; only a state
  /// the guard has passed.
  void save_checkpoint() override {
    const Clock::time_point start = Clock::now();
    Simulation& sim = *p_.sim;
    if (last_guard_step_ != sim.steps()) guard_state();
    const fs::path dir = p_.record.checkpoint_dir;
    if (Status s = create_output_directory(dir.string(), "checkpoint"); !s) fail(s.message());
    CheckpointRun record = p_.record;
    record.series.frame_times = frame_times_;
    if (record.output_format == "csv") {
      if (Status s = csv_series_sizes(record.output_dir, record.series); !s) fail(s.message());
    }
    const fs::path path = dir / checkpoint_file_name(sim.steps());
    if (Status s = sim.save_state(path.string(), record); !s) fail(s.message());
    prune_numbered(dir, sim.steps(), kCheckpointPrefix, kCheckpointSuffix, false);
    last_checkpoint_ = path.string();
    ++checkpoints_;
    output_seconds_ += seconds_since(start);
  }

  void loop() {
    const InterruptSignals signals;
    const Clock::time_point start = Clock::now();
    Progress progress(p_.total, p_.sim->steps());
    progress_ = &progress;
    try {
      run_steps(p_.total, p_.every, p_.checkpoint_every, p_.resumed);
    } catch (const CLI::RuntimeError&) {
      progress.finish();  // so that the error starts on a line of its own
      throw;
    }
    progress.finish();
    progress_ = nullptr;
    if (p_.writer) {
      if (Status s = p_.writer->finish(); !s) fail(s.message());
    }
    if (p_.render) {
      if (Status s = p_.render->finish(); !s) fail(s.message());
    }
    if (signal_ == 0) signal_ = InterruptSignals::caught();  // came during the last chunk
    if (signal_ != 0 || p_.checkpoint_every > 0) save_checkpoint();
    wall_seconds_ = seconds_since(start);
    if (signal_ != 0) {
      Simulation& sim = *p_.sim;
      fmt::print(stderr,
                 "motes: interrupted by {} at step {} of {} (t = {:.6g} s); {}; checkpoint {}\n"
                 "motes: continue with: motes resume {}\n",
                 signal_name(signal_), sim.steps(), p_.total, sim.time(), frames_written(),
                 last_checkpoint_, last_checkpoint_);
    }
  }

  void summary() const {
    Simulation& sim = *p_.sim;
    const DeviceInfo& info = sim.device().info();
    // The state's fingerprint: equal on every run of the same scene, steps and backend.
    const Result<std::uint64_t> hash = sim.state_hash();
    const std::uint64_t steps = sim.steps() - first_step_;
    const double rate = step_seconds_ > 0.0 ? static_cast<double>(steps) / step_seconds_ : 0.0;
    const double particle_rate = rate * sim.particle_count();
    fmt::print("motes: {}\n",
               signal_ != 0 ? fmt::format("interrupted ({})", signal_name(signal_)) : "done");
    fmt::print("  {:<16}{} {}: {}{}\n", "device", info.backend, info.index, info.name,
               info.detail.empty() ? "" : fmt::format(" ({})", info.detail));
    fmt::print("  {:<16}{}\n", "particles", sim.particle_count());
    fmt::print("  {:<16}{}\n", "bodies", sim.body_count());
    if (p_.resumed) {
      fmt::print("  {:<16}{} of {} (resumed at step {})\n", "steps", sim.steps(), p_.total,
                 first_step_);
    } else {
      fmt::print("  {:<16}{} of {}\n", "steps", sim.steps(), p_.total);
    }
    fmt::print("  {:<16}{:.6g} s\n", "simulated time", sim.time());
    if (hash) fmt::print("  {:<16}{:016x}\n", "state hash", hash.value());
    fmt::print("  {:<16}{} (scene, device and upload)\n", "setup",
               format_seconds(p_.setup_seconds));
    fmt::print("  {:<16}{} (stepping {}, checks and output {})\n", "wall time",
               format_seconds(wall_seconds_), format_seconds(step_seconds_),
               format_seconds(output_seconds_));
    fmt::print("  {:<16}{} steps/s, {} particle-steps/s (stepping only)\n", "speed",
               format_si(rate), format_si(particle_rate));
    print_frames();
    if (checkpoints_ > 0) {
      fmt::print("  {:<16}{} written, the last {}\n", "checkpoints", checkpoints_,
                 last_checkpoint_);
    }
    print_guards("");
    std::fflush(stdout);
  }

  SessionPlan p_;
};

}  // namespace

InterruptSignals::InterruptSignals() {
  g_signal = 0;
  previous_int_ = std::signal(SIGINT, on_signal);
  previous_term_ = std::signal(SIGTERM, on_signal);
}

InterruptSignals::~InterruptSignals() {
  std::signal(SIGINT, previous_int_);
  std::signal(SIGTERM, previous_term_);
}

int InterruptSignals::caught() { return g_signal; }

const char* signal_name(int signal) {
  return signal == SIGINT ? "SIGINT (Ctrl-C)" : signal == SIGTERM ? "SIGTERM" : "a signal";
}

std::string checkpoint_file_name(std::uint64_t step) {
  return fmt::format("{}{:012}{}", kCheckpointPrefix, step, kCheckpointSuffix);
}

void run_session(SessionPlan plan) { Session(std::move(plan)).run(); }

}  // namespace motes::cli
