// The motes command, run as a user would: exit codes, messages and the files it writes.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "sanitized_build.h"
#include "unit/cli_support.h"
#include "unit/test_support.h"

namespace fs = std::filesystem;

namespace {

const std::string kSmallScene = std::string(MOTES_TEST_DATA_DIR) + "/cli/small.json";
const std::string kBunny = std::string(MOTES_SOURCE_DIR) + "/examples/assets/bunny.obj";

using motes_test::TempDir;

using motes_test::contains;
using motes_test::describe;
using motes_test::Outcome;
using motes_test::quote;
using motes_test::read_text;
using motes_test::run_motes;

std::vector<std::string> files_with_extension(const fs::path& dir, const std::string& ext) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ext) names.push_back(e.path().filename().string());
  }
  return names;
}

std::vector<std::string> lines_of(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(Cli, DevicesListsOpenmp) {
  TempDir tmp;
  const Outcome o = run_motes(tmp, {"devices"});
  EXPECT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_TRUE(std::regex_search(o.out, std::regex(R"(^openmp +0 +\S)", std::regex::multiline)))
      << describe(o);
  // Every backend appears, with its devices or the reason it has none.
  for (const char* backend : {"cuda", "vulkan"}) {
    EXPECT_TRUE(contains(o.out, backend)) << describe(o);
  }
}

// The CUDA backend through the command line: runs where there is a CUDA GPU (the GPU machine);
// elsewhere `--backend cuda` must fail with the reason, and the run itself is reported skipped.
TEST(Cli, RunOnCuda) {
  TempDir tmp;
  const std::string out = tmp / "out";
  const Outcome o = run_motes(tmp, {"run", kSmallScene, "--backend", "cuda", "--steps", "20",
                                    "--every", "10", "--out", out});
  for (const motes::BackendReport& r : motes::list_backends()) {
    if (r.backend != "cuda" || !r.devices.empty()) continue;
    EXPECT_NE(o.exit_code, 0) << describe(o);
    EXPECT_TRUE(contains(o.err, "cuda")) << describe(o);
    EXPECT_TRUE(contains(o.err, r.unavailable_reason)) << describe(o);
    GTEST_SKIP() << "no CUDA device: " << r.unavailable_reason;
  }
  EXPECT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(out) / "particles.pvd")) << describe(o);
}

TEST(Cli, VersionAndUsage) {
  TempDir tmp;
  const Outcome v = run_motes(tmp, {"--version"});
  EXPECT_EQ(v.exit_code, 0) << describe(v);
  EXPECT_TRUE(contains(v.out, "motes ")) << describe(v);
  const Outcome none = run_motes(tmp, {});
  EXPECT_NE(none.exit_code, 0) << describe(none);
  const Outcome both = run_motes(tmp, {"run", kSmallScene, "--steps", "5", "--duration", "1"});
  EXPECT_NE(both.exit_code, 0) << describe(both);
  EXPECT_NE(both.exit_code, 2) << "usage errors keep CLI11's exit codes\n" << describe(both);
  EXPECT_TRUE(contains(both.err, "--duration")) << describe(both);
  const Outcome every = run_motes(tmp, {"run", kSmallScene, "--every", "0"});
  EXPECT_NE(every.exit_code, 0) << describe(every);
  const Outcome nan = run_motes(tmp, {"run", kSmallScene, "--duration", "nan"});
  EXPECT_NE(nan.exit_code, 0) << describe(nan);
  EXPECT_TRUE(contains(nan.err, "finite")) << describe(nan);
}

