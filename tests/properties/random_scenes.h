// Seeded random impulse scenes for the property tests (test_impulse_properties.cpp): domino
// chains, piles, stacks and pyramids, drops onto piles and into corners, and bodies wedged
// between the floor and others, each from one seed, each set at its own place on one floor so
// that many run side by side in one simulation (a batch) without touching.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "motes/devices.h"
#include "motes/scene.h"

namespace motes_props {

/// splitmix64: a small generator with the same output everywhere (the scenes' draws here, the
/// water's in test_fluid_properties.cpp).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// In [0, 1).
  double unit() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  /// In [lo, hi].
  int integer(int lo, int hi) {
    return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  bool chance(double p) { return unit() < p; }
  Eigen::Vector3d vec(double scale) {
    const double x = uniform(-scale, scale);
    const double y = uniform(-scale, scale);
    return {x, y, uniform(-scale, scale)};
  }
  /// A uniformly random rotation (Shoemake).
  Eigen::Quaterniond rotation() {
    const double u1 = unit(), u2 = unit(), u3 = unit();
    const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
    const double t2 = 2.0 * std::numbers::pi * u2, t3 = 2.0 * std::numbers::pi * u3;
    return Eigen::Quaterniond(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2),
                              b * std::sin(t3));
  }

 private:
  std::uint64_t s_;
};

/// The kinds of scene, as issue 25 lists them.
enum class Kind { Chain, Pile, Stack, Drop, Wedge };
inline constexpr Kind kKinds[] = {Kind::Chain, Kind::Pile, Kind::Stack, Kind::Drop, Kind::Wedge};

const char* kind_name(Kind k);
std::optional<Kind> kind_from_name(std::string_view name);

/// Every case shares these: 1 cm particles, dt = 0.5 ms, impulse contacts with the default sweeps
/// and substeps, gravity -9.81 m/s^2 along y, one floor plane at y = 0.
inline constexpr double kDiameter = 0.01;
inline constexpr double kDt = 5.0e-4;

/// One generated scene.
struct Case {
  Kind kind = Kind::Chain;
  std::uint32_t seed = 0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< where it stands on the floor
  motes::Material material;                          ///< its bodies' (friction, restitution)
  std::vector<motes::BodySpec> bodies;               ///< world positions, static walls included
  /// Every dynamic body must be at rest over [rest_from, duration]: drift below 1% of a diameter
  /// and speed below kRestSpeed, except the bodies that may roll.
  bool settles = false;
  double rest_from = 0.0;
  double duration = 3.0;       ///< simulated seconds the case needs
  std::vector<bool> may_roll;  ///< per body: a sphere or a rod of spheres rolls forever
  /// Per body (empty: none): one particle thick, standing on a line of spheres (a domino). Still
  /// upright when the rest window opens, it balances on that line, an unstable equilibrium: it
  /// tips over when rounding has grown enough (e^(lambda t), lambda = sqrt(m g r / I) about 15/s
  /// for these dominoes), which is physics, not a solver's failure; its rest is not checked.
  std::vector<bool> on_edge;
  std::string summary;  ///< one line: what was drawn
};

/// Rest: speed below this (m/s) at the end, besides the drift bound.
inline constexpr double kRestSpeed = 2.0e-3;

/// The case of `kind` drawn from `seed` (the same on every machine: its own generator, no
/// std::uniform_*_distribution, whose results the standard leaves to the library). Its origin
/// depends on the seed only (slot seed % 256 of a 16 x 16 grid, 2 m apart), so a case stands at
/// the same place alone or in a batch of other seeds. Alone it runs the same physics, not the same
/// bits (particle numbers and the times of list builds depend on the batch): a failure names its
/// batch too, which replays it exactly.
Case make_case(Kind kind, std::uint32_t seed);

/// Cases side by side in one scene: the floor, one material per case (and the floor's), the
/// bodies of case k at [first_body[k], first_body[k + 1]).
struct Batch {
  motes::Scene scene;
  std::vector<std::size_t> first_body;
};

/// Fails (empty scene, error in `why`) if two cases share a slot (seeds equal modulo 256).
Batch make_batch(const std::vector<Case>& cases, std::string& why);

/// The device options of the property scenes: MOTES_PROPERTY_THREADS OpenMP threads (unset or 0:
/// OpenMP's default). scripts/test.sh asks for 1: ctest runs two tests side by side on CI's two
/// cores, and these small scenes' many short kernels then cost less CPU time on one thread than
/// on two that wait for each other (20 seeds of the pile, two batches side by side: 145 against
/// 181 CPU seconds). The bits are the same on any number of threads.
inline motes::DeviceOptions device_options() {
  motes::DeviceOptions options;
  if (const char* v = std::getenv("MOTES_PROPERTY_THREADS"); v != nullptr && *v != '\0') {
    options.cpu_threads = std::atoi(v);
  }
  return options;
}

}  // namespace motes_props
