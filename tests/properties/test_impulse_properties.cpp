// Property tests of impulse contacts (issue 25; docs/validation.md, "Random impulse scenes"):
// scenes drawn from seeds (random_scenes.h: domino chains, piles, stacks and pyramids with
// offsets, drops onto piles and into corners, bodies wedged between the floor and others) run
// on every backend, many side by side in one simulation, each checked on its own:
// - energy: its kinetic + potential energy never rises above its start by more than
//   kEnergyMargin of its energy scale (its start's kinetic energy + m g h of its bodies above the
//   floor): impulses with restitution at most 1 and Coulomb friction cannot add energy;
// - no guard warning: no particle travels more than Simulation::kSafeTravel of its diameter per
//   substep (what the motion guard warns about), nothing is NaN or infinite;
// - rest, where the scene should settle: over [rest_from, end] no particle of a body that does not
//   roll drifts 1% of a diameter, and each such body ends slower than kRestSpeed (a domino still
//   upright on its one-particle edge when the window opens, which then tips about its base, is
//   left out: an unstable equilibrium, Case::on_edge).
// A failure prints the seed and how to replay it (alone, or its whole batch: the same bits).
// RandomPositionScenes runs the same scenes with position contacts (issue 27) at frames of 1/60 s:
// energy and travel required as above, rest measured and printed, not required yet.
//
// Environment: MOTES_PROPERTY_SEEDS (seeds per kind; default: openmp 50, vulkan 1, cuda 8, sized
// for CI's two cores; the sanitizer build 2, 1 and 8 for their first 0.5 s; vulkan's pile is seed
// 4 and its stack seed 2, the others seed 1: default_first_seed; a count set here starts at 1),
// MOTES_PROPERTY_DURATION (s: stop there, rest not checked),
// MOTES_PROPERTY_THREADS (OpenMP threads; scripts/test.sh: 1, random_scenes.h says why),
// MOTES_PROPERTY_FIRST (first seed, default 1), MOTES_PROPERTY_KIND (only this kind),
// MOTES_PROPERTY_BATCH (cases per simulation, default 20), MOTES_PROPERTY_SEED (one seed alone),
// MOTES_PROPERTY_DUMP (a folder: each case's last state, for scripts/static_balance.py);
// to look into a failure, MOTES_PROPERTY_TRACE=1 (each case's fastest body every 25 ms, the
// particles that drifted) and MOTES_PROPERTY_ITERATIONS / MOTES_PROPERTY_SUBSTEPS (the scene's
// impulse_iterations and impulse_substeps instead of the defaults),
// MOTES_PROPERTY_POSITION_SUBSTEPS (RandomPositionScenes' substeps a frame, default 24);
// MOTES_PROPERTY_SAVE=FILE with MOTES_PROPERTY_SAVE_AT=T (s): the batch's state at the first look
// at or after T as a checkpoint, and MOTES_PROPERTY_LOAD=FILE: the run goes on from one (written
// by the same cases on any backend: a state from one backend replayed on another; with other
// ITERATIONS or SUBSTEPS, its state alone, the contacts' impulses starting cold).
// scripts/gpu/run-suite.sh runs thousands on the GPU machine (both suites).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "motes/devices.h"
#include "motes/simulation.h"
#include "random_scenes.h"
#include "sanitized_build.h"

