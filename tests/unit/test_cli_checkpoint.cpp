// `motes run --checkpoint-every` and `motes resume`, run as a user would (docs/cli.md,
// docs/reliability.md): a resumed run writes the same files and reaches the same state hash as the
// uninterrupted one, refusals write nothing, SIGINT and SIGTERM leave a last checkpoint, and a run
// killed with SIGKILL while it writes a checkpoint leaves the previous one usable.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "motes/checkpoint.h"
#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "unit/cli_support.h"
#include "unit/test_support.h"

namespace fs = std::filesystem;

namespace {

using motes_test::contains;
using motes_test::describe;
using motes_test::Outcome;
using motes_test::read_text;
using motes_test::run_motes;
using motes_test::TempDir;

using motes_test::kMixedScene;

std::string summary_hash(const Outcome& o) {
  std::smatch m;
  if (!std::regex_search(o.out, m, std::regex(R"(state hash +([0-9a-f]{16}))"))) return "";
  return m[1];
}

/// Every file under `dir` (checkpoints excluded) with its contents.
std::map<std::string, std::string> files_of(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file()) out[e.path().filename().string()] = read_text(e.path());
  }
  return out;
}

/// Every file under `dir`, recursively, with its size and modification time.
std::map<std::string, std::pair<std::uintmax_t, fs::file_time_type>> stamps_of(
    const fs::path& dir) {
  std::map<std::string, std::pair<std::uintmax_t, fs::file_time_type>> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) {
      out[fs::relative(e.path(), dir).string()] = {e.file_size(), e.last_write_time()};
    }
  }
  return out;
}

std::vector<std::string> backends_here() {
  std::vector<std::string> out;
  for (const motes::BackendReport& r : motes::list_backends()) {
    if (!r.devices.empty()) out.push_back(r.backend);
  }
  return out;
}