TEST(Cli, NegativeCountsAreUsageErrors) {
  // CLI11 alone wraps "-5" around to 18446744073709551611 steps, or prints a range up to the
  // largest double: every count option says plainly what it wants instead.
  TempDir tmp;
  const std::vector<std::vector<std::string>> cases = {
      {"run", kSmallScene, "--steps", "-5"},   {"run", kSmallScene, "--every", "-5"},
      {"run", kSmallScene, "--every", "2.5"},  {"run", kSmallScene, "--device", "-1"},
      {"run", kSmallScene, "--threads", "-2"}, {"voxelize", "mesh.obj", "--count", "-5"},
      {"bench", "--falling-steps", "-5"},      {"bench", "--sizes", "16384,-5"},
      {"bench", "--cloth-sides", "1"},         {"render-bench", "--frames", "-3"},
  };
  for (const std::vector<std::string>& args : cases) {
    const Outcome o = run_motes(tmp, args);
    EXPECT_NE(o.exit_code, 0) << describe(o);
    EXPECT_NE(o.exit_code, 2) << "usage errors keep CLI11's exit codes\n" << describe(o);
    EXPECT_TRUE(contains(o.err, "is not a whole number ")) << describe(o);
    EXPECT_FALSE(contains(o.err, "18446744073709551")) << describe(o);
    EXPECT_FALSE(contains(o.err, "179769313486231570")) << describe(o);
  }
}

TEST(Cli, HugeNonNumericAndOutOfRangeValuesAreUsageErrors) {
  // Beyond the option's type CLI11 says only "Could not convert"; beyond a real limit
  // (threads, dominoes) the command used to build the workload until memory ran out. Every
  // numeric option names its range instead, before anything runs.
  TempDir tmp;
  const std::string huge = "99999999999";
  const std::string beyond_64_bits = "18446744073709551616";
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{"run", kSmallScene, "--threads", huge}, "'99999999999' is too large: at most 1024"},
      {{"run", kSmallScene, "--threads", "1025"}, "at most 1024"},
      {{"run", kSmallScene, "--device", huge}, "is too large: at most 2147483647"},
      {{"run", kSmallScene, "--steps", beyond_64_bits},
       "is too large: at most 18446744073709551615"},
      {{"run", kSmallScene, "--every", "nan"}, "'nan' is not a whole number >= 1"},
      {{"run", kSmallScene, "--duration", "1e400"}, "must be a finite number >= 0"},
      {{"run", kSmallScene, "--fps", "1e300"}, "must be a finite number from 0.01 to 1000"},
      {{"run", kSmallScene, "--fps", "1e-300"}, "must be a finite number from 0.01 to 1000"},
      {{"run", kSmallScene, "--size", "99999999999x5"},
       "invalid size '99999999999x5': width and height must be 16 to 16384 pixels"},
      {{"voxelize", kBunny, "--count", beyond_64_bits}, "is too large: at most 100000000"},
      {{"bench", "--threads", huge}, "at most 1024"},
      {{"bench", "--dominoes", huge}, "is too large: at most 6666666"},
      {{"bench", "--dominoes", "10", "--domino-rows", "2147483647"}, "is too large"},
      {{"bench", "--dominoes", "10", "--domino-rows", "11", "--workload", "dominoes"},
       "11 rows for 10 dominoes: at most one row per domino"},
      {{"bench", "--soft-counts", "1," + huge}, "is too large: at most 100000"},
      {{"bench", "--cloth-sides", "2000"}, "'2000' is too large: at most 1024"},
      {{"bench", "--repeats", "nan"}, "'nan' is not a whole number from 1 to 1000"},
      {{"render-bench", "--particles", "-5"}, "'-5' is not a whole number from 1 to 100000000"},
      {{"render-bench", "--frames", huge}, "is too large: at most 1000"},
  };
  for (const Case& c : cases) {
    const Outcome o = run_motes(tmp, c.args);
    EXPECT_NE(o.exit_code, 0) << describe(o);
    EXPECT_NE(o.exit_code, 2) << "usage errors keep CLI11's exit codes\n" << describe(o);
    EXPECT_TRUE(contains(o.err, c.says)) << "expected \"" << c.says << "\"\n" << describe(o);
    EXPECT_FALSE(contains(o.err, "Could not convert")) << describe(o);
    EXPECT_FALSE(contains(o.err, ") AND (")) << describe(o);
    EXPECT_TRUE(o.out.empty()) << describe(o);
  }
}