namespace motes_props {
namespace {

/// Energy may rise above the start by this fraction of the case's energy scale: what the position
/// correction may lift (overlaps pushed out) and float rounding, not what an instability gives.
constexpr double kEnergyMargin = 0.01;
constexpr int kChunk = 50;  // steps of kDt between looks at the state (25 ms)
/// A domino of one particle thickness (Case::on_edge) tilted less than this when the rest window
/// opens still stands on its line of spheres: an unstable equilibrium, its rest not checked.
/// Leaning on a fallen neighbour, a domino is tilted far more (its support is real).
constexpr double kUprightTilt = 10.0 * 3.14159265358979323846 / 180.0;
/// RandomPositionScenes: frames of 1/60 s in this many substeps. The fastest drops land at about
/// 2.6 m/s: 0.22 of a diameter a substep at 24 (at 16, drop 15 travelled 0.253 of a diameter, at
/// 20 drop 292 0.261, past the guard's quarter: a scene's substeps must follow its fastest
/// motion, as its dt does).
constexpr double kPositionFrame = 1.0 / 60.0;
constexpr int kPositionSubsteps = 24;
// The sanitizer build (tests/sanitized_build.h): fewer seeds, the first 0.5 s.
constexpr bool kQuick = motes_test::kSanitized;

Eigen::Vector3d v3(const motes::shared::vec4& v) {
  return {static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)};
}
double vlen(const motes::shared::vec4& v) { return v3(v).norm(); }

/// What one case did.
struct Outcome {
  double scale = 0.0;    // J
  double rise = 0.0;     // largest energy rise above the start, fraction of the scale
  double travel = 0.0;   // largest travel per substep, in diameters
  double drift = 0.0;    // largest drift over the rest window, in diameters (settling cases)
  double speed = 0.0;    // fastest non-rolling body at the end (settling cases)
  std::string failure;   // empty: passed
  std::string restless;  // a rest failure that is measured, not required (position contacts)
};

int env_int(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? std::atoi(v) : fallback;
}

/// Energy of case k (bodies [first, last)) in a snapshot: 1/2 m v^2 + 1/2 L.w + m g y.
double case_energy(const motes::Snapshot& s, std::size_t first, std::size_t last) {
  double e = 0.0;
  for (std::size_t b = first; b < last; ++b) {
    const double inv_m = static_cast<double>(s.body_pos[b].w);
    if (inv_m == 0.0) continue;
    e += 0.5 * v3(s.body_vel[b]).squaredNorm() / inv_m;
    e += 0.5 * v3(s.body_angmom[b]).dot(v3(s.body_angvel[b]));
    e += 9.81 * static_cast<double>(s.body_pos[b].y) / inv_m;
  }
  return e;
}

/// The vertical span of a body's particle centres in a snapshot (m).
double height_span(const motes::Snapshot& s, const motes::BodyInfo& b) {
  double lo = 1e30, hi = -1e30;
  for (std::size_t i = b.first_particle; i < b.first_particle + b.particle_count; ++i) {
    lo = std::min(lo, static_cast<double>(s.particle_pos[i].y));
    hi = std::max(hi, static_cast<double>(s.particle_pos[i].y));
  }
  return hi - lo;
}

/// MOTES_PROPERTY_DUMP=DIR: each case's last state as DIR/KIND-SEED.txt (for looking into a
/// failure): "mu F", then a line per body of the case ("body INDEX static|dynamic INV_MASS X Y Z")
/// and per particle ("particle BODY X Y Z RADIUS VX VY VZ").
void dump_case(const std::string& dir, const Case& c, const motes::Snapshot& s,
               const std::vector<motes::BodyInfo>& info, std::size_t first, std::size_t last) {
  const std::string path = fmt::format("{}/{}-{}.txt", dir, kind_name(c.kind), c.seed);
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    ADD_FAILURE() << "cannot write " << path;
    return;
  }
  std::fprintf(f, "mu %.9g\n", double{c.material.friction});
  for (std::size_t b = first; b < last; ++b) {
    const motes::shared::vec4 x = s.body_pos[b];
    std::fprintf(f, "body %zu %s %.9g %.9g %.9g %.9g\n", b - first,
                 info[b].kind == motes::BodyKind::Static ? "static" : "dynamic", double{x.w},
                 double{x.x}, double{x.y}, double{x.z});
    for (std::size_t i = info[b].first_particle;
         i < info[b].first_particle + info[b].particle_count; ++i) {
      const motes::shared::vec4 p = s.particle_pos[i], v = s.particle_vel[i];
      std::fprintf(f, "particle %zu %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", b - first, double{p.x},
                   double{p.y}, double{p.z}, double{p.w}, double{v.x}, double{v.y}, double{v.z});
    }
  }
  std::fclose(f);
}