/// Starts `motes ARGS` with stdout and stderr into files; returns its process id.
pid_t spawn_motes(const std::vector<std::string>& args, const std::string& out,
                  const std::string& err) {
  std::vector<std::string> argv_s = {MOTES_CLI_PATH};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  const pid_t pid = fork();
  if (pid == 0) {
    const int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int in = ::open("/dev/null", O_RDONLY);
    if (o < 0 || e < 0 || in < 0) _exit(127);
    dup2(in, 0);
    dup2(o, 1);
    dup2(e, 2);
    std::vector<char*> argv;
    for (std::string& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

/// Waits for `pid`; its exit code, or 1000 + the signal that ended it.
int wait_for(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 1000 + WTERMSIG(status);
  return -1;
}

/// Checkpoint files (checkpoint-*.mck) in `dir` by step, and whether a *.tmp one is there.
std::map<std::uint64_t, fs::path> checkpoints_in(const fs::path& dir, bool* tmp = nullptr) {
  std::map<std::uint64_t, fs::path> out;
  if (tmp != nullptr) *tmp = false;
  if (!fs::is_directory(dir)) return out;
  const std::regex name(R"(checkpoint-(\d+)\.mck(\.tmp)?)");
  for (const auto& e : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string f = e.path().filename().string();
    if (!std::regex_match(f, m, name)) continue;
    if (m[2].matched) {
      if (tmp != nullptr) *tmp = true;
    } else {
      out[std::stoull(m[1])] = e.path();
    }
  }
  return out;
}

// 200 steps in one run against 100 steps with checkpoints, then `motes resume` for 100 more: the
// same state hash, and the same frame files byte for byte (VTU series and CSV), on every backend
// here. Then a run of 200 resumed from its checkpoint at 150 with no --steps (the rest of the
// run): frames before the checkpoint are not written again.
TEST(CliCheckpoint, ResumeContinuesTheSeriesBitwise) {
  for (const std::string& backend : backends_here()) {
    for (const std::string format : {"vtu", "csv"}) {
      SCOPED_TRACE(backend + " " + format);
      TempDir tmp;
      const std::string full = tmp / "full";
      const std::string part = tmp / "part";
      const Outcome a = run_motes(tmp, {"run", kMixedScene, "--backend", backend, "--steps", "200",
                                        "--every", "20", "--format", format, "--out", full});
      ASSERT_EQ(a.exit_code, 0) << describe(a);
      const Outcome b =
          run_motes(tmp, {"run", kMixedScene, "--backend", backend, "--steps", "100", "--every",
                          "20", "--format", format, "--out", part, "--checkpoint-every", "50"});
      ASSERT_EQ(b.exit_code, 0) << describe(b);
      EXPECT_TRUE(contains(b.out, "checkpoints     2 written")) << describe(b);
      const auto cks = checkpoints_in(fs::path(part) / "checkpoints");
      ASSERT_EQ(cks.size(), 2u);
      EXPECT_EQ(cks.begin()->first, 50u);
      EXPECT_EQ(cks.rbegin()->first, 100u);
      const Outcome c = run_motes(tmp, {"resume", cks.rbegin()->second.string(), "--steps", "100"});
      ASSERT_EQ(c.exit_code, 0) << describe(c);
      EXPECT_TRUE(contains(c.out, "200 of 200 (resumed at step 100)")) << describe(c);
      EXPECT_EQ(summary_hash(c), summary_hash(a)) << describe(a) << describe(c);
      EXPECT_FALSE(summary_hash(a).empty());
      auto whole = files_of(full);
      auto resumed = files_of(part);
      EXPECT_EQ(whole.size(), resumed.size());
      for (const auto& [name, text] : whole) {
        EXPECT_TRUE(resumed.count(name) && resumed[name] == text) << name << " differs";
      }
      // After the resume: checkpoints at 150 and 200, the older ones removed.
      const auto after = checkpoints_in(fs::path(part) / "checkpoints");
      ASSERT_EQ(after.size(), 2u);
      EXPECT_EQ(after.begin()->first, 150u);

      // The rest of the run by default; frames up to the checkpoint kept as they are.
      const std::string again = tmp / "again";
      const Outcome d =
          run_motes(tmp, {"run", kMixedScene, "--backend", backend, "--steps", "200", "--every",
                          "20", "--format", format, "--out", again, "--checkpoint-every", "50"});
      ASSERT_EQ(d.exit_code, 0) << describe(d);
      const auto stamps = stamps_of(again);
      const Outcome e = run_motes(
          tmp,
          {"resume", (fs::path(again) / "checkpoints" / "checkpoint-000000000150.mck").string()});
      ASSERT_EQ(e.exit_code, 0) << describe(e);
      EXPECT_TRUE(contains(e.out, "200 of 200 (resumed at step 150)")) << describe(e);
      EXPECT_EQ(summary_hash(e), summary_hash(a)) << describe(e);
      EXPECT_EQ(files_of(again), whole);
      if (format == "vtu") {
        const auto later = stamps_of(again);
        for (int frame = 0; frame <= 7; ++frame) {  // steps 0 to 140
          for (const char* series : {"particles", "bodies"}) {
            const std::string name = fmt::format("{}_{:06}.vtu", series, frame);
            EXPECT_TRUE(later.at(name) == stamps.at(name)) << name << " was written again";
          }
        }
      }
    }
  }
}

// An OpenMP checkpoint resumed on Vulkan: the run goes on, saying it is not bitwise.
TEST(CliCheckpoint, ResumeOnAnotherBackend) {
  const auto here = backends_here();
  if (std::find(here.begin(), here.end(), "vulkan") == here.end()) {
    GTEST_SKIP() << "no Vulkan device";
  }
  TempDir tmp;
  const Outcome a = run_motes(tmp, {"run", kMixedScene, "--backend", "openmp", "--steps", "60",
                                    "--checkpoint-every", "60", "--out", tmp / "out"});
  ASSERT_EQ(a.exit_code, 0) << describe(a);
  const Outcome b = run_motes(tmp, {"resume", tmp / "out/checkpoints/checkpoint-000000000060.mck",
                                    "--backend", "vulkan", "--steps", "40"});
  ASSERT_EQ(b.exit_code, 0) << describe(b);
  EXPECT_TRUE(contains(b.out, "device vulkan")) << describe(b);
  EXPECT_TRUE(contains(b.out, "not bitwise")) << describe(b);
  EXPECT_TRUE(contains(b.out, "100 of 100 (resumed at step 60)")) << describe(b);
}

// Truncated, bit-flipped, other-version and wrong-scene checkpoints: exit code 2, a message with
// the file and the reason, and not one file of the output changed or added.
TEST(CliCheckpoint, RefusalsNameTheReasonAndWriteNothing) {
  TempDir tmp;
  const std::string scene = tmp / "scene.json";
  fs::copy_file(kMixedScene, scene);
  const std::string out = tmp / "out";
  const Outcome a = run_motes(tmp, {"run", scene, "--backend", "openmp", "--steps", "100",
                                    "--every", "20", "--out", out, "--checkpoint-every", "50"});
  ASSERT_EQ(a.exit_code, 0) << describe(a);
  const std::string good = out + "/checkpoints/checkpoint-000000000100.mck";
  const std::string text = read_text(good);
  const auto write = [&](const std::string& name, const std::string& bytes) {
    const std::string path = tmp / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  };
  std::string flipped = text;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x04);
  std::string version = text;
  version[8] = 7;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {write("truncated.mck", text.substr(0, text.size() - 100)), "truncated checkpoint"},
      {write("flipped.mck", flipped), "checksum mismatch"},
      {write("version.mck", version), "checkpoint format version 7"},
      {write("foreign.mck", "not a checkpoint at all"), "not a motes checkpoint"},
      {tmp / "missing.mck", "cannot open"},
  };
  const auto before = stamps_of(out);
  for (const auto& [path, reason] : cases) {
    const Outcome o = run_motes(tmp, {"resume", path});
    EXPECT_EQ(o.exit_code, 2) << describe(o);
    EXPECT_TRUE(contains(o.err, "motes: error: " + path)) << describe(o);
    EXPECT_TRUE(contains(o.err, reason)) << describe(o);
    EXPECT_TRUE(stamps_of(out) == before) << "the output changed: " << path;
  }
  // The scene edited after the checkpoint (one more space): refused by its hash.
  std::ofstream(scene, std::ios::app) << " ";
  const Outcome o = run_motes(tmp, {"resume", good});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err, good)) << describe(o);
  EXPECT_TRUE(contains(o.err, "scene file '" + fs::absolute(scene).lexically_normal().string() +
                                  "' has changed since the checkpoint was written"))
      << describe(o);
  EXPECT_TRUE(stamps_of(out) == before) << "the output changed";
  // Another scene under the same name (the file replaced): refused the same way.
  fs::copy_file(std::string(MOTES_TEST_DATA_DIR) + "/cli/small.json", scene,
                fs::copy_options::overwrite_existing);
  const Outcome other = run_motes(tmp, {"resume", good});
  EXPECT_EQ(other.exit_code, 2) << describe(other);
  EXPECT_TRUE(contains(other.err, "has changed")) << describe(other);
  EXPECT_TRUE(stamps_of(out) == before) << "the output changed";
}