TEST(Cli, VoxelizeOutsideTheFloatRangeSaysSo) {
  // Particles are 32-bit floats: a scale or diameter beyond them used to give NaN mass
  // properties (--diameter 1e300), a mesh "flat" by overflow or underflow (--scale 1e300,
  // 1e-300) or a lattice size of 300 digits (--diameter 1e-300).
  TempDir tmp;
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--diameter", "1e300"}, "particle diameter 1e+300 m is outside the range of 32-bit floats"},
      {{"--diameter", "1e-300"}, "particle diameter 1e-300 m gives a lattice of 9.91e+300 x "},
      {{"--count", "100", "--scale", "1e300"},
       "vertex 0 has a coordinate of 2.81e+300 m, outside the range of particle positions"},
      {{"--count", "100", "--scale", "1e-300"}, "the mesh is 9.91e-300 m across, too small"},
  };
  for (const auto& [extra, says] : cases) {
    std::vector<std::string> args = {"voxelize", kBunny};
    args.insert(args.end(), extra.begin(), extra.end());
    const Outcome o = run_motes(tmp, args);
    EXPECT_EQ(o.exit_code, 2) << describe(o);
    EXPECT_TRUE(contains(o.err, "motes: error: " + kBunny + ": " + says))
        << "expected \"" << says << "\"\n"
        << describe(o);
    EXPECT_FALSE(contains(o.out, "nan")) << describe(o);
  }
}

/// The index of lavapipe among the Vulkan devices, or -1.
int lavapipe_index() {
  for (const motes::BackendReport& r : motes::list_backends()) {
    if (r.backend != "vulkan") continue;
    for (const motes::DeviceInfo& d : r.devices) {
      if (contains(d.name, "llvmpipe")) return d.index;
    }
  }
  return -1;
}

// Device limits (docs/reliability.md): `motes run` refuses what does not fit on the device through
// the check of Simulation::create, before allocating, with both numbers and the largest particle
// count that fits. Lavapipe's maxStorageBufferRange (128 MiB) makes it cheap: a neighbour list of
// 160,000 x 1,024 entries, whose four column blocks need 160 MB each. (`motes bench` goes through
// the same check; since the list splits, no workload reaches a buffer's limit on lavapipe before
// its scene takes gigabytes of host memory, and bench's refusals are tested with host memory:
// Cli.BenchRefusesAW1SizeBeyondHostMemory.)
TEST(Cli, RunRefusesWhatDoesNotFitOnTheDevice) {
  const int lavapipe = lavapipe_index();
  if (lavapipe < 0) GTEST_SKIP() << "needs lavapipe, whose maxStorageBufferRange is 128 MiB";
  TempDir tmp;
  const std::string scene = std::string(MOTES_TEST_DATA_DIR) + "/cli/big_neighbour_list.json";
  const std::string out = tmp / "out";
  const Outcome run = run_motes(tmp, {"run", scene, "--backend", "vulkan", "--device",
                                      std::to_string(lavapipe), "--steps", "1", "--out", out});
  EXPECT_EQ(run.exit_code, 2) << describe(run);
  EXPECT_TRUE(contains(run.err, "motes: error: " + scene +
                                    ": 160000 particles do not fit on vulkan device " +
                                    std::to_string(lavapipe)))
      << describe(run);
  EXPECT_TRUE(contains(run.err,
                       "buffer NeighbourList would need 163840000 bytes, more than the "
                       "134217728 bytes one buffer may hold there (maxStorageBufferRange); at "
                       "most 131072 particles fit"))
      << describe(run);
  EXPECT_FALSE(fs::exists(out)) << "output written for a refused run";
}

