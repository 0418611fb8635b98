// The OpenMP backend's team size on a shared machine (backends/openmp/cpu_share.h): /proc/stat
// parsed for the process's CPUs, the rule from other processes' load to a team, and on Linux a
// busy process beside this one taking a thread away.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "cpu_share.h"

#ifdef __linux__
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

namespace {

using motes::openmp::CpuShare;
using motes::openmp::parse_proc_stat;
using motes::openmp::team_for;

constexpr const char* kStat =
    "cpu  900 10 300 5000 20 1 2 7 0 0\n"
    "cpu0 100 1 50 2000 10 1 1 3 0 0\n"
    "cpu1 200 2 60 1000 5 0 0 2 0 0\n"
    "cpu3 600 7 190 2000 5 0 1 2 0 0\n"
    "intr 12345 0 0\n"
    "ctxt 999\n";

TEST(CpuShare, ParsesTheCpusOfTheMask) {
  const motes::openmp::CpuTimes t = parse_proc_stat(kStat, {0, 3});
  ASSERT_TRUE(t.valid);
  // busy: user nice system irq softirq steal; total adds idle and iowait.
  EXPECT_EQ(t.busy, (100u + 1 + 50 + 1 + 1 + 3) + (600u + 7 + 190 + 0 + 1 + 2));
  EXPECT_EQ(t.total, t.busy + 2000 + 10 + 2000 + 5);
  // A CPU of the mask that the text does not list: not valid (the watch then stays off).
  EXPECT_FALSE(parse_proc_stat(kStat, {0, 2}).valid);
  EXPECT_FALSE(parse_proc_stat("", {0}).valid);
}

TEST(CpuShare, TeamFromOtherProcessesLoad) {
  EXPECT_EQ(team_for(2, 0.0, 2), 2);   // quiet
  EXPECT_EQ(team_for(2, 0.3, 2), 2);   // a little: 1.7 CPUs left
  EXPECT_EQ(team_for(2, 0.67, 2), 1);  // a busy process sharing with two threads (2 of 3 CPUs)
  EXPECT_EQ(team_for(2, 1.0, 2), 1);   // a busy process on a core of its own
  EXPECT_EQ(team_for(2, 2.0, 2), 1);   // never fewer than one
  EXPECT_EQ(team_for(16, 1.0, 16), 15);
  EXPECT_EQ(team_for(16, 1.0, 4), 4);  // never more than configured
  EXPECT_EQ(team_for(2, 0.0, 8), 2);   // nor more than the CPUs left
  EXPECT_EQ(team_for(2, -0.1, 2), 2);  // rounding of the ticks: no negative load
}

TEST(CpuShare, OffKeepsTheConfiguredTeam) {
  CpuShare off(4, false);
  EXPECT_FALSE(off.adapting());
  EXPECT_EQ(off.team(), 4);
}

#ifdef __linux__
TEST(CpuShare, ABusyProcessBesideTakesAThreadAway) {
  // On two CPUs of this process's mask (a child inherits it): a child that spins on one of them
  // leaves one, so a watch for two threads must come down to one.
  cpu_set_t mask;
  CPU_ZERO(&mask);
  ASSERT_EQ(sched_getaffinity(0, sizeof(mask), &mask), 0);
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE && cpus.size() < 2; ++c) {
    if (CPU_ISSET(c, &mask)) cpus.push_back(c);
  }
  if (cpus.size() < 2) GTEST_SKIP() << "one CPU in this process's mask";
  cpu_set_t two;
  CPU_ZERO(&two);
  for (int c : cpus) CPU_SET(c, &two);
  ASSERT_EQ(sched_setaffinity(0, sizeof(two), &two), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    volatile unsigned spin = 0;
    while (std::chrono::steady_clock::now() < end) spin = spin + 1;
    _exit(0);
  }
  CpuShare share(2, true);
  ASSERT_TRUE(share.adapting()) << "no /proc/stat to watch";
  int team = 2;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (std::chrono::steady_clock::now() < deadline && team != 1) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    team = share.team();
  }
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  sched_setaffinity(0, sizeof(mask), &mask);
  EXPECT_EQ(team, 1) << "other processes' load seen: " << share.others() << " CPUs";
}
#endif

}  // namespace
