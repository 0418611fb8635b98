// `motes run --render` and `motes render` as a user runs them: PNG frames decoded back, the MP4
// checked with ffprobe, results read back from VTU and CSV, and clear errors for bad input.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

// The scalar decoder: its SSE2 paths need optimization to compile (the sanitizer build compiles
// the tests at -O0), and a test reading a few small PNGs gains nothing from them.
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_SIMD
#include <stb/stb_image.h>

#include "motes/render_output.h"
#include "unit/cli_support.h"
#include "unit/test_support.h"

namespace fs = std::filesystem;

namespace {

using motes_test::TempDir;

const std::string kSmallScene = std::string(MOTES_TEST_DATA_DIR) + "/cli/small.json";
// small.json: 0.05 s with a frame every 0.01 s: frames 0 to 5.
constexpr std::size_t kSmallFrames = 6;

using motes_test::contains;
using motes_test::describe;
using motes_test::Outcome;
using motes_test::quote;
using motes_test::read_text;

/// Rendering runs get more time than the CLI tests' default (slow under the sanitizers).
Outcome run_rendering(const TempDir& tmp, const std::vector<std::string>& args,
                      const std::string& env = "") {
  return motes_test::run_motes(tmp, args, env, 300);
}

std::vector<fs::path> pngs_in(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".png") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

struct Decoded {
  int width = 0, height = 0, channels = 0;
  std::vector<unsigned char> pixels;
};

Decoded decode_png(const fs::path& path) {
  Decoded d;
  unsigned char* data = stbi_load(path.c_str(), &d.width, &d.height, &d.channels, 3);
  if (data == nullptr) {
    ADD_FAILURE() << "cannot decode " << path << ": " << stbi_failure_reason();
    return d;
  }
  d.pixels.assign(data, data + 3 * static_cast<std::size_t>(d.width) * d.height);
  stbi_image_free(data);
  return d;
}

/// A picture of something: many distinct colours (not a blank or one-colour image).
std::size_t distinct_colors(const Decoded& d) {
  std::set<std::uint32_t> colors;
  for (std::size_t i = 0; i + 2 < d.pixels.size(); i += 3) {
    colors.insert(std::uint32_t{d.pixels[i]} << 16 | std::uint32_t{d.pixels[i + 1]} << 8 |
                  d.pixels[i + 2]);
  }
  return colors.size();
}

TEST(RenderCli, RunWritesOnePngPerFrame) {
  TempDir tmp;
  const std::string dir = tmp / "frames";
  const Outcome o = run_rendering(tmp, {"run", kSmallScene, "--format", "none", "--render", dir,
                                        "--size", "320x180", "--no-video"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_TRUE(contains(o.out, "pictures        6 PNG frames in " + dir)) << o.out;
  const std::vector<fs::path> files = pngs_in(dir);
  ASSERT_EQ(files.size(), kSmallFrames);
  EXPECT_EQ(files.front().filename(), "frame_000000.png");
  std::vector<unsigned char> first;
  for (const fs::path& f : files) {
    const Decoded d = decode_png(f);
    EXPECT_EQ(d.width, 320);
    EXPECT_EQ(d.height, 180);
    EXPECT_GT(distinct_colors(d), 200u) << f;
    if (first.empty()) {
      first = d.pixels;
    } else if (f == files.back()) {
      EXPECT_NE(d.pixels, first) << "the boxes fell, so the last frame differs from the first";
    }
  }
  EXPECT_FALSE(fs::exists(fs::path(dir) / "video.mp4"));
}

TEST(RenderCli, RunWritesAnH264Mp4WhenFfmpegIsInstalled) {
  if (!motes::render::find_program("ffmpeg") || !motes::render::find_program("ffprobe")) {
    GTEST_SKIP() << "ffmpeg or ffprobe is not installed (Debian: apt-get install ffmpeg)";
  }
  TempDir tmp;
  const std::string dir = tmp / "frames";
  const Outcome o = run_rendering(
      tmp, {"run", kSmallScene, "--format", "none", "--render", dir, "--size", "161x91"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  const std::string video = (fs::path(dir) / "video.mp4").string();
  EXPECT_TRUE(contains(o.out, "video " + video + " at 60 fps (")) << o.out;
  EXPECT_TRUE(contains(o.out, "clamped to 60 fps")) << o.out;
  ASSERT_TRUE(fs::exists(video)) << describe(o);
  const std::string probe = tmp / "probe.txt";
  const std::string cmd =
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=codec_name,pix_fmt,width,height,nb_read_frames -of default=noprint_wrappers=1 " +
      quote(video) + " >" + quote(probe);
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const std::string info = read_text(probe);
  EXPECT_TRUE(contains(info, "codec_name=h264")) << info;
  EXPECT_TRUE(contains(info, "pix_fmt=yuv420p")) << info;
  EXPECT_TRUE(contains(info, "width=162")) << info;  // odd sizes padded to even for 4:2:0
  EXPECT_TRUE(contains(info, "height=92")) << info;
  EXPECT_TRUE(contains(info, "nb_read_frames=" + std::to_string(kSmallFrames))) << info;
}

TEST(RenderCli, WithoutFfmpegTheMessageSaysHowToGetItAndPngsStay) {
  TempDir tmp;
  const std::string dir = tmp / "frames";
  const Outcome o = run_rendering(
      tmp, {"run", kSmallScene, "--format", "none", "--render", dir, "--size", "64x64"},
      "MOTES_FFMPEG=");
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_TRUE(contains(o.out, "ffmpeg was not found")) << o.out;
  EXPECT_TRUE(contains(o.out, "apt-get install ffmpeg")) << o.out;
  EXPECT_EQ(pngs_in(dir).size(), kSmallFrames);
  EXPECT_FALSE(fs::exists(fs::path(dir) / "video.mp4"));
}

TEST(RenderCli, RenderCommandDrawsVtuResultsAsRunDid) {
  TempDir tmp;
  const std::string results = tmp / "results", frames = tmp / "frames";
  const Outcome run = run_rendering(tmp, {"run", kSmallScene, "--out", results, "--render", frames,
                                          "--size", "200x120", "--no-video"});
  ASSERT_EQ(run.exit_code, 0) << describe(run);
  const Outcome render = run_rendering(
      tmp, {"render", results, "--scene", kSmallScene, "--size", "200x120", "--no-video"});
  ASSERT_EQ(render.exit_code, 0) << describe(render);
  EXPECT_TRUE(contains(render.out, "6 frames of 108 particles")) << render.out;
  const std::vector<fs::path> from_run = pngs_in(frames);
  const std::vector<fs::path> from_results = pngs_in(fs::path(results) / "render");
  ASSERT_EQ(from_run.size(), kSmallFrames);
  ASSERT_EQ(from_results.size(), kSmallFrames);
  // The VTU files hold the same float32 state, so the same scene gives the same pictures.
  for (std::size_t i = 0; i < kSmallFrames; ++i) {
    EXPECT_EQ(decode_png(from_run[i]).pixels, decode_png(from_results[i]).pixels) << i;
  }
}

TEST(RenderCli, RenderCommandDrawsCsvResults) {
  TempDir tmp;
  const std::string results = tmp / "results", out = tmp / "pictures";
  const Outcome run = run_rendering(tmp, {"run", kSmallScene, "--out", results, "--format", "csv"});
  ASSERT_EQ(run.exit_code, 0) << describe(run);
  const Outcome render = run_rendering(tmp, {"render", results, "--out", out, "--size", "96x64",
                                             "--no-video", "--color-by", "speed"});
  ASSERT_EQ(render.exit_code, 0) << describe(render);
  const std::vector<fs::path> files = pngs_in(out);
  ASSERT_EQ(files.size(), kSmallFrames);
  EXPECT_GT(distinct_colors(decode_png(files.back())), 100u);
}

TEST(RenderCli, BadSizeAndColourModeAreUsageErrors) {
  TempDir tmp;
  for (const char* size : {"12x", "0x100", "big", "1280x720x2"}) {
    const Outcome o =
        run_rendering(tmp, {"run", kSmallScene, "--render", tmp / "f", "--size", size});
    EXPECT_EQ(o.exit_code, 105) << describe(o);
    EXPECT_TRUE(contains(o.err, std::string("invalid size '") + size + "'")) << o.err;
  }
  const Outcome color =
      run_rendering(tmp, {"render", tmp.path().string(), "--color-by", "rainbow"});
  EXPECT_EQ(color.exit_code, 105) << describe(color);
  EXPECT_TRUE(contains(color.err, "unknown colour mode 'rainbow' (expected one of: body, speed"))
      << color.err;
}

TEST(RenderCli, UnreadableResultsAreErrorsNamingThePath) {
  TempDir tmp;
  const std::string missing = tmp / "no_such_results";
  Outcome o = run_rendering(tmp, {"render", missing});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err, "motes: error: cannot read results '" + missing + "'")) << o.err;

  const std::string empty = tmp / "empty";
  fs::create_directories(empty);
  o = run_rendering(tmp, {"render", empty});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err, "no particles.pvd, particles_*.vtu or particles.csv in it")) << o.err;

  // A truncated frame: the error names the file.
  const std::string results = tmp / "results";
  ASSERT_EQ(run_rendering(tmp, {"run", kSmallScene, "--out", results}).exit_code, 0);
  const fs::path frame = fs::path(results) / "particles_000003.vtu";
  fs::resize_file(frame, fs::file_size(frame) / 2);
  o = run_rendering(tmp, {"render", results, "--no-video"});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err, frame.string() + "': ")) << o.err;
  EXPECT_TRUE(contains(o.err, "truncated")) << o.err;

  const std::string csv = tmp / "bad.csv";
  std::ofstream(csv) << "x,y,z\n1,2,3\n";
  o = run_rendering(tmp, {"render", csv});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_TRUE(contains(o.err, csv + "':1: expected the header")) << o.err;
}

}  // namespace