/// Loads checkpoint `path` into a simulation of `scene` (the settings it was written with) on
/// openmp and writes its state into `into` (a simulation of the same cases, other settings).
motes::Status write_checkpoint_state(const motes::Scene& scene, const std::string& path,
                                     motes::Simulation& into) {
  motes::Result<std::unique_ptr<motes::Device>> device = motes::open_device("openmp", -1, {});
  if (!device) return device.status();
  auto other = motes::Simulation::create(scene, std::move(device).value());
  if (!other) return other.status();
  if (motes::Status st = other.value()->load_state(path); !st) return st;
  motes::Result<motes::Snapshot> state = other.value()->snapshot();
  if (!state) return state.status();
  return into.write_state(*state);
}

/// Runs `cases` side by side on `backend`; one outcome per case.
std::vector<Outcome> run_batch(const std::string& backend, const std::vector<Case>& cases,
                               std::string& skip, bool positions) {
  std::vector<Outcome> out(cases.size());
  std::string why;
  Batch batch = make_batch(cases, why);
  if (!why.empty()) {
    for (Outcome& o : out) o.failure = why;
    return out;
  }
  if (positions) {  // position contacts: a step is a frame (RandomPositionScenes)
    batch.scene.settings.contact_model = motes::ContactModel::Positions;
    batch.scene.settings.dt = kPositionFrame;
    batch.scene.settings.substeps =
        std::max(1, env_int("MOTES_PROPERTY_POSITION_SUBSTEPS", kPositionSubsteps));
  }
  const motes::Scene saved_scene = batch.scene;  // the default settings, before the experiments
  // Experiments: other sweeps or substeps than the defaults every scene gets.
  if (const int v = env_int("MOTES_PROPERTY_ITERATIONS", 0); v > 0) {
    batch.scene.settings.impulse_iterations = v;
  }
  if (const int v = env_int("MOTES_PROPERTY_SUBSTEPS", 0); v > 0) {
    batch.scene.settings.impulse_substeps = v;
  }
  motes::Result<std::unique_ptr<motes::Device>> device =
      motes::open_device(backend, -1, motes_props::device_options());
  if (!device) {
    skip = device.message();
    return out;
  }
  auto sim = motes::Simulation::create(batch.scene, std::move(device).value());
  if (!sim) {
    for (Outcome& o : out) o.failure = sim.message();
    return out;
  }
  motes::Simulation& s = *sim.value();
  const std::vector<std::size_t>& first = batch.first_body;
  const std::vector<motes::BodyInfo>& info = s.bodies();
  const auto particles_of = [&](std::size_t k) {
    const motes::BodyInfo& a = info[first[k]];
    const motes::BodyInfo& z = info[first[k + 1] - 1];
    return std::pair<std::size_t, std::size_t>{a.first_particle,
                                               z.first_particle + z.particle_count};
  };
  motes::Result<motes::Snapshot> start = s.snapshot();
  if (!start) {
    for (Outcome& o : out) o.failure = start.message();
    return out;
  }
  std::vector<double> e0(cases.size());
  for (std::size_t k = 0; k < cases.size(); ++k) {
    e0[k] = case_energy(*start, first[k], first[k + 1]);
    out[k].scale = e0[k];  // m g h above the floor (y = 0) + the start's kinetic energy
  }
  const double h = s.settings().dt / s.settings().substeps;
  std::vector<std::vector<motes::shared::vec4>> rest_pos(cases.size());
  std::vector<std::vector<bool>> upright(cases.size());        // on an edge when the window opened
  const bool trace = env_int("MOTES_PROPERTY_TRACE", 0) != 0;  // the fastest body every look
  // MOTES_PROPERTY_DURATION (s): a shorter run, the energy and travel checked, rest not (the
  // sanitizer build: memory errors along the code paths, the physics checked above).
  double duration = batch.scene.settings.duration;
  if (const char* cap = std::getenv("MOTES_PROPERTY_DURATION"); cap != nullptr && *cap != '\0') {
    duration = std::min(duration, std::atof(cap));
  } else if (kQuick) {
    duration = std::min(duration, 0.5);
  }
  const auto steps = static_cast<std::uint64_t>(std::llround(duration / s.settings().dt));
  // A look every 25 ms of simulated time (every frame of position contacts).
  const auto chunk =
      static_cast<std::uint64_t>(std::max(1.0, std::round(kChunk * kDt / s.settings().dt)));
  std::uint64_t done = 0;
  if (const char* load = std::getenv("MOTES_PROPERTY_LOAD"); load != nullptr && *load != '\0') {
    motes::Status st = s.load_state(load);
    // Written with the default sweeps and substeps and run with others: the state alone (the
    // contacts' memory starts cold); if that fails too, the first refusal is the one to read.
    if (!st && write_checkpoint_state(saved_scene, load, s)) st = motes::Status::ok();
    if (!st) {
      for (Outcome& o : out) o.failure = st.message();
      return out;
    }
    done = s.steps();
  }
  const char* save = std::getenv("MOTES_PROPERTY_SAVE");
  const char* save_at_text = std::getenv("MOTES_PROPERTY_SAVE_AT");
  const double save_at = save_at_text != nullptr ? std::atof(save_at_text) : 0.0;
  bool saved = save == nullptr || *save == '\0';
  while (done < steps) {
    const std::uint64_t n = std::min<std::uint64_t>(chunk, steps - done);
    motes::Status st = s.step(n);
    done += n;
    if (st && !saved && s.time() >= save_at - 1e-9) {
      st = s.save_state(save);
      saved = true;
    }
    motes::Result<motes::Snapshot> snap = st ? s.snapshot() : motes::Result<motes::Snapshot>(st);
    if (!snap) {
      for (Outcome& o : out) {
        if (o.failure.empty()) o.failure = "the run stopped: " + snap.message();
      }
      return out;
    }
    const double t = s.time();
    if (trace) {
      for (std::size_t k = 0; k < cases.size(); ++k) {
        double fastest = 0.0;
        std::size_t which = 0;
        for (std::size_t b = first[k]; b < first[k + 1]; ++b) {
          const double v = vlen(snap->body_vel[b]);
          if (v > fastest) {
            fastest = v;
            which = b - first[k];
          }
        }
        const std::size_t b = first[k] + which;
        const motes::shared::vec4 x = snap->body_pos[b], v = snap->body_vel[b],
                                  w = snap->body_angvel[b];
        std::printf(
            "trace %s %u t %.3f energy %+.3g of the scale; fastest body %zu (%u particles) at "
            "%.3g m/s: x (%.4f %.4f %.4f) v (%.4f %.4f %.4f) w (%.3f %.3f %.3f)\n",
            kind_name(cases[k].kind), cases[k].seed, t,
            (case_energy(*snap, first[k], first[k + 1]) - e0[k]) / out[k].scale, which,
            info[b].particle_count, fastest, double{x.x}, double{x.y}, double{x.z}, double{v.x},
            double{v.y}, double{v.z}, double{w.x}, double{w.y}, double{w.z});
      }
    }
    if (done == steps) {
      if (const char* dir = std::getenv("MOTES_PROPERTY_DUMP"); dir != nullptr && *dir != '\0') {
        for (std::size_t k = 0; k < cases.size(); ++k) {
          dump_case(dir, cases[k], *snap, info, first[k], first[k + 1]);
        }
      }
    }
    for (std::size_t k = 0; k < cases.size(); ++k) {
      Outcome& o = out[k];
      if (t > std::max(cases[k].duration, duration) + 1e-9) continue;
      const double rise = (case_energy(*snap, first[k], first[k + 1]) - e0[k]) / o.scale;
      if (!(rise == rise)) {
        o.failure =
            o.failure.empty() ? fmt::format("non-finite state at t = {:.3f} s", t) : o.failure;
        continue;
      }
      o.rise = std::max(o.rise, rise);
      const auto [lo, hi] = particles_of(k);
      for (std::size_t i = lo; i < hi; ++i) {
        const double d = 2.0 * static_cast<double>(snap->particle_pos[i].w);
        const double travel = vlen(snap->particle_vel[i]) * h / d;
        if (!(travel == travel)) o.travel = 1e30;
        o.travel = std::max(o.travel, travel);
      }
      if (cases[k].settles && rest_pos[k].empty() && t >= cases[k].rest_from - 1e-9) {
        rest_pos[k].assign(snap->particle_pos.begin() + static_cast<std::ptrdiff_t>(lo),
                           snap->particle_pos.begin() + static_cast<std::ptrdiff_t>(hi));
        upright[k].assign(first[k + 1] - first[k], false);
        for (std::size_t b = first[k]; b < first[k + 1]; ++b) {
          const std::size_t c = b - first[k];
          if (c >= cases[k].on_edge.size() || !cases[k].on_edge[c]) continue;
          // Its particles' height span against the start's (every domino starts upright; the body
          // frame is the principal axes', not the domino's).
          upright[k][c] =
              height_span(*snap, info[b]) > std::cos(kUprightTilt) * height_span(*start, info[b]);
          if (trace && upright[k][c]) {
            std::printf("trace %s %u body %zu stands on an edge at t %.3f: rest not checked\n",
                        kind_name(cases[k].kind), cases[k].seed, c, t);
          }
        }
      }
      if (cases[k].settles && t >= cases[k].duration - 1e-9) {
        for (std::size_t b = first[k]; b < first[k + 1]; ++b) {
          const std::size_t c = b - first[k];
          if (cases[k].may_roll[c] || info[b].kind == motes::BodyKind::Static) continue;
          const motes::BodyInfo& bi = info[b];
          if (upright[k][c]) {
            // Left out only if it tips: its highest particle moved more than twice its lowest (a
            // turn about its base). One that slides or jitters as a whole is checked as any other.
            std::size_t top = bi.first_particle, bottom = bi.first_particle;
            for (std::size_t i = bi.first_particle; i < bi.first_particle + bi.particle_count;
                 ++i) {
              if (rest_pos[k][i - lo].y > rest_pos[k][top - lo].y) top = i;
              if (rest_pos[k][i - lo].y < rest_pos[k][bottom - lo].y) bottom = i;
            }
            const auto moved = [&, lo = lo](std::size_t i) {  // clang 14: a binding is copied
              return (v3(snap->particle_pos[i]) - v3(rest_pos[k][i - lo])).norm();
            };
            if (moved(top) > 2.0 * moved(bottom)) continue;
          }
          for (std::size_t i = bi.first_particle; i < bi.first_particle + bi.particle_count; ++i) {
            const motes::shared::vec4 a = rest_pos[k][i - lo];
            const double dx = (v3(snap->particle_pos[i]) - v3(a)).norm();
            o.drift = std::max(o.drift, dx / (2.0 * static_cast<double>(a.w)));
            if (trace && dx > 0.005 * 2.0 * static_cast<double>(a.w)) {
              std::printf("trace %s %u body %zu particle %zu drifted %.3g d\n",
                          kind_name(cases[k].kind), cases[k].seed, c, i - bi.first_particle,
                          dx / (2.0 * static_cast<double>(a.w)));
            }
            o.speed = std::max(o.speed, vlen(snap->particle_vel[i]));
          }
        }
      }
    }
  }
  for (std::size_t k = 0; k < cases.size(); ++k) {
    Outcome& o = out[k];
    if (!o.failure.empty()) continue;
    if (o.rise > kEnergyMargin) {
      o.failure = fmt::format("energy rose {:.3g} of its scale ({:.3g} J), more than {}", o.rise,
                              o.scale, kEnergyMargin);
    } else if (o.travel > motes::Simulation::kSafeTravel) {
      o.failure = fmt::format(
          "a particle travelled {:.3g} of its diameter per substep (the guard "
          "warns above {})",
          o.travel, motes::Simulation::kSafeTravel);
    } else if (cases[k].settles && o.drift >= 0.01) {
      o.failure = fmt::format("not at rest: a particle drifted {:.3g} d over [{:.2f}, {:.2f}] s",
                              o.drift, cases[k].rest_from, cases[k].duration);
    } else if (cases[k].settles && o.speed >= kRestSpeed) {
      o.failure = fmt::format("not at rest: a body ends at {:.3g} m/s", o.speed);
    }
    if (positions && o.failure.rfind("not at rest", 0) == 0) o.restless = std::move(o.failure);
  }
  return out;
}