TEST(Cli, RunWritesVtuFramesAndSeries) {
  TempDir tmp;
  const std::string out = tmp / "out";
  const Outcome o =
      run_motes(tmp, {"run", kSmallScene, "--steps", "20", "--every", "10", "--out", out});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  std::vector<std::string> vtus = files_with_extension(out, ".vtu");
  std::sort(vtus.begin(), vtus.end());
  EXPECT_EQ(vtus, (std::vector<std::string>{"bodies_000000.vtu", "bodies_000001.vtu",
                                            "bodies_000002.vtu", "particles_000000.vtu",
                                            "particles_000001.vtu", "particles_000002.vtu"}));
  const std::string pvd = read_text(fs::path(out) / "particles.pvd");
  const std::string bodies_pvd = read_text(fs::path(out) / "bodies.pvd");
  for (const std::string& name : vtus) {
    EXPECT_TRUE(contains(name.starts_with("bodies") ? bodies_pvd : pvd, name)) << name;
  }
  // The summary says what ran and where the frames are.
  for (const char* word : {"openmp", "particles", "steps/s", "particle-steps/s", "particles.pvd"}) {
    EXPECT_TRUE(contains(o.out, word)) << word << "\n" << describe(o);
  }
  EXPECT_TRUE(std::regex_search(o.out, std::regex(R"(steps +20 of 20)"))) << describe(o);
}

TEST(Cli, RunWritesCsvWithThreeFrames) {
  TempDir tmp;
  const std::string out = tmp / "csv";
  const Outcome o = run_motes(tmp, {"run", kSmallScene, "--steps", "20", "--every", "10", "--out",
                                    out, "--format", "csv", "--threads", "1"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  const std::vector<std::string> lines = lines_of(fs::path(out) / "particles.csv");
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0], "frame,time,particle,body,x,y,z,vx,vy,vz");
  std::map<int, int> rows_per_frame;
  std::set<std::string> times;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::vector<std::string> fields;
    std::stringstream ss(lines[i]);
    for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
    ASSERT_EQ(fields.size(), 10u) << lines[i];
    ++rows_per_frame[std::stoi(fields[0])];
    times.insert(fields[1]);
  }
  ASSERT_EQ(rows_per_frame.size(), 3u);
  EXPECT_GT(rows_per_frame[0], 0);
  EXPECT_EQ(rows_per_frame[1], rows_per_frame[0]);
  EXPECT_EQ(rows_per_frame[2], rows_per_frame[0]);
  EXPECT_EQ(times.size(), 3u);
  EXPECT_TRUE(times.count("0")) << "frame 0 is the initial state";
}

TEST(Cli, RunWritesBodyTableThatMatchesTheSimulation) {
  // The last frame of bodies.csv is the bodies' state after the run, exactly: the same scene
  // stepped in this process on the same backend gives the same floats.
  TempDir tmp;
  const std::string out = tmp / "bodies";
  const Outcome o = run_motes(tmp, {"run", kSmallScene, "--steps", "30", "--every", "10", "--out",
                                    out, "--format", "csv", "--backend", "openmp"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  const std::vector<std::string> lines = lines_of(fs::path(out) / "bodies.csv");
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0], "frame,time,body,name,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz");

  auto scene = motes::load_scene_file(kSmallScene);
  ASSERT_TRUE(scene) << scene.message();
  auto device = motes::open_device("openmp");
  ASSERT_TRUE(device) << device.message();
  auto sim = motes::Simulation::create(scene.value(), std::move(device).value());
  ASSERT_TRUE(sim) << sim.message();
  ASSERT_TRUE(sim.value()->step(30));
  auto snap = sim.value()->snapshot();
  ASSERT_TRUE(snap) << snap.message();
  const std::size_t bodies = snap->body_pos.size();
  ASSERT_GT(bodies, 0u);
  ASSERT_EQ(lines.size(), 1 + 4 * bodies) << "a row per body for frames 0, 10, 20 and 30 steps";
  for (std::size_t b = 0; b < bodies; ++b) {
    std::vector<std::string> f;
    std::stringstream ss(lines[1 + 3 * bodies + b]);
    for (std::string field; std::getline(ss, field, ',');) f.push_back(field);
    ASSERT_EQ(f.size(), 17u) << lines[1 + 3 * bodies + b];
    EXPECT_EQ(f[0], "3");
    EXPECT_EQ(std::stoul(f[2]), b);
    EXPECT_EQ(f[3], sim.value()->bodies()[b].name);
    const motes::shared::vec4 x = snap->body_pos[b], q = snap->body_quat[b];
    const motes::shared::vec4 v = snap->body_vel[b], w = snap->body_angvel[b];
    const float want[13] = {x.x, x.y, x.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z};
    for (int k = 0; k < 13; ++k) {
      EXPECT_EQ(std::strtof(f[4 + static_cast<std::size_t>(k)].c_str(), nullptr), want[k])
          << "body " << b << " column " << 4 + k;
    }
  }
}

