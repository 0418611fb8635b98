// Inputs the fuzz targets (tests/fuzz, docs/fuzzing.md) once failed on, replayed through the same
// entry points: every file in tests/data/fuzz-regressions/<target>/ must be refused or accepted
// without a crash, an uncaught exception or an error without a message (the entry points abort on
// those), and in the sanitizer stage of scripts/test.sh without a sanitizer report. The inputs of
// assimp/ are not replayed: docs/fuzzing.md says why.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz/fuzz_targets.h"

namespace {

namespace fs = std::filesystem;
using Entry = int (*)(const std::uint8_t*, std::size_t);

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> files;
  if (fs::is_directory(dir)) {
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
      if (e.is_regular_file()) files.push_back(e.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// Runs every file of `dir` through `entry`; returns how many there were.
std::size_t replay(const fs::path& dir, Entry entry) {
  const std::vector<fs::path> files = files_in(dir);
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    const std::string bytes = text.str();
    if (bytes.empty()) {
      ADD_FAILURE() << "an empty input (libFuzzer never passes one)";
      continue;
    }
    EXPECT_EQ(entry(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), 0);
  }
  return files.size();
}

fs::path regressions(const std::string& target) {
  return fs::path(MOTES_TEST_DATA_DIR) / "fuzz-regressions" / target;
}

TEST(FuzzRegressions, Scene) { replay(regressions("scene"), motes::fuzz::scene); }

TEST(FuzzRegressions, Mesh) { replay(regressions("mesh"), motes::fuzz::mesh); }

TEST(FuzzRegressions, Checkpoint) {
  // run_record_empty_extension: a run record whose extension is 0 bytes long; the reader handed
  // memcpy the null data() of the empty vector (UBSan).
  EXPECT_GE(replay(regressions("checkpoint"), motes::fuzz::checkpoint), 1u);
}

TEST(FuzzRegressions, Frames) {
  // vtu_array_name_outside_tag: an uncaught std::out_of_range; vtu_huge_point_count: 1.2 TB
  // allocated for a NumberOfPoints the file cannot hold; vtu_zero_points: memcpy into the null
  // data() of an empty vector (UBSan); vtu_offset_wrap: an offset that wrapped past 2^64.
  EXPECT_GE(replay(regressions("frames"), motes::fuzz::frames), 4u);
}

// The seeds scripts/fuzz.sh gives the checkpoint and frame targets, through the same entry points:
// valid files, each loaded and read in full.
TEST(FuzzRegressions, GeneratedSeeds) {
  const fs::path dir = motes::fuzz::work_dir() / "seeds";
  motes::fuzz::write_checkpoint_seeds(dir / "checkpoint");
  motes::fuzz::write_frame_seeds(dir / "frames");
  EXPECT_EQ(replay(dir / "checkpoint", motes::fuzz::checkpoint), 4u);
  EXPECT_EQ(replay(dir / "frames", motes::fuzz::frames), 5u);
}

}  // namespace