/// Runs `cases` in batches of `per_batch` and reports every failure.
void check_cases(const std::string& backend, const std::vector<Case>& cases,
                 const std::string& label, std::size_t per_batch, bool positions = false) {
  std::size_t failed = 0, restless = 0;
  Outcome worst;
  std::uint32_t worst_rise_seed = 0, worst_drift_seed = 0;
  for (std::size_t at = 0; at < cases.size(); at += per_batch) {
    const std::vector<Case> part(
        cases.begin() + static_cast<std::ptrdiff_t>(at),
        cases.begin() + static_cast<std::ptrdiff_t>(std::min(cases.size(), at + per_batch)));
    std::string skip;
    const std::vector<Outcome> got = run_batch(backend, part, skip, positions);
    if (!skip.empty()) GTEST_SKIP() << "no " << backend << " device: " << skip;
    for (std::size_t k = 0; k < part.size(); ++k) {
      const Case& c = part[k];
      const Outcome& o = got[k];
      if (o.rise > worst.rise) {
        worst.rise = o.rise;
        worst_rise_seed = c.seed;
      }
      if (o.drift > worst.drift) {
        worst.drift = o.drift;
        worst_drift_seed = c.seed;
      }
      worst.travel = std::max(worst.travel, o.travel);
      if (!o.restless.empty()) {
        ++restless;
        std::printf("%s seed %u on %s: %s (position contacts: measured, not yet required)\n",
                    kind_name(c.kind), c.seed, backend.c_str(), o.restless.c_str());
      }
      if (o.failure.empty()) continue;
      ++failed;
      ADD_FAILURE() << fmt::format(
          "{} seed {} on {} ({}): {}\n  replay alone: MOTES_PROPERTY_KIND={} "
          "MOTES_PROPERTY_SEED={}; its batch: MOTES_PROPERTY_KIND={} MOTES_PROPERTY_FIRST={} "
          "MOTES_PROPERTY_SEEDS={} MOTES_PROPERTY_BATCH={}{}",
          kind_name(c.kind), c.seed, backend, c.summary, o.failure, kind_name(c.kind), c.seed,
          kind_name(c.kind), part.front().seed, part.size(), part.size(),
          o.failure.rfind("not at rest", 0) == 0
              ? "\n  could its bodies stand? add MOTES_PROPERTY_DUMP=DIR, then "
                "scripts/static_balance.py DIR/KIND-SEED.txt"
              : "");
    }
  }
  std::printf(
      "%s on %s: %zu cases, %zu failed%s; largest energy rise %.3g of the scale (seed %u), drift "
      "%.3g d (seed %u), travel %.3g d per substep\n",
      label.c_str(), backend.c_str(), cases.size(), failed,
      positions ? fmt::format(", {} not at rest (measured)", restless).c_str() : "", worst.rise,
      worst_rise_seed, worst.drift, worst_drift_seed, worst.travel);
}