TEST(Cli, RunWithoutSceneUsesTheBuiltInScene) {
  TempDir tmp;
  const Outcome o = run_motes(tmp, {"run", "--steps", "2", "--format", "none"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_TRUE(contains(o.out, "built-in")) << describe(o);
  EXPECT_FALSE(fs::exists(tmp / "out"));
}

TEST(Cli, MalformedSceneNamesFileAndJsonPath) {
  TempDir tmp;
  const std::string bad = tmp / "bad_scene.json";
  std::string text = read_text(kSmallScene);
  // The same scene with one unknown key in settings.
  const auto at = text.find("\"settings\": {");
  ASSERT_NE(at, std::string::npos) << "small.json must have a settings object";
  text.insert(at + 13, "\"time_step_typo\": 1, ");
  std::ofstream(bad) << text;
  const Outcome o = run_motes(tmp, {"run", bad, "--steps", "1", "--out", tmp / "out"});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err, "motes: error: ")) << describe(o);
  EXPECT_TRUE(contains(o.err, bad)) << describe(o);
  EXPECT_TRUE(contains(o.err, "/settings")) << describe(o);
  EXPECT_TRUE(contains(o.err, "time_step_typo")) << describe(o);
}

TEST(Cli, NonFiniteStateEndsTheRunWithAnError) {
  TempDir tmp;
  // A body at the edge of the float range under a gravity of 3e38 m/s^2 (a body thrown at 1e38
  // m/s is refused by the loader, docs/reliability.md): its position would overflow to infinity
  // within about 80 steps, but already at the frame of step 10 its speed (1.5e35 m/s) gives a
  // kinetic energy beyond the float range, and the energy guard stops the run there.
  const std::string scene = tmp / "overflow.json";
  std::ofstream(scene) << R"({
    "settings": {"dt": 5e-5, "particle_diameter": 0.01, "gravity": [3e38, 0, 0],
                 "contact": {"stiffness": 500, "damping": 50}},
    "bodies": [{"shape": {"type": "box", "particles": [2, 2, 2]},
                "position": [3.4028e38, 0, 0]}]
  })";
  const std::string out = tmp / "out";
  const Outcome o = run_motes(
      tmp, {"run", scene, "--steps", "200", "--every", "10", "--out", out, "--threads", "1"});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err, "motes: error: ")) << describe(o);
  EXPECT_TRUE(contains(o.err, "energy out of bounds at step 10")) << describe(o);
  EXPECT_TRUE(contains(o.err, "inf")) << describe(o);
  // The frames before the stop are complete and listed.
  const std::string pvd = read_text(fs::path(out) / "particles.pvd");
  EXPECT_TRUE(contains(pvd, "particles_000000.vtu")) << pvd;
  EXPECT_FALSE(contains(pvd, "particles_000001.vtu")) << pvd;
}

TEST(Cli, MissingFilesAreClearErrors) {
  TempDir tmp;
  const std::string missing = tmp / "no_such_scene.json";
  const Outcome o = run_motes(tmp, {"run", missing});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err, "motes: error: ")) << describe(o);
  EXPECT_TRUE(contains(o.err, missing)) << describe(o);

  const std::string mesh = tmp / "no_such_mesh.obj";
  const Outcome v = run_motes(tmp, {"voxelize", mesh, "--count", "100"});
  EXPECT_EQ(v.exit_code, 2) << describe(v);
  EXPECT_TRUE(contains(v.err, mesh)) << describe(v);
}

