// CpuShare: the OpenMP team size from what other processes leave of this process's CPUs.
#include "cpu_share.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <sstream>

#ifdef __linux__
#include <sched.h>
#include <unistd.h>
#endif

namespace motes::openmp {

CpuTimes parse_proc_stat(const std::string& text, const std::vector<int>& cpus) {
  CpuTimes t;
  std::istringstream in(text);
  std::string line;
  int found = 0;
  while (std::getline(in, line)) {
    if (line.rfind("cpu", 0) != 0 || line.size() < 4 || line[3] < '0' || line[3] > '9') continue;
    std::istringstream f(line.substr(3));
    int cpu = -1;
    std::uint64_t v[8] = {};
    f >> cpu;
    for (std::uint64_t& x : v) f >> x;  // user nice system idle iowait irq softirq steal
    if (!f || std::find(cpus.begin(), cpus.end(), cpu) == cpus.end()) continue;
    const std::uint64_t busy = v[0] + v[1] + v[2] + v[5] + v[6] + v[7];
    t.busy += busy;
    t.total += busy + v[3] + v[4];
    ++found;
  }
  t.valid = found == static_cast<int>(cpus.size()) && found > 0;
  return t;
}

int team_for(int cpus, double others, int most) {
  const double left = static_cast<double>(cpus) - std::max(0.0, others);
  const int team = static_cast<int>(std::floor(left + 0.35));
  return std::clamp(team, 1, std::max(1, most));
}

CpuShare::CpuShare(int most, bool adapt) : most_(std::max(1, most)), team_(most_) {
#ifdef __linux__
  cpu_set_t set;
  CPU_ZERO(&set);
  if (adapt && most_ > 1 && sched_getaffinity(0, sizeof(set), &set) == 0) {
    for (int c = 0; c < CPU_SETSIZE; ++c) {
      if (CPU_ISSET(c, &set)) cpus_.push_back(c);
    }
    const long hz = sysconf(_SC_CLK_TCK);
    if (hz > 0) tick_ = 1.0 / static_cast<double>(hz);
    adapt_ = !cpus_.empty();
  }
#else
  (void)adapt;
#endif
  if (adapt_) look();
}

int CpuShare::team() {
  if (!adapt_) return team_;
  if (std::chrono::steady_clock::now() - last_time_ >= kPeriod) look();
  return team_;
}

void CpuShare::look() {
#ifdef __linux__
  std::ifstream in("/proc/stat");
  std::stringstream text;
  text << in.rdbuf();
  CpuTimes now = parse_proc_stat(text.str(), cpus_);
  if (!now.valid) {  // no /proc/stat, or other CPUs than it lists: keep the configured team
    adapt_ = false;
    team_ = most_;
    return;
  }
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  now.own = static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  const auto time = std::chrono::steady_clock::now();
  if (looks_ > 0) {
    const double wall = std::chrono::duration<double>(time - last_time_).count();
    if (wall > 0.0) {
      const double busy = static_cast<double>(now.busy - last_.busy) * tick_;
      const double others = std::max(0.0, busy - (now.own - last_.own)) / wall;
      others_ = looks_ == 1 ? others : 0.5 * (others_ + others);
      team_ = team_for(static_cast<int>(cpus_.size()), others_, most_);
    }
  }
  ++looks_;
  last_ = now;
  last_time_ = time;
#endif
}

}  // namespace motes::openmp
