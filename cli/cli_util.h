// Small helpers shared by the subcommands: error exits and number formatting.
#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdint>
#include <limits>
#include <string>

namespace motes::cli {

/// Exit code of scene, mesh, device and output errors.
constexpr int kErrorExit = 2;

/// Most OpenMP threads a command accepts (OpenMP would start every one of them).
constexpr std::uint64_t kMaxThreads = 1024;

/// Prints "motes: error: MESSAGE" on stderr and ends the command with exit code 2.
[[noreturn]] void fail(const std::string& message);

/// More steps than this in one run is a mistake in the arguments or the scene (dt too small).
constexpr double kMaxSteps = 1e13;

/// round(duration / dt) steps; fail() when that is more than kMaxSteps.
std::uint64_t steps_of_duration(double duration, double dt);
/// `steps`, or fail() when it is more than kMaxSteps (`option` names it in the message).
std::uint64_t checked_steps(std::uint64_t steps, const char* option);

/// `path` made absolute (from the current directory) and normalized.
std::string absolute_path(const std::string& path);

/// Seconds on the steady clock since `start`.
double seconds_since(std::chrono::steady_clock::time_point start);

/// A run hands steps to the device (or to the ranks) in chunks sized to take about this long, so
/// that progress, signals and device errors are seen promptly without a call per step.
constexpr double kChunkSeconds = 0.1;
/// The largest chunk, however fast the steps.
constexpr std::uint64_t kMaxChunk = std::uint64_t{1} << 20;

/// A duration for people: "850 ms", "12.3 s", "4 min 05 s", "2 h 03 min".
std::string format_seconds(double seconds);

/// A rate or count with three significant digits and an SI suffix: "1.23e+07" -> "12.3 M".
std::string format_si(double value);

/// --halo auto|host of `motes run` and `motes resume` under mpirun (docs/scale-out.md).
void add_halo_option(CLI::App* command, std::string& halo);

/// Validator for a finite number >= 0 (CLI11's own checks let NaN and infinity through).
CLI::Validator finite_non_negative();
/// Validator for a finite number > 0.
CLI::Validator finite_positive();
/// Validator for a finite number from least to most.
CLI::Validator finite_between(double least, double most);
/// Validator for a count: a whole number from least to most, in digits only ("-5", "2.5" and "1e3"
/// are refused with a plain message; CLI11 would wrap a negative count around or print its range
/// up to the largest double, and say "Could not convert" for one beyond its type). `most` is the
/// largest value of the option's type, or a smaller limit of the option.
CLI::Validator whole_number(std::uint64_t least,
                            std::uint64_t most = std::numeric_limits<std::uint64_t>::max());
/// whole_number for an option of type T: at most T's largest value (or `most`, if smaller).
template <typename T>
CLI::Validator whole_number_of(std::uint64_t least,
                               std::uint64_t most = std::numeric_limits<std::uint64_t>::max()) {
  const auto largest = static_cast<std::uint64_t>(std::numeric_limits<T>::max());
  return whole_number(least, most < largest ? most : largest);
}

}  // namespace motes::cli