TEST(Cli, UnwritableOutputAndUnknownBackendAreErrors) {
  TempDir tmp;
  std::ofstream(tmp / "file") << "x";
  const std::string out = tmp / "file/out";  // a regular file where a directory should be
  const Outcome o = run_motes(tmp, {"run", kSmallScene, "--steps", "1", "--out", out});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err, out)) << describe(o);

  const Outcome b = run_motes(tmp, {"run", kSmallScene, "--backend", "metal"});
  EXPECT_NE(b.exit_code, 0) << describe(b);
  const Outcome d = run_motes(tmp, {"run", kSmallScene, "--backend", "openmp", "--device", "7"});
  EXPECT_EQ(d.exit_code, 2) << describe(d);
  EXPECT_TRUE(contains(d.err, "motes: error: ")) << describe(d);
}

TEST(Cli, VoxelizeBunnyToCsv) {
  TempDir tmp;
  const std::string csv = tmp / "x.csv";
  const Outcome o = run_motes(tmp, {"voxelize", kBunny, "--count", "1000", "--out", csv});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.out, m, std::regex(R"(particles +(\d+))"))) << describe(o);
  const int count = std::stoi(m[1]);
  EXPECT_GT(count, 800) << describe(o);
  EXPECT_LT(count, 1200) << describe(o);
  EXPECT_TRUE(contains(o.out, "density 1000")) << describe(o);
  const std::vector<std::string> lines = lines_of(csv);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0], "x,y,z");
  EXPECT_EQ(static_cast<int>(lines.size()) - 1, count);

  const std::string vtu = tmp / "x.vtu";
  const Outcome w = run_motes(tmp, {"voxelize", kBunny, "--count", "1000", "--out", vtu});
  ASSERT_EQ(w.exit_code, 0) << describe(w);
  EXPECT_TRUE(contains(read_text(vtu), "NumberOfPoints=\"" + std::to_string(count) + "\""));

  const Outcome neither = run_motes(tmp, {"voxelize", kBunny});
  EXPECT_NE(neither.exit_code, 0) << describe(neither);
  const Outcome both = run_motes(tmp, {"voxelize", kBunny, "--count", "10", "--diameter", "0.1"});
  EXPECT_NE(both.exit_code, 0) << describe(both);
}

}  // namespace

