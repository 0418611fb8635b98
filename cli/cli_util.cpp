// Helpers shared by the subcommands.
#include "cli_util.h"
#include "run_mpi.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace motes::cli {

void fail(const std::string& message) {
  // Over MPI every rank fails together with the same message (mpi_agree_or_fail): rank 0 says it.
  if (mpi_rank() == 0) fmt::print(stderr, "motes: error: {}\n", message);
  // CLI::App::exit() returns a RuntimeError's code without printing anything more.
  throw CLI::RuntimeError(kErrorExit);
}

std::uint64_t steps_of_duration(double duration, double dt) {
  const double n = std::round(duration / dt);
  if (!(n <= kMaxSteps)) {
    fail(fmt::format("a duration of {} s at dt = {} s is {:.3g} steps: too many", duration, dt, n));
  }
  return static_cast<std::uint64_t>(n);
}

std::uint64_t checked_steps(std::uint64_t steps, const char* option) {
  if (static_cast<double>(steps) > kMaxSteps) {
    fail(fmt::format("{} {} is more than {:.0e} steps", option, steps, kMaxSteps));
  }
  return steps;
}

std::string absolute_path(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::absolute(path, ec);
  return ec ? path : p.lexically_normal().string();
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string format_seconds(double seconds) {
  if (!std::isfinite(seconds)) return "?";
  if (seconds < 1.0) return fmt::format("{:.0f} ms", seconds * 1e3);
  if (seconds < 60.0) return fmt::format("{:.1f} s", seconds);
  const auto total = static_cast<long long>(std::llround(seconds));
  if (total < 3600) return fmt::format("{} min {:02} s", total / 60, total % 60);
  return fmt::format("{} h {:02} min", total / 3600, (total % 3600) / 60);
}

std::string format_si(double value) {
  if (!std::isfinite(value)) return "?";
  const char* suffixes[] = {"", " k", " M", " G", " T"};
  std::size_t i = 0;
  while (std::fabs(value) >= 999.5 && i + 1 < std::size(suffixes)) {
    value /= 1000.0;
    ++i;
  }
  const int decimals = std::fabs(value) >= 99.95 ? 0 : (std::fabs(value) >= 9.995 ? 1 : 2);
  return fmt::format("{:.{}f}{}", value, i == 0 && value == std::floor(value) ? 0 : decimals,
                     suffixes[i]);
}

namespace {

CLI::Validator finite_number(bool allow_zero) {
  const char* description = allow_zero ? "NUMBER >= 0" : "NUMBER > 0";
  return CLI::Validator(
      [allow_zero](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return fmt::format("'{}' is not a number", text);
        if (!std::isfinite(v) || v < 0.0 || (!allow_zero && v == 0.0)) {
          return fmt::format("'{}' must be a finite number {}", text, allow_zero ? ">= 0" : "> 0");
        }
        return {};
      },
      description);
}

}  // namespace

CLI::Validator finite_non_negative() { return finite_number(true); }
CLI::Validator finite_positive() { return finite_number(false); }

CLI::Validator finite_between(double least, double most) {
  return CLI::Validator(
      [least, most](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return fmt::format("'{}' is not a number", text);
        if (!std::isfinite(v) || v < least || v > most) {
          return fmt::format("'{}' must be a finite number from {} to {}", text, least, most);
        }
        return {};
      },
      fmt::format("NUMBER in [{}, {}]", least, most));
}

CLI::Validator whole_number(std::uint64_t least, std::uint64_t most) {
  const bool bounded = most != std::numeric_limits<std::uint64_t>::max();
  return CLI::Validator(
      [least, most, bounded](std::string& text) -> std::string {
        const bool digits = !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
          return c >= '0' && c <= '9';
        });
        const std::string wanted =
            bounded ? fmt::format("from {} to {}", least, most) : fmt::format(">= {}", least);
        if (!digits) return fmt::format("'{}' is not a whole number {}", text, wanted);
        // Digits only: the value, or "too large" once it passes `most` (or 64 bits).
        std::uint64_t value = 0;
        bool too_large = false;
        for (char c : text) {
          const auto d = static_cast<std::uint64_t>(c - '0');
          if (d > most || value > (most - d) / 10) {
            too_large = true;
            break;
          }
          value = value * 10 + d;
        }
        if (too_large) {
          return fmt::format("'{}' is too large: at most {}", text, most);
        }
        if (value < least) return fmt::format("'{}' is not a whole number {}", text, wanted);
        return {};
      },
      bounded ? fmt::format("INTEGER in [{}, {}]", least, most)
              : fmt::format("INTEGER >= {}", least));
}

void add_halo_option(CLI::App* command, std::string& halo) {
  command
      ->add_option("--halo", halo,
                   "under mpirun: how halo copies travel: auto (device to device where every rank "
                   "is on one host and the backend can: CUDA; else through host memory), host "
                   "(always through host memory and MPI)")
      ->check(CLI::IsMember({"auto", "host"}));
}

}  // namespace motes::cli