TEST(CliCheckpoint, UsageErrors) {
  TempDir tmp;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"run", kMixedScene, "--checkpoint-every", "0"},
        std::vector<std::string>{"run", kMixedScene, "--checkpoint-every", "-5"},
        std::vector<std::string>{"run", kMixedScene, "--checkpoint-every", "2.5"},
        std::vector<std::string>{"resume", "x.mck", "--steps", "-1"},
        std::vector<std::string>{"resume", "x.mck", "--checkpoint-every", "0"}}) {
    const Outcome o = run_motes(tmp, args);
    EXPECT_GE(o.exit_code, 100) << describe(o);
    EXPECT_TRUE(contains(o.err, "is not a whole number >=")) << describe(o);
  }
  const Outcome none = run_motes(tmp, {"resume"});
  EXPECT_GE(none.exit_code, 100) << describe(none);
  const Outcome both = run_motes(tmp, {"resume", "x.mck", "--steps", "5", "--duration", "1"});
  EXPECT_GE(both.exit_code, 100) << describe(both);
}

// SIGTERM and SIGINT during motes run: the frames so far stay, a last checkpoint is written, the
// message names it and how to go on, the exit code is 128 + the signal; the checkpoint resumes.
TEST(CliCheckpoint, SigtermAndSigintLeaveALastCheckpoint) {
  for (const int sig : {SIGTERM, SIGINT}) {
    SCOPED_TRACE(sig);
    TempDir tmp;
    const std::string out = tmp / "out";
    const pid_t pid = spawn_motes({"run", kMixedScene, "--backend", "openmp", "--threads", "1",
                                   "--steps", "100000000", "--every", "50", "--out", out},
                                  tmp / "stdout.txt", tmp / "stderr.txt");
    ASSERT_GT(pid, 0);
    // Until three frames are listed (at most 60 s).
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline &&
           !contains(read_text(fs::path(out) / "particles.pvd"), "particles_000002.vtu")) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ASSERT_EQ(kill(pid, sig), 0);
    const int code = wait_for(pid);
    Outcome o;
    o.exit_code = code;
    o.out = read_text(tmp / "stdout.txt");
    o.err = read_text(tmp / "stderr.txt");
    EXPECT_EQ(code, 128 + sig) << describe(o);
    EXPECT_TRUE(
        contains(o.err, sig == SIGTERM ? "interrupted by SIGTERM" : "interrupted by SIGINT"))
        << describe(o);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(o.err, m, std::regex(R"(motes resume (\S+\.mck))")))
        << describe(o);
    const std::string checkpoint = m[1];
    EXPECT_TRUE(fs::exists(checkpoint)) << checkpoint;
    EXPECT_EQ(fs::path(checkpoint).parent_path(), fs::path(out) / "checkpoints");
    auto info = motes::read_checkpoint_info(checkpoint);
    ASSERT_TRUE(info) << info.message();
    EXPECT_TRUE(contains(o.out, fmt::format("steps           {} of 100000000", info->step)))
        << describe(o);
    const std::size_t frames = info->run.series.frame_times.size();
    EXPECT_GE(frames, 3u);
    EXPECT_TRUE(contains(read_text(fs::path(out) / "particles.pvd"),
                         fmt::format("particles_{:06}.vtu", frames - 1)));
    // It goes on from there, numbering frames after the ones written.
    const Outcome r = run_motes(tmp, {"resume", checkpoint, "--steps", "120"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_TRUE(contains(read_text(fs::path(out) / "particles.pvd"),
                         fmt::format("particles_{:06}.vtu", frames + 1)));
  }
}