namespace {

TEST(Cli, BenchRealtimeStepsScenesInFrames) {
  // Every .json of a folder, in name order, in frames of 1/60 s: small.json's dt of 50 us makes
  // 333 steps a frame, and 0.05 s three frames.
  TempDir tmp;
  const fs::path scenes = tmp / "scenes";
  fs::create_directories(scenes);
  fs::copy_file(kSmallScene, scenes / "b.json");
  fs::copy_file(kSmallScene, scenes / "a.json");
  std::ofstream(scenes / "notes.txt") << "not a scene\n";
  const std::string json = tmp / "rt.json";
  const Outcome o = run_motes(
      tmp, {"bench", "--workload", "realtime", "--scenes", scenes.string(), "--realtime-seconds",
            "0.05", "--repeats", "2", "--backend", "openmp", "--threads", "1", "--json", json});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_TRUE(std::regex_search(o.out, std::regex(R"(\na +force +108 .*\nb +force +108 )")))
      << describe(o);
  const nlohmann::json r = nlohmann::json::parse(read_text(json));
  ASSERT_EQ(r.size(), 2u);
  for (const nlohmann::json& row : r) {
    EXPECT_EQ(row["workload"], "realtime");
    EXPECT_EQ(row["steps_per_frame"], 333);
    EXPECT_EQ(row["frames"], 3);
    EXPECT_NEAR(row["simulated_seconds"].get<double>(), 3 * 333 * 5e-5, 1e-12);
    ASSERT_EQ(row["seconds"].size(), 2u);
    for (const auto& s : row["seconds"]) EXPECT_GT(s.get<double>(), 0.0);
    EXPECT_GT(row["realtime_factor_median"].get<double>(), 0.0);
  }
  EXPECT_TRUE(contains(r[0]["scene"].get<std::string>(), "a.json"));
}

TEST(Cli, BenchRealtimeNamesScenesItCannotRun) {
  TempDir tmp;
  const Outcome missing = run_motes(
      tmp, {"bench", "--workload", "realtime", "--scenes", tmp / "nowhere", "--backend", "openmp"});
  EXPECT_EQ(missing.exit_code, 2) << describe(missing);
  EXPECT_TRUE(contains(missing.err, "nowhere is neither a scene file nor a folder of them"))
      << describe(missing);
  fs::create_directories(tmp / "empty");
  const Outcome empty = run_motes(
      tmp, {"bench", "--workload", "realtime", "--scenes", tmp / "empty", "--backend", "openmp"});
  EXPECT_EQ(empty.exit_code, 2) << describe(empty);
  EXPECT_TRUE(contains(empty.err, "holds no .json scene file")) << describe(empty);
}

// The W1 dense phase starts from a checkpoint of the settle, which carries the settle's list
// builds (NeighbourStats::builds goes on counting across a resume); the "builds" column is the
// timed repeat's own. 1,000 steps from the lattice rebuild the lists at least three times (the
// first at step 1, then each 0.45 mm of free fall): the falling phase's repeat reports them, and
// one dense step after a 1,000-step settle reports at most one.
TEST(Cli, BenchDenseBuildsCountOnlyTheTimedSteps) {
  TempDir tmp;
  const std::filesystem::path json = tmp / "bench.json";
  const Outcome o = run_motes(
      tmp, {"bench",       "--workload",     "settle", "--phase",         "both", "--sizes",
            "16384",       "--backend",      "openmp", "--falling-steps", "1000", "--dense-steps",
            "1",           "--settle-steps", "1000",   "--repeats",       "1",    "--cache",
            tmp / "cache", "--json",         json});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.is_array() && j.size() == 2u) << j.dump(2);
  for (const nlohmann::json& r : j) {
    if (r["phase"] == "falling") {
      EXPECT_GE(r["neighbour_builds"].get<int>(), 3) << r.dump(2);
    } else {
      EXPECT_EQ(r["phase"], "dense");
      EXPECT_LE(r["neighbour_builds"].get<int>(), 1) << r.dump(2);
    }
  }
}

// --skin sets W1's neighbour-list skin in the timed runs (issue 30: what a larger skin gives the
// dense pile): a 3 mm skin rebuilds the falling spheres' lists less often than the default 1 mm,
// the dense phase starts from the pile settled with the default (the checkpoint of that scene,
// its state written into the other), and a skin of zero, beyond a diameter or not a number is
// refused by name.
TEST(Cli, BenchSkinSetsW1sListSkin) {
  TempDir tmp;
  std::vector<nlohmann::json> rows;
  for (const char* skin : {"", "0.003"}) {
    const std::filesystem::path json = tmp / fmt::format("bench{}.json", skin);
    std::vector<std::string> args = {
        "bench",       "--workload",     "settle", "--phase",         "both", "--sizes",
        "16384",       "--backend",      "openmp", "--falling-steps", "1000", "--dense-steps",
        "50",          "--settle-steps", "1000",   "--repeats",       "1",    "--cache",
        tmp / "cache", "--json",         json};
    if (*skin != '\0') args.insert(args.end(), {"--skin", skin});
    const Outcome o = run_motes(tmp, args);
    ASSERT_EQ(o.exit_code, 0) << describe(o);
    std::ifstream in(json);
    const nlohmann::json j = nlohmann::json::parse(in);
    ASSERT_TRUE(j.is_array() && j.size() == 2u) << j.dump(2);
    EXPECT_EQ(j[1]["phase"], "dense") << j.dump(2);
    for (const nlohmann::json& r : j) {
      const std::string want = fmt::format("skin {} m", *skin == '\0' ? "0.001" : skin);
      EXPECT_TRUE(contains(r["neighbour_search"].get<std::string>(), want)) << r.dump(2);
    }
    rows.push_back(j[0]);
  }
  EXPECT_LT(rows[1]["neighbour_builds"].get<int>(), rows[0]["neighbour_builds"].get<int>())
      << rows[0].dump(2) << rows[1].dump(2);
  for (const char* bad : {"0.5", "nan", "0"}) {
    const Outcome refused = run_motes(tmp, {"bench", "--workload", "settle", "--skin", bad});
    EXPECT_NE(refused.exit_code, 0) << describe(refused);
    EXPECT_TRUE(contains(refused.err, "--skin")) << describe(refused);
  }
}