int default_seeds(const std::string& backend) {
  if (backend == "openmp") return kQuick ? 2 : 50;
  if (backend == "vulkan") return 1;  // lavapipe in CI: 20 to 90 s a seed
  return 8;                           // run-suite.sh asks for thousands
}

/// The first seed by default: 1, but lavapipe's one pile and one stack are smaller ones (pile 4:
/// 10 boxes, 103 particles, stack 2: a pyramid of 15 boxes, 120 particles), which CI's two cores
/// run in a quarter of the time of seed 1's tray of 23 boxes (1,114 particles, 360 s) and column
/// of ten 4^3 boxes (640, 187 s): lavapipe's time grows with the particles.
int default_first_seed(const std::string& backend, Kind kind) {
  if (backend != "vulkan") return 1;
  if (kind == Kind::Pile) return 4;
  if (kind == Kind::Stack) return 2;
  return 1;
}

using Param = std::tuple<std::string, Kind>;

class RandomImpulseScenes : public ::testing::TestWithParam<Param> {};

/// The cases the environment asks for (MOTES_PROPERTY_SEED, _FIRST, _SEEDS), `count` seeds from
/// `first_seed` by default (from 1 when _SEEDS is set); empty when MOTES_PROPERTY_KIND names
/// another kind.
std::vector<Case> cases_asked(Kind kind, int count, int first_seed = 1) {
  std::vector<Case> cases;
  if (const char* only = std::getenv("MOTES_PROPERTY_KIND"); only != nullptr && *only != '\0') {
    if (only != std::string(kind_name(kind))) return cases;
  }
  if (const int one = env_int("MOTES_PROPERTY_SEED", -1); one >= 0) {
    cases.push_back(make_case(kind, static_cast<std::uint32_t>(one)));
  } else {
    // A count asked for starts at seed 1 on every backend (the GPU machine's thousands compare
    // the same seeds on CUDA and Vulkan); first_seed sizes only the default count.
    const bool asked = env_int("MOTES_PROPERTY_SEEDS", 0) > 0;
    const int first = env_int("MOTES_PROPERTY_FIRST", asked ? 1 : first_seed);
    count = env_int("MOTES_PROPERTY_SEEDS", count);
    for (int s = first; s < first + count; ++s) {
      cases.push_back(make_case(kind, static_cast<std::uint32_t>(s)));
    }
  }
  return cases;
}