// SIGKILL at random moments of a run that writes a checkpoint every step (2 MB each): whenever the
// kill came while a checkpoint was being written (its .tmp file is left), the newest complete
// checkpoint still loads and resumes.
TEST(CliCheckpoint, SigkillWhileWritingLeavesTheLastCheckpointUsable) {
  TempDir tmp;
  // One rigid block of 24^3 particles falling onto a floor: checkpoints of about 2 MB.
  const std::string scene = tmp / "block.json";
  std::ofstream(scene) << R"({
    "settings": {"dt": 5e-5, "particle_diameter": 0.01,
                 "contact": {"stiffness": 2000, "damping": 200}},
    "planes": [{"name": "floor", "normal": [0, 1, 0], "point": [0, 0, 0]}],
    "bodies": [{"name": "block", "shape": {"type": "box", "particles": [24, 24, 24]},
                "position": [0, 0.13, 0]}]
  })";
  auto loaded = motes::load_scene_file(scene);
  ASSERT_TRUE(loaded) << loaded.message();
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int> wait_ms(300, 1500);
  int mid_write = 0;
  int attempts = 0;
  fs::path newest;
  while (mid_write < 3 && attempts < 15) {
    ++attempts;
    const fs::path out = tmp.path() / ("out" + std::to_string(attempts));
    const pid_t pid =
        spawn_motes({"run", scene, "--backend", "openmp", "--threads", "1", "--steps", "1000000",
                     "--format", "none", "--out", out.string(), "--checkpoint-every", "1"},
                    tmp / "stdout.txt", tmp / "stderr.txt");
    ASSERT_GT(pid, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(wait_ms(rng)));
    ASSERT_EQ(kill(pid, SIGKILL), 0);
    ASSERT_EQ(wait_for(pid), 1000 + SIGKILL);
    bool tmp_left = false;
    const auto cks = checkpoints_in(out / "checkpoints", &tmp_left);
    if (cks.empty()) continue;  // killed before the first
    EXPECT_LE(cks.size(), 3u);  // the last two, and a third between its rename and the pruning
    if (tmp_left) ++mid_write;
    newest = cks.rbegin()->second;
    auto info = motes::read_checkpoint_info(newest.string());
    ASSERT_TRUE(info) << newest << ": " << info.message();
    EXPECT_EQ(info->step, cks.rbegin()->first);
    auto sim = motes::Simulation::create(loaded.value(), motes::open_device("openmp").value());
    ASSERT_TRUE(sim);
    ASSERT_TRUE(sim.value()->load_state(newest.string())) << newest;
  }
  std::printf("[checkpoint] %d kills, %d of them while a checkpoint was being written\n", attempts,
              mid_write);
  EXPECT_GE(mid_write, 1) << "no kill came while a checkpoint was being written";
  ASSERT_FALSE(newest.empty());
  const Outcome r = run_motes(tmp, {"resume", newest.string(), "--steps", "3"});
  EXPECT_EQ(r.exit_code, 0) << describe(r);
}

}  // namespace