// The host memory W1 takes stays within the estimate bench refuses sizes by (cmd_bench.cpp:
// kW1HostBytesPerSphere, 420 B a sphere, and for the openmp device its buffers, 196 B a sphere in
// the falling phase), with 160 MiB for the program itself: at 4,194,304 spheres 2.50 GB
// (2026-12-01), against 2.75 GB here. A copy of the scene (about 280 B a sphere) once took it
// to 3.64 GB, and on the GPU machine W1 at 268,435,456 spheres past the machine's memory: killed,
// not refused.
TEST(Cli, BenchW1HostMemoryStaysWithinItsEstimate) {
  // AddressSanitizer's shadow memory is not the program's: the sanitizer stage runs the same
  // path at 262,144 spheres for memory errors and leaves the peak to the first stage.
  constexpr std::uint64_t kSpheres = motes_test::sanitized_or<std::uint64_t>(4194304, 262144);
  constexpr bool kCheckPeak = !motes_test::kSanitized;
  TempDir tmp;
  const Outcome o = run_motes(tmp, {"bench", "--workload", "settle", "--phase", "falling",
                                    "--sizes", std::to_string(kSpheres), "--backend", "openmp",
                                    "--threads", "1", "--falling-steps", "1", "--repeats", "1"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  if (!kCheckPeak) return;
  rusage usage{};
  ASSERT_EQ(getrusage(RUSAGE_CHILDREN, &usage), 0);
  const auto peak = static_cast<std::uint64_t>(usage.ru_maxrss) * 1024u;  // ru_maxrss: KiB
  const std::uint64_t limit = kSpheres * (420u + 196u) + (160u << 20u);
  EXPECT_LE(peak, limit) << "peak RSS " << peak << " B, " << peak / kSpheres << " B a sphere";
}

// W1 at 268,435,456 spheres is a size (issue 30), but building its scene takes about 420 B of host
// memory a sphere (880 B with the openmp device's): where MemAvailable is short of that, bench
// refuses it before building anything, names both numbers and runs the other sizes.
TEST(Cli, BenchRefusesAW1SizeBeyondHostMemory) {
  std::ifstream meminfo("/proc/meminfo");
  std::string key, unit;
  std::uint64_t kib = 0, available = 0;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") available = kib * 1024u;
  }
  if (available == 0) GTEST_SKIP() << "no MemAvailable in /proc/meminfo";
  constexpr std::uint64_t kSpheres = 268435456;
  if (available >= kSpheres * 880u) {
    GTEST_SKIP() << "this machine has room for W1 at 268,435,456 on openmp: it would run it";
  }
  TempDir tmp;
  const Outcome o = run_motes(
      tmp, {"bench", "--workload", "settle", "--phase", "both", "--sizes", "16384,268435456",
            "--backend", "openmp", "--falling-steps", "2", "--dense-steps", "2", "--settle-steps",
            "2", "--repeats", "1", "--cache", tmp / "cache"});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err,
                       "W1 at 268435456 spheres needs about 236.2 GB of host memory (880 "
                       "B a sphere"))
      << describe(o);
  EXPECT_TRUE(contains(o.err, "is available here (MemAvailable): refused; at most "))
      << describe(o);
  EXPECT_TRUE(contains(o.out, "settle    falling      16384")) << "the other size still runs\n"
                                                               << describe(o);
  EXPECT_TRUE(contains(o.out, "settle    dense        16384")) << describe(o);
}

}  // namespace