TEST_P(RandomImpulseScenes, KeepEnergyStayQuietAndComeToRest) {
  const auto& [backend, kind] = GetParam();
  const std::vector<Case> cases =
      cases_asked(kind, default_seeds(backend), default_first_seed(backend, kind));
  if (cases.empty()) GTEST_SKIP() << "MOTES_PROPERTY_KIND names another kind";
  check_cases(backend, cases, kind_name(kind),
              static_cast<std::size_t>(std::max(1, env_int("MOTES_PROPERTY_BATCH", 20))));
}

std::string param_name(const ::testing::TestParamInfo<Param>& p) {
  return std::get<0>(p.param) + "_" + kind_name(std::get<1>(p.param));
}

INSTANTIATE_TEST_SUITE_P(Backends, RandomImpulseScenes,
                         ::testing::Combine(::testing::Values("openmp", "vulkan", "cuda"),
                                            ::testing::ValuesIn(kKinds)),
                         param_name);

/// The same generated scenes with position contacts (issue 27: "the random scenes of section 14,
/// with the energy check, run on this solver too"), at frames of 1/60 s in kPositionSubsteps
/// substeps: energy within kEnergyMargin of its scale and no guard-level travel, required of
/// every seed. Rest is measured and printed, not required yet: about 12% of cases in openmp's
/// batches of 20 and 37% in the GPU's batches of 250 end with a body at a few mm/s that
/// hardly moves, or sliding (docs/validation.md, section 15), issue 27's open item.
/// Seeds per kind: openmp 10 (2 in the sanitizer build, its first 0.5 s), vulkan 1 (the same ones
/// as RandomImpulseScenes), cuda 8.
class RandomPositionScenes : public ::testing::TestWithParam<Param> {};

