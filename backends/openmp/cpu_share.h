// How many of the CPUs this process may run on are left to it by other processes: the OpenMP
// backend sizes its team from it, so that a machine shared with another busy program is not made
// slower by threads that wait for a core (docs/architecture.md, "Threads on a shared machine").
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace motes::openmp {

/// Busy and total time of some CPUs, in clock ticks (/proc/stat), and of this process (seconds of
/// CPU time of all its threads).
struct CpuTimes {
  std::uint64_t busy = 0;   ///< user + nice + system + irq + softirq + steal
  std::uint64_t total = 0;  ///< busy + idle + iowait
  double own = 0.0;         ///< this process
  bool valid = false;
};

/// Sums the "cpuN" lines of a /proc/stat text for the CPUs in `cpus` (busy and total ticks). A
/// text without them leaves `valid` false.
CpuTimes parse_proc_stat(const std::string& text, const std::vector<int>& cpus);

/// The team size for `cpus` CPUs when other processes keep `others` of them busy (in CPUs, a
/// smoothed average): one thread per CPU they leave, a CPU counted as left when at least 0.65 of
/// it is; at least 1, at most `most`.
int team_for(int cpus, double others, int most);

/// Watches the CPUs of this process's affinity mask (Linux: /proc/stat, and the process's own CPU
/// time) and says how many threads to run. Elsewhere, or when switched off, always `most`.
class CpuShare {
 public:
  /// most: the configured thread count; adapt: false keeps it fixed.
  CpuShare(int most, bool adapt);
  /// The team for the next kernels; looks at the CPUs again when `period` has passed since the
  /// last look (a /proc/stat read, some 20 us), so call it often: it reads a clock otherwise.
  int team();
  /// Other processes' busy CPUs, smoothed (0 until two looks were made).
  [[nodiscard]] double others() const { return others_; }
  [[nodiscard]] bool adapting() const { return adapt_; }
  static constexpr std::chrono::milliseconds kPeriod{100};

 private:
  void look();
  int most_ = 1;
  bool adapt_ = false;
  int team_ = 1;
  std::vector<int> cpus_;
  CpuTimes last_;
  std::chrono::steady_clock::time_point last_time_;
  double others_ = 0.0;
  int looks_ = 0;
  double tick_ = 0.01;  // seconds per clock tick
};

}  // namespace motes::openmp