TEST_P(RandomPositionScenes, KeepEnergyAndStayQuiet) {
  const auto& [backend, kind] = GetParam();
  const int seeds = backend == "openmp" ? (kQuick ? 2 : 10) : default_seeds(backend);
  const std::vector<Case> cases = cases_asked(kind, seeds, default_first_seed(backend, kind));
  if (cases.empty()) GTEST_SKIP() << "MOTES_PROPERTY_KIND names another kind";
  check_cases(backend, cases, std::string(kind_name(kind)) + " (position contacts)",
              static_cast<std::size_t>(std::max(1, env_int("MOTES_PROPERTY_BATCH", 20))), true);
}

INSTANTIATE_TEST_SUITE_P(Backends, RandomPositionScenes,
                         ::testing::Combine(::testing::Values("openmp", "vulkan", "cuda"),
                                            ::testing::ValuesIn(kKinds)),
                         param_name);

/// Seeds that failed once, kept on every backend: while issue 25's fixes were made, piles 1, 3 and
/// 9 crept (the warm start lost at every list build), pyramids 2 and 4 and drop 8 drifted, drop 2
/// slid 2.5 d, drop 3's energy rose 1.1% and wedge 5's box walked 3.7 d out of its gap (sweeps
/// split otherwise than now, or no leak).
struct Kept {
  Kind kind;
  std::uint32_t seed;
};
const Kept kKept[] = {{Kind::Pile, 1},  {Kind::Pile, 3},  {Kind::Pile, 9},
                      {Kind::Stack, 2}, {Kind::Stack, 4}, {Kind::Drop, 2},
                      {Kind::Drop, 3},  {Kind::Drop, 8},  {Kind::Wedge, 5}};

/// The device's name when `backend` is Vulkan on a CPU (lavapipe, CI's), else empty: the seeds
/// run one at a time are too slow there (80 s a seed) and run on openmp and a GPU's Vulkan.
std::string lavapipe(const std::string& backend) {
  if (backend != "vulkan") return {};
  motes::Result<std::unique_ptr<motes::Device>> d = motes::open_device("vulkan", -1, {});
  if (d && d.value()->info().name.find("llvmpipe") != std::string::npos)
    return d.value()->info().name;
  return {};
}

class KeptImpulseSeeds : public ::testing::TestWithParam<std::string> {};

TEST_P(KeptImpulseSeeds, StillPass) {
  // Vulkan on a CPU (lavapipe, CI's) runs them about ten times slower than openmp: 80 s a seed
  // (12 minutes in all) on CI's two cores. They run there on openmp, and on CUDA and Vulkan on the
  // GPU machine (scripts/gpu/run-suite.sh properties).
  if (const std::string cpu = lavapipe(GetParam()); !cpu.empty()) {
    GTEST_SKIP() << "kept seeds on " << cpu
                 << ": run on openmp here and on a GPU's Vulkan (80 s a seed on lavapipe)";
  }
  // One at a time: each as its own scene, whatever else is kept (two seeds equal modulo 256
  // would share a place anyway).
  for (const Kept& k : kKept) check_cases(GetParam(), {make_case(k.kind, k.seed)}, "kept seed", 1);
}

INSTANTIATE_TEST_SUITE_P(Backends, KeptImpulseSeeds, ::testing::Values("openmp", "vulkan", "cuda"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

/// Chains and piles 300 m out in x and z, where floats are 30.5 um apart (1.5 times the contacts'
/// slop), must come to rest as near the origin: contacts take their geometry from the bodies'
/// centres and small offsets, and centres move as pairs of floats (shared/impulse.h:
/// contact_particle; shared/body_math.h: body_push_pose). Before both (openmp), chain 3 ended at
/// 7 mm/s and pile 1 at 12 mm/s here (docs/validation.md, section 14). Particle positions are
/// floats: a move below their spacing (0.003 d) may show as one.
class FarImpulseScenes : public ::testing::TestWithParam<std::string> {};

TEST_P(FarImpulseScenes, ComeToRestFarFromTheOrigin) {
  if (const std::string cpu = lavapipe(GetParam()); !cpu.empty()) {
    GTEST_SKIP() << "far scenes on " << cpu << ": run on openmp here and on a GPU's Vulkan";
  }
  for (const Kind kind : {Kind::Chain, Kind::Pile}) {
    std::vector<Case> cases;
    for (std::uint32_t seed = 1; seed <= (kQuick ? 2u : 6u); ++seed) {
      Case c = make_case(kind, seed);
      const Eigen::Vector3d away(300.0, 0.0, -300.0);
      c.origin += away;
      for (motes::BodySpec& b : c.bodies) b.position += away;
      cases.push_back(std::move(c));
    }
    check_cases(GetParam(), cases, std::string(kind_name(kind)) + " 300 m out", cases.size());
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, FarImpulseScenes, ::testing::Values("openmp", "vulkan", "cuda"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace motes_props
