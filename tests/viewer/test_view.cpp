// `motes view` seen as a person sees it: its pictures (offscreen, and from a window under Xvfb)
// against the headless renderer's picture of the same state, the one-line error without a
// display, and a window closed mid-run leaving no process behind.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "motes/devices.h"
#include "motes/render.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/viewer.h"

#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_SIMD
#include <stb/stb_image.h>

extern char** environ;

namespace {

namespace fs = std::filesystem;
using motes::render::Image;

const std::string kScene = std::string(MOTES_SOURCE_DIR) + "/examples/scenes/position_dice.json";
constexpr int kFrames = 20;
constexpr int kWidth = 320;
constexpr int kHeight = 240;
// Mean absolute difference (0..255) of the 80 x 60 greyscale pictures below which two pictures
// show the same thing. Measured here: the viewer's picture after an openmp run 0.00 from the
// headless renderer's (offscreen and window), after a vulkan run 1.55; a camera turned by 8
// degrees 5.3, the particles left out 14.9 (both checked in every test, so that the threshold
// cannot pass a wrong picture).
constexpr double kSameBelow = 3.0;

fs::path scratch_dir() {
  return fs::temp_directory_path() / ("motes-view-test-" + std::to_string(getpid()));
}

fs::path scratch(const std::string& name) {
  fs::create_directories(scratch_dir());
  return scratch_dir() / name;
}

/// The scratch folder is removed when the program's tests have passed (kept after a failure, for
/// its pictures and logs).
class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    if (!::testing::UnitTest::GetInstance()->Passed()) return;
    std::error_code ec;
    fs::remove_all(scratch_dir(), ec);
  }
};
[[maybe_unused]] ::testing::Environment* const kScratchCleanup =
    ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

Image load_png(const fs::path& path) {
  Image image;
  int channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &image.width, &image.height, &channels, 3);
  if (data == nullptr) {
    ADD_FAILURE() << "cannot read " << path;
    return image;
  }
  image.rgb.assign(data, data + 3 * image.width * image.height);
  stbi_image_free(data);
  return image;
}

/// Greyscale box-averaged to 80 x 60.
std::vector<double> small_grey(const Image& image) {
  constexpr int kW = 80, kH = 60;
  std::vector<double> sum(kW * kH, 0.0), count(kW * kH, 0.0);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      const int i = (y * kH / image.height) * kW + x * kW / image.width;
      sum[i] += 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
      count[i] += 1.0;
    }
  }
  for (std::size_t i = 0; i < sum.size(); ++i) sum[i] /= std::max(count[i], 1.0);
  return sum;
}

/// The mean absolute difference of the pictures' small greyscale versions (0..255).
double difference(const Image& a, const Image& b) {
  const std::vector<double> ga = small_grey(a), gb = small_grey(b);
  double d = 0.0;
  for (std::size_t i = 0; i < ga.size(); ++i) d += std::abs(ga[i] - gb[i]);
  return d / static_cast<double>(ga.size());
}

/// The headless renderer's pictures after `kFrames` frames on openmp: as the camera sees it,
/// with the camera turned 8 degrees about up, and with no particles.
struct Reference {
  Image same, turned, empty;
};

Reference reference() {
  motes::Scene scene = motes::load_scene_file(kScene).value();
  auto sim = motes::Simulation::create(scene, motes::open_device("openmp").value()).value();
  const motes::Snapshot first = sim->snapshot().value();
  const auto steps = static_cast<std::uint64_t>(
      std::max<long long>(1, std::llround(1.0 / (60.0 * scene.settings.dt))));
  EXPECT_TRUE(sim->step(steps * kFrames));
  const motes::Snapshot last = sim->snapshot().value();
  motes::render::RenderSettings s;
  s.size = {kWidth, kHeight};
  s.look = motes::render::look_from_scene(scene);
  s.shadows = false;
  s.camera = scene.camera ? motes::render::camera_from_spec(*scene.camera)
                          : motes::render::fit_camera(first.particle_pos, s.look.up, s.size, 35.0f,
                                                      s.look.ground_height);
  auto draw = [&](const motes::render::RenderSettings& settings, const motes::Snapshot& frame) {
    motes::render::FrameRenderer r(settings);
    r.render(first);  // the ground's extent from the first frame, as the viewer takes it
    return r.render(frame);
  };
  Reference ref;
  ref.same = draw(s, last);
  motes::render::RenderSettings turned = s;
  const Eigen::Vector3f up = s.look.up.normalized();
  const Eigen::AngleAxisf turn(8.0f * 3.14159265f / 180.0f, up);
  turned.camera.position = s.camera.target + turn * (s.camera.position - s.camera.target);
  ref.turned = draw(turned, last);
  motes::Snapshot none = last;
  none.particle_pos.clear();
  none.particle_body.clear();
  none.particle_vel.clear();
  ref.empty = draw(s, none);
  return ref;
}

/// Runs a command line through the shell; its exit status (-1 when it did not exit).
int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// `motes view` of kScene; without shadows unless `shadows` (the headless reference has none:
/// its shadows are another method's, shadow-mapped).
std::string view_command(const std::string& backend, const fs::path& png, bool offscreen,
                         int frames = kFrames, bool shadows = false) {
  return std::string(MOTES_CLI_PATH) + " view " + kScene + " --backend " + backend +
         " --size 320x240 --frames " + std::to_string(frames) + " --screenshot " + png.string() +
         (offscreen ? " --offscreen" : "") + (shadows ? "" : " --no-shadows");
}

void expect_matches(const Image& picture, const Reference& ref) {
  ASSERT_EQ(picture.width, kWidth);
  ASSERT_EQ(picture.height, kHeight);
  const double same = difference(picture, ref.same);
  const double turned = difference(picture, ref.turned);
  const double empty = difference(picture, ref.empty);
  std::printf("difference from the headless picture %.2f, turned camera %.2f, no particles %.2f\n",
              same, turned, empty);
  EXPECT_LT(same, kSameBelow);
  // The measure tells wrong pictures apart.
  EXPECT_GT(turned, kSameBelow);
  EXPECT_GT(empty, kSameBelow);
}

/// An X server of its own for one test: Xvfb on a free display number, stopped at the end.
class Xvfb {
 public:
  Xvfb() {
    const char* candidates[] = {"/usr/bin/Xvfb", "/usr/local/bin/Xvfb"};
    std::string exe;
    for (const char* c : candidates) {
      if (access(c, X_OK) == 0) exe = c;
    }
    if (exe.empty()) return;
    for (int n = 90 + getpid() % 100; n < 400; ++n) {
      if (fs::exists("/tmp/.X11-unix/X" + std::to_string(n)) ||
          fs::exists("/tmp/.X" + std::to_string(n) + "-lock")) {
        continue;
      }
      display_ = ":" + std::to_string(n);
      std::vector<std::string> args = {exe,          display_,    "-screen", "0",
                                       "640x480x24", "-nolisten", "tcp"};
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      if (posix_spawn(&pid_, exe.c_str(), nullptr, nullptr, argv.data(), environ) != 0) return;
      const fs::path socket = "/tmp/.X11-unix/X" + std::to_string(n);
      for (int i = 0; i < 100 && !fs::exists(socket); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      ready_ = fs::exists(socket);
      return;
    }
  }
  ~Xvfb() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
  }
  Xvfb(const Xvfb&) = delete;
  Xvfb& operator=(const Xvfb&) = delete;
  [[nodiscard]] bool ready() const { return ready_; }
  [[nodiscard]] const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  bool ready_ = false;
  std::string display_;
};

/// The text of the file at `path`.
std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class ViewOffscreen : public testing::TestWithParam<const char*> {};

TEST_P(ViewOffscreen, MatchesTheHeadlessRenderer) {
  const std::string backend = GetParam();
  if (backend != "openmp" && !motes::open_device(backend)) {
    GTEST_SKIP() << "skipped: no " << backend << " device for the simulation";
  }
  const fs::path png = scratch("offscreen-" + backend + ".png");
  const fs::path out = scratch("offscreen-" + backend + ".txt");
  ASSERT_EQ(shell(view_command(backend, png, true) + " > " + out.string()), 0);
  // Vulkan draws zero copy, CUDA by the CUDA copy, openmp staged (docs/viewer.md).
  const std::string text = read_text(out);
  const char* path = backend == "vulkan" ? "drawn zero copy"
                     : backend == "cuda" ? "drawn CUDA copy"
                                         : "drawn staged";
  EXPECT_NE(text.find(path), std::string::npos) << text;
  expect_matches(load_png(png), reference());
}

INSTANTIATE_TEST_SUITE_P(Backends, ViewOffscreen, testing::Values("openmp", "vulkan", "cuda"));

TEST(ViewWindow, MatchesTheHeadlessRendererUnderXvfb) {
  Xvfb x;
  if (!x.ready()) GTEST_SKIP() << "skipped: no Xvfb (Debian: xvfb)";
  const fs::path png = scratch("window.png");
  ASSERT_EQ(shell("DISPLAY=" + x.display() + " " + view_command("openmp", png, false)), 0);
  const Reference ref = reference();
  expect_matches(load_png(png), ref);
  // A window's swapchain, zero copy from the Vulkan backend's buffers.
  if (!motes::open_device("vulkan")) return;
  const fs::path vulkan_png = scratch("window-vulkan.png"), out = scratch("window-vulkan.txt");
  ASSERT_EQ(shell("DISPLAY=" + x.display() + " " + view_command("vulkan", vulkan_png, false) +
                  " > " + out.string()),
            0);
  EXPECT_NE(read_text(out).find("drawn zero copy"), std::string::npos) << read_text(out);
  expect_matches(load_png(vulkan_png), ref);
}

TEST(ViewWindow, NoDisplayIsAOneLineError) {
  const fs::path err = scratch("no-display.txt");
  const int rc = shell("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(MOTES_CLI_PATH) +
                       " view " + kScene + " 2> " + err.string());
  EXPECT_EQ(rc, 1);
  std::ifstream in(err);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].rfind("motes view: no display (", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find("use --offscreen"), std::string::npos) << lines[0];
}

TEST(ViewWindow, ClosedMidRunLeavesNoProcess) {
  Xvfb x;
  if (!x.ready()) GTEST_SKIP() << "skipped: no Xvfb (Debian: xvfb)";
  const std::string display = "DISPLAY=" + x.display();
  std::vector<std::string> args = {MOTES_CLI_PATH, "view",   kScene,   "--backend",
                                   "openmp",       "--size", "320x240"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_text;
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::string(*e).rfind("DISPLAY=", 0) != 0) env_text.emplace_back(*e);
  }
  env_text.push_back(display);
  std::vector<char*> envp;
  for (std::string& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = -1;
  ASSERT_EQ(posix_spawn(&pid, MOTES_CLI_PATH, nullptr, nullptr, argv.data(), envp.data()), 0);
  // Running with its window open for a while, then closed as a session ends it.
  std::this_thread::sleep_for(std::chrono::seconds(3));
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, WNOHANG), 0) << "motes view ended by itself";
  ASSERT_EQ(kill(pid, SIGTERM), 0);
  pid_t done = 0;
  for (int i = 0; i < 200 && done == 0; ++i) {
    done = waitpid(pid, &status, WNOHANG);
    if (done == 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (done == 0) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    FAIL() << "motes view still ran 10 s after SIGTERM";
  }
  ASSERT_TRUE(WIFEXITED(status)) << "motes view did not exit cleanly";
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_NE(kill(pid, 0), 0);  // gone, and reaped
}

// Every example scene in a window under Xvfb: two frames stepped on openmp (drawn staged), and
// the position scenes also on vulkan (drawn zero copy), each ending with the run's guards, which
// must find nothing (a guard warning fails the scene, as in the scene runs of CI).
TEST(ViewWindow, EveryExampleSceneRunsUnderXvfb) {
  Xvfb x;
  if (!x.ready()) GTEST_SKIP() << "skipped: no Xvfb (Debian: xvfb)";
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(fs::path(MOTES_SOURCE_DIR) / "examples/scenes")) {
    if (e.path().extension() == ".json") scenes.push_back(e.path());
  }
  std::sort(scenes.begin(), scenes.end());
  ASSERT_GE(scenes.size(), 20u);
  const bool vulkan = static_cast<bool>(motes::open_device("vulkan"));
  const fs::path out = scratch("every.txt"), err = scratch("every-err.txt");
  for (const fs::path& scene : scenes) {
    std::vector<std::string> backends = {"openmp"};
    if (vulkan && scene.stem().string().rfind("position_", 0) == 0) backends.emplace_back("vulkan");
    for (const std::string& backend : backends) {
      SCOPED_TRACE(scene.filename().string() + " on " + backend);
      const int rc = shell("DISPLAY=" + x.display() + " " + std::string(MOTES_CLI_PATH) + " view " +
                           scene.string() + " --backend " + backend +
                           " --size 160x120 --frames 2 > " + out.string() + " 2> " + err.string());
      const std::string text = read_text(out);
      EXPECT_EQ(rc, 0) << text << read_text(err);
      EXPECT_NE(text.find("2 frames shown"), std::string::npos) << text;
      EXPECT_NE(text.find("no guard warning"), std::string::npos) << text;
      EXPECT_EQ(read_text(err), "");
    }
  }
}

// Scripted input (--input): the same Input as keys and mouse, offscreen too.

/// Writes `text` to the scratch file `name`.
fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path path = scratch(name);
  std::ofstream(path) << text;
  return path;
}

/// The state a `--save-state` run left.
motes::Snapshot saved_state(const fs::path& path) {
  motes::Scene scene = motes::load_scene_file(kScene).value();
  auto sim = motes::Simulation::create(scene, motes::open_device("openmp").value()).value();
  EXPECT_TRUE(sim->load_state(path.string()));
  return sim->snapshot().value();
}

std::uint64_t steps_per_frame() {
  const double dt = motes::load_scene_file(kScene).value().settings.dt;
  return static_cast<std::uint64_t>(std::max<long long>(1, std::llround(1.0 / (60.0 * dt))));
}

/// Runs `motes view` offscreen on openmp for `frames` frames with the script `script` (none when
/// empty) and returns the state it saved.
motes::Snapshot scripted_run(const std::string& tag, int frames, const std::string& script) {
  const fs::path state = scratch(tag + ".state");
  std::string command = std::string(MOTES_CLI_PATH) + " view " + kScene +
                        " --backend openmp --offscreen --size 320x240 --frames " +
                        std::to_string(frames) + " --save-state " + state.string();
  if (!script.empty()) command += " --input " + write_file(tag + ".txt", script).string();
  EXPECT_EQ(shell(command), 0) << command;
  return saved_state(state);
}

bool same_positions(const motes::Snapshot& a, const motes::Snapshot& b) {
  if (a.particle_pos.size() != b.particle_pos.size()) return false;
  for (std::size_t i = 0; i < a.particle_pos.size(); ++i) {
    if (a.particle_pos[i].x != b.particle_pos[i].x || a.particle_pos[i].y != b.particle_pos[i].y ||
        a.particle_pos[i].z != b.particle_pos[i].z) {
      return false;
    }
  }
  return true;
}

TEST(ViewScript, SpacePausesAndResetStartsAgain) {
  const std::uint64_t steps = steps_per_frame();
  const motes::Snapshot five = scripted_run("five", 5, "");
  const motes::Snapshot two = scripted_run("two", 2, "");
  const motes::Snapshot fifteen = scripted_run("fifteen", 15, "");
  EXPECT_EQ(five.step, 5 * steps);
  EXPECT_EQ(fifteen.step, 15 * steps);
  EXPECT_FALSE(same_positions(five, fifteen));  // the bodies move, so a pause shows
  // Paused from frame 5 on: the state of frame 5, 10 frames later.
  const motes::Snapshot paused = scripted_run("paused", 15, "5 key space  # pause\n");
  EXPECT_EQ(paused.step, 5 * steps);
  EXPECT_TRUE(same_positions(paused, five));
  // Paused, one frame's steps with '.', then on again.
  const motes::Snapshot stepped = scripted_run("stepped", 8, "2 key space\n4 key .\n6 key space\n");
  EXPECT_EQ(stepped.step, 5 * steps);  // frames 0, 1, 4, 6, 7
  EXPECT_TRUE(same_positions(stepped, five));
  // Reset at frame 10 of 12: the scene from the start, then frames 10 and 11.
  const motes::Snapshot reset = scripted_run("reset", 12, "10 key r\n");
  EXPECT_EQ(reset.step, 2 * steps);
  EXPECT_TRUE(same_positions(reset, two));
}

// The wireframes (keys W and C): the segments, and that they show in the picture.
TEST(ViewWireframe, GridCellsAndContactsFromAState) {
  motes::Snapshot s;
  s.particle_pos = {{0.05f, 0.05f, 0.05f, 0.05f},   // body 0
                    {0.149f, 0.05f, 0.05f, 0.05f},  // body 1: touches body 0's particle
                    {0.05f, 0.149f, 0.05f, 0.05f},  // body 0 too: its own, not a contact
                    {0.5f, 0.5f, 0.5f, 0.05f}};     // body 2, alone
  s.particle_body = {0, 1, 0, 2};
  const motes::viewer::Segments contacts = motes::viewer::contact_segments(s, 100);
  ASSERT_EQ(contacts.colors.size(), 1u);
  ASSERT_EQ(contacts.ends.size(), 2u);
  EXPECT_FLOAT_EQ(contacts.ends[0].x(), 0.05f);
  EXPECT_FLOAT_EQ(contacts.ends[1].x(), 0.149f);
  EXPECT_FALSE(contacts.truncated);
  EXPECT_TRUE(motes::viewer::contact_segments(s, 0).truncated);
  // Cells of 0.1 m: the first three particles' centres lie in cells (0,0,0), (1,0,0), (0,1,0),
  // the fourth in (5,5,5): four cubes of 12 edges, each edge 0.1 m long on an axis.
  const motes::viewer::Segments cells = motes::viewer::grid_cell_segments(s, 10.0f, 100);
  ASSERT_EQ(cells.colors.size(), 48u);
  for (std::size_t k = 0; k < cells.colors.size(); ++k) {
    EXPECT_NEAR((cells.ends[2 * k + 1] - cells.ends[2 * k]).norm(), 0.1f, 1e-6f);
  }
  EXPECT_EQ(motes::viewer::grid_cell_segments(s, 10.0f, 2).colors.size(), 24u);
}

/// Pixels of `image` within 6 of `rgb` in every channel.
int pixels_like(const Image& image, int r, int g, int b) {
  int n = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      n += std::abs(p[0] - r) <= 6 && std::abs(p[1] - g) <= 6 && std::abs(p[2] - b) <= 6;
    }
  }
  return n;
}

TEST(ViewWireframe, KeysWAndCDrawOverThePicture) {
  const auto run = [](const std::string& tag, const std::string& script) {
    const fs::path png = scratch(tag + ".png");
    std::string command = std::string(MOTES_CLI_PATH) + " view " + kScene +
                          " --backend openmp --offscreen --size 320x240 --frames 40 --screenshot " +
                          png.string();
    if (!script.empty()) command += " --input " + write_file(tag + ".txt", script).string();
    EXPECT_EQ(shell(command), 0) << command;
    return load_png(png);
  };
  const Image plain = run("plain", "");
  const Image contacts = run("contacts", "0 key c\n");
  const Image cells = run("cells", "0 key w\n");
  const Image off = run("off", "0 key c\n0 key w\n20 key c\n20 key w\n");
  // The colours of wireframe.cpp (contacts linear (1, 0.15, 0.1), cells (0.25, 0.65, 1)) after
  // the viewer's gamma 2.
  const int red_plain = pixels_like(plain, 255, 99, 81);
  const int red = pixels_like(contacts, 255, 99, 81);
  const int blue_plain = pixels_like(plain, 128, 206, 255);
  const int blue = pixels_like(cells, 128, 206, 255);
  std::printf("contact-coloured pixels %d (without: %d), cell-coloured %d (without: %d)\n", red,
              red_plain, blue, blue_plain);
  EXPECT_GT(red, red_plain + 50);
  EXPECT_GT(blue, blue_plain + 200);
  // Both toggled off again: the plain picture.
  EXPECT_EQ(off.rgb, plain.rgb);
}

/// One sphere above the ground seen offscreen (`shadows` on or off; `ground`: the scene has one),
/// and where the camera sees the point below its centre along the light, and its centre.
struct ShadowPicture {
  Image image;
  Eigen::Vector2f shadow_pixel, sphere_pixel;
};

ShadowPicture sphere_above_ground(bool shadows, bool ground) {
  motes::Snapshot s;
  const Eigen::Vector3f centre(0.0f, 0.25f, 0.0f);
  s.particle_pos = {{centre.x(), centre.y(), centre.z(), 0.1f}};
  s.particle_vel = {{0.0f, 0.0f, 0.0f, 1.0f}};
  s.particle_body = {0};
  motes::viewer::Style style;
  style.look.up = Eigen::Vector3f::UnitY();
  if (ground) style.look.ground_height = 0.0f;
  motes::render::Camera camera;
  camera.position = {0.0f, 1.2f, 2.0f};
  camera.target = {0.1f, 0.0f, 0.0f};
  camera.up = Eigen::Vector3f::UnitY();
  motes::viewer::Offscreen view({kWidth, kHeight});
  view.restyle(style, s);
  view.set_shadows(shadows);
  ShadowPicture out;
  out.image = view.draw(camera, &s);
  // The light as viewer/src/style.cpp sets it (from above, left and behind the camera), the
  // centre cast along it onto the ground, and both points' pixels (motes/render.h's camera).
  const Eigen::Vector3f forward = (camera.target - camera.position).normalized();
  const Eigen::Vector3f right = forward.cross(camera.up).normalized();
  const Eigen::Vector3f view_up = right.cross(forward);
  const Eigen::Vector3f up = style.look.up;
  const Eigen::Vector3f light = (up - 0.7f * right - 0.35f * forward).normalized();
  const Eigen::Vector3f below = centre - light * (centre.dot(up) / light.dot(up));
  const float focal = 0.5f * kHeight / std::tan(0.5f * camera.fov_degrees * 3.14159265f / 180.0f);
  const auto pixel = [&](const Eigen::Vector3f& p) {
    const Eigen::Vector3f rel = p - camera.position;
    const float z = rel.dot(forward);
    return Eigen::Vector2f(0.5f * kWidth + focal * rel.dot(right) / z,
                           0.5f * kHeight - focal * rel.dot(view_up) / z);
  };
  out.shadow_pixel = pixel(below);
  out.sphere_pixel = pixel(centre);
  return out;
}

/// The sum of the three channels of pixel `p` (rounded down to a pixel).
int brightness(const Image& image, const Eigen::Vector2f& p) {
  const auto at = static_cast<std::size_t>(
      3 * (static_cast<int>(p.y()) * image.width + static_cast<int>(p.x())));
  return image.rgb[at] + image.rgb[at + 1] + image.rgb[at + 2];
}

TEST(ViewShadows, ASphereDarkensTheGroundBelowItAlongTheLight) {
  const ShadowPicture on = sphere_above_ground(true, true);
  const ShadowPicture off = sphere_above_ground(false, true);
  ASSERT_EQ(on.image.rgb.size(), off.image.rgb.size());
  // The point below the centre along the light: in the picture, on the ground (not behind the
  // sphere), and darker with the shadow.
  const Eigen::Vector2f s = on.shadow_pixel;
  ASSERT_GT(s.x(), 0.0f);
  ASSERT_LT(s.x(), kWidth);
  ASSERT_GT(s.y(), 0.0f);
  ASSERT_LT(s.y(), kHeight);
  const int lit = brightness(off.image, s), shaded = brightness(on.image, s);
  std::printf(
      "below the sphere along the light, pixel (%.0f, %.0f): %d without the shadow, %d "
      "with it\n",
      static_cast<double>(s.x()), static_cast<double>(s.y()), lit, shaded);
  EXPECT_LT(shaded, lit - 60);
  // The sphere itself is as it was; nothing is brighter; every pixel that changed lies near the
  // shadow (the sphere's radius is 0.1 m, some 25 pixels here), the rest of the picture is
  // unchanged.
  EXPECT_EQ(brightness(on.image, on.sphere_pixel), brightness(off.image, off.sphere_pixel));
  int changed = 0, brighter = 0, far_changed = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const Eigen::Vector2f p(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
      const int a = brightness(on.image, p), b = brightness(off.image, p);
      if (a == b) continue;
      ++changed;
      if (a > b) ++brighter;
      if ((p - s).norm() > 60.0f) ++far_changed;
    }
  }
  std::printf("pixels changed by the shadow %d, brighter %d, more than 60 pixels away %d\n",
              changed, brighter, far_changed);
  EXPECT_GT(changed, 200);
  EXPECT_EQ(brighter, 0);
  EXPECT_EQ(far_changed, 0);
}

TEST(ViewShadows, NoGroundNoShadow) {
  EXPECT_EQ(sphere_above_ground(true, false).image.rgb,
            sphere_above_ground(false, false).image.rgb);
}

TEST(ViewShadows, KeyHTurnsThemOffAndOn) {
  const auto run = [](const std::string& tag, const std::string& script, bool no_shadows) {
    const fs::path png = scratch(tag + ".png");
    std::string command = std::string(MOTES_CLI_PATH) + " view " + kScene +
                          " --backend openmp --offscreen --size 320x240 --frames 4 --screenshot " +
                          png.string() + (no_shadows ? " --no-shadows" : "");
    if (!script.empty()) command += " --input " + write_file(tag + ".txt", script).string();
    EXPECT_EQ(shell(command), 0) << command;
    return load_png(png);
  };
  const Image with = run("shadows-on", "", false);
  const Image without = run("shadows-off", "", true);
  EXPECT_NE(with.rgb, without.rgb);
  EXPECT_EQ(run("shadows-key-off", "0 key h\n", false).rgb, without.rgb);
  EXPECT_EQ(run("shadows-key-on", "0 key h\n", true).rgb, with.rgb);
}

TEST(ViewScript, QuitEndsARunWithoutAFrameLimit) {
  const fs::path script = write_file("quit.txt", "3 quit\n");
  const fs::path state = scratch("quit.state");
  ASSERT_EQ(shell(std::string(MOTES_CLI_PATH) + " view " + kScene +
                  " --backend openmp --offscreen --size 320x240 --input " + script.string() +
                  " --save-state " + state.string()),
            0);
  EXPECT_EQ(saved_state(state).step, 3 * steps_per_frame());
}

TEST(ViewScript, DragOrbitsTheCamera) {
  const fs::path still = scratch("still.png"), dragged = scratch("dragged.png");
  const std::string base = std::string(MOTES_CLI_PATH) + " view " + kScene +
                           " --backend openmp --offscreen --size 320x240 --frames 6 ";
  ASSERT_EQ(shell(base + "--screenshot " + still.string()), 0);
  const fs::path script = write_file("orbit.txt", "1 drag 100 120 160 120 3\n");
  ASSERT_EQ(shell(base + "--input " + script.string() + " --screenshot " + dragged.string()), 0);
  const double d = difference(load_png(still), load_png(dragged));
  std::printf("orbit drag changed the picture by %.2f\n", d);
  EXPECT_GT(d, kSameBelow);
}

TEST(ViewScript, BadLinesAreOneLineErrorsNamingFileAndLine) {
  const struct {
    const char* text;
    const char* reason;
  } cases[] = {
      {"1 key space\n3 key x\n", ":2: unknown key 'x'"},
      {"# fine\nten key r\n", ":2: frame 'ten' is not a number"},
      {"4 drag 1 2 3\n", ":1: expected 'FRAME drag"},
      {"4 jump\n", ":1: unknown event 'jump'"},
      {"4 drag 1 2 3 4 0\n", ":1: a drag lasts at least 1 frame"},
  };
  int n = 0;
  for (const auto& c : cases) {
    const fs::path script = write_file("bad" + std::to_string(n) + ".txt", c.text);
    const fs::path err = scratch("bad" + std::to_string(n++) + ".err");
    const int rc =
        shell(std::string(MOTES_CLI_PATH) + " view " + kScene + " --offscreen --frames 2 --input " +
              script.string() + " 2> " + err.string());
    EXPECT_NE(rc, 0);
    std::ifstream in(err);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    ASSERT_EQ(lines.size(), 1u) << c.text;
    EXPECT_NE(lines[0].find(script.string() + c.reason), std::string::npos) << lines[0];
  }
}

// Pick and drag (Shift + left drag) through scripted input, offscreen.

// One 4 cm box of 64 particles resting on the floor, seen from the front: the camera looks along
// -z at the box's centre, so that a drag to the right pulls the box towards +x.
constexpr const char* kBoxScene = R"({
  "settings": { "dt": 0.016666666666666666, "substeps": 16, "contact_model": "position",
                "gravity": [0.0, -9.81, 0.0], "particle_diameter": 0.01 },
  "materials": { "plastic": { "density": 1200.0, "friction": 0.4, "restitution": 0.3 } },
  "bodies": [ { "name": "box", "material": "plastic",
                "shape": { "type": "box", "particles": [4, 4, 4] }, "position": [0.0, 0.02, 0.0] } ],
  "camera": { "position": [0.0, 0.1, 0.4], "target": [0.0, 0.02, 0.0], "fov": 40.0 },
  "planes": [ { "name": "floor", "normal": [0.0, 1.0, 0.0], "point": [0.0, 0.0, 0.0] } ]
})";

/// The state `--save-state` wrote for the scene file `scene_path`.
motes::Snapshot load_saved(const fs::path& scene_path, const fs::path& state) {
  motes::Scene scene = motes::load_scene_file(scene_path.string()).value();
  auto sim = motes::Simulation::create(scene, motes::open_device("openmp").value()).value();
  EXPECT_TRUE(sim->load_state(state.string()));
  return sim->snapshot().value();
}

/// The state after `frames` frames of the scene `scene_text` with the script `script` (none when
/// empty).
motes::Snapshot state_after(const std::string& scene_text, const std::string& tag, int frames,
                            const std::string& script) {
  const fs::path scene_path = write_file(tag + ".json", scene_text);
  const fs::path state = scratch(tag + ".state");
  std::string command = std::string(MOTES_CLI_PATH) + " view " + scene_path.string() +
                        " --backend openmp --offscreen --size 320x240 --frames " +
                        std::to_string(frames) + " --save-state " + state.string();
  if (!script.empty()) command += " --input " + write_file(tag + ".txt", script).string();
  EXPECT_EQ(shell(command), 0) << command;
  return load_saved(scene_path, state);
}

/// The box's centre after 30 frames with the script `script` (none when empty).
Eigen::Vector3d box_after(const std::string& tag, const std::string& script) {
  const motes::Snapshot s = state_after(kBoxScene, tag, 30, script);
  return {s.body_pos.at(0).x, s.body_pos.at(0).y, s.body_pos.at(0).z};
}

TEST(ViewGrab, ShiftDragPullsTheBoxSideways) {
  const Eigen::Vector3d start(0.0, 0.02, 0.0);
  const Eigen::Vector3d still = box_after("box-still", "");
  std::printf("left alone: (%.4f, %.4f, %.4f)\n", still.x(), still.y(), still.z());
  EXPECT_LT(std::abs(still.x() - start.x()), 1e-3);
  EXPECT_LT(std::abs(still.z() - start.z()), 1e-3);
  // 60 pixels to the right at the box's depth (0.408 m; focal length 120 / tan 20 degrees =
  // 330 pixels): 7.4 cm. The pull closes the gap in about 0.1 s and lets go with the drag's end,
  // so the box lags the cursor: it must move the right way by a good part of that distance.
  const double expected = 60.0 * std::sqrt(0.08 * 0.08 + 0.4 * 0.4) /
                          (120.0 / std::tan(20.0 * 3.14159265358979 / 180.0));
  const Eigen::Vector3d dragged = box_after("box-dragged", "5 drag 165 117 225 117 10 shift\n");
  const double dx = dragged.x() - still.x();
  std::printf("dragged 60 px right: moved %.4f m along x (cursor %.4f m), %.4f along z\n", dx,
              expected, dragged.z() - still.z());
  EXPECT_GT(dx, 0.3 * expected);
  EXPECT_LT(dx, 1.5 * expected);
  EXPECT_LT(std::abs(dragged.z() - still.z()), 0.3 * dx);
  EXPECT_GT(dragged.y(), 0.0);  // still above the floor
  // A plain left drag orbits the camera and leaves the box alone, and a grab that misses every
  // particle pulls nothing.
  const Eigen::Vector3d orbited = box_after("box-orbited", "5 drag 165 117 225 117 10\n");
  EXPECT_LT((orbited - still).norm(), 1e-3);
  const Eigen::Vector3d missed = box_after("box-missed", "5 drag 20 20 80 20 10 shift\n");
  EXPECT_LT((missed - still).norm(), 1e-3);
}

// Recording (V, --record FILE) through ffmpeg, offscreen.

/// ffprobe's count of the video frames in `path` (-1 when it reads no video stream).
int video_frames(const fs::path& path) {
  const fs::path out = scratch(path.filename().string() + ".frames");
  if (shell("ffprobe -v error -count_frames -select_streams v:0 -show_entries "
            "stream=nb_read_frames -of csv=p=0 " +
            path.string() + " > " + out.string()) != 0) {
    return -1;
  }
  std::ifstream in(out);
  int frames = -1;
  in >> frames;
  return frames;
}

TEST(ViewRecord, KeyVAndRecordWriteTheDisplayedFrames) {
  if (shell("command -v ffmpeg > /dev/null && command -v ffprobe > /dev/null") != 0) {
    GTEST_SKIP() << "skipped: no ffmpeg or ffprobe (Debian: ffmpeg)";
  }
  const fs::path dir = scratch("record");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path script = write_file("record.txt", "2 key v\n8 key v\n");
  const std::string base = std::string(MOTES_CLI_PATH) + " view " + kScene +
                           " --backend openmp --offscreen --size 320x240 ";
  // V at frame 2 and again at frame 8: frames 2 to 7 in the current directory's first free name.
  ASSERT_EQ(shell("cd " + dir.string() + " && " + base + "--frames 10 --input " + script.string()),
            0);
  EXPECT_EQ(video_frames(dir / "motes-view-001.mp4"), 6);
  EXPECT_FALSE(fs::exists(dir / "motes-view-002.mp4"));
  // --record FILE: every frame from the start.
  const fs::path mp4 = dir / "whole.mp4";
  ASSERT_EQ(shell(base + "--frames 4 --record " + mp4.string()), 0);
  EXPECT_EQ(video_frames(mp4), 4);
  // Without ffmpeg, --record is refused with one line.
  const fs::path err = scratch("record.err");
  EXPECT_NE(shell("MOTES_FFMPEG= " + base + "--frames 2 --record " + (dir / "no.mp4").string() +
                  " 2> " + err.string()),
            0);
  std::ifstream in(err);
  std::string line;
  std::getline(in, line);
  EXPECT_NE(line.find("no ffmpeg"), std::string::npos) << line;
  EXPECT_FALSE(fs::exists(dir / "no.mp4"));
}

// A rope of 41 particles, 40 cm long, pinned at its left end and let fall, seen from the front
// with its middle particle at the picture's centre.
constexpr const char* kRopeScene = R"({
  "settings": { "dt": 0.016666666666666666, "substeps": 30, "contact_model": "position",
                "gravity": [0.0, -9.81, 0.0], "particle_diameter": 0.01,
                "constraint_iterations": 4, "link_damping": 0.5 },
  "materials": { "rope": { "density": 1000.0, "friction": 0.8 } },
  "bodies": [ { "name": "rope", "kind": "rope", "material": "rope",
                "rope": { "from": [-0.2, 0.1, 0.0], "to": [0.2, 0.1, 0.0], "particles": 41,
                          "pin": [0] } } ],
  "camera": { "position": [0.0, 0.1, 0.5], "target": [0.0, 0.1, 0.0], "fov": 40.0 },
  "planes": [ { "name": "floor", "normal": [0.0, 1.0, 0.0], "point": [0.0, 0.0, 0.0] } ]
})";

TEST(ViewGrab, ShiftDragHoldsUpARopePoint) {
  // Grabbed at frame 1 by its middle particle and dragged 40 pixels up (6 cm at its depth) over
  // 10 frames: at frame 12 the middle particle is well above where the falling rope leaves it.
  const motes::Snapshot fallen = state_after(kRopeScene, "rope-fallen", 12, "");
  const motes::Snapshot held =
      state_after(kRopeScene, "rope-held", 12, "1 drag 160 121 160 81 10 shift\n");
  const double y_fallen = fallen.particle_pos.at(20).y, y_held = held.particle_pos.at(20).y;
  std::printf("rope middle at frame 12: %.4f m left alone, %.4f m held up\n", y_fallen, y_held);
  EXPECT_GT(y_held, y_fallen + 0.02);
  EXPECT_LT(y_held, 0.1 + 0.06 + 0.01);  // not past the cursor's point
  // The pinned end stays pinned, and a grab at the pin picks nothing that moves it.
  EXPECT_EQ(held.particle_pos.at(0).x, fallen.particle_pos.at(0).x);
  EXPECT_EQ(held.particle_pos.at(0).y, fallen.particle_pos.at(0).y);
}

TEST(ViewGrab, ShiftDragInAWindowUnderXvfb) {
  Xvfb x;
  if (!x.ready()) GTEST_SKIP() << "skipped: no Xvfb (Debian: xvfb)";
  if (shell("command -v xdotool > /dev/null") != 0) {
    GTEST_SKIP() << "skipped: no xdotool (Debian: xdotool)";
  }
  const fs::path scene_path = write_file("window-box.json", kBoxScene);
  // The real mouse and keyboard through the X server: press at (165, 117), move 60 pixels to
  // the right in 10 moves, release; with Shift held (a grab) or without (an orbit); then Q ends
  // the run (the frame cap only bounds a run whose window never gets the key), so a slow machine
  // cannot end the run before the drag is done.
  auto drag = [&](const std::string& tag, bool shift) {
    const fs::path state = scratch(tag + ".state");
    const std::string view = std::string(MOTES_CLI_PATH) + " view " + scene_path.string() +
                             " --backend openmp --size 320x240 --frames 3000 --save-state " +
                             state.string();
    const std::string script =
        "DISPLAY=" + x.display() + " sh -c '" + view + " > /dev/null & p=$!; " +
        "w=$(xdotool search --sync --name \"motes view\" | head -1); sleep 0.5; " +
        "xdotool mousemove --window $w 165 117 " + (shift ? "keydown shift " : "") +
        "mousedown 1; for i in 1 2 3 4 5 6 7 8 9 10; do xdotool mousemove --window $w " +
        "$((165 + 6 * i)) 117; sleep 0.03; done; xdotool mouseup 1" +
        (shift ? " keyup shift" : "") + "; sleep 0.3; xdotool key q; wait $p'";
    EXPECT_EQ(shell(script), 0) << script;
    const motes::Snapshot s = load_saved(scene_path, state);
    return s.body_pos.at(0).x;
  };
  const double grabbed = drag("window-grab", true);
  const double orbited = drag("window-orbit", false);
  std::printf("box x after a Shift-drag %.4f m, after a plain drag %.4f m\n", grabbed, orbited);
  EXPECT_GT(grabbed, 0.02);
  EXPECT_LT(std::abs(orbited), 1e-3);
}

bool has_backend(const char* backend) { return motes::open_device(backend).is_ok(); }

// Drawn without the host (docs/viewer.md, "How it draws"), on `backend`, whose path the summary
// names as `path`: the pictures must be the staged path's, whatever the colours.
void expect_pictures_match_the_staged_path(const std::string& backend, const std::string& path) {
  for (const std::string color_by : {"body", "speed", "height"}) {
    Image pictures[2];
    for (int staged = 0; staged < 2; ++staged) {
      const std::string tag = backend + "-" + color_by + (staged != 0 ? "-staged" : "-direct");
      const fs::path png = scratch(tag + ".png"), out = scratch(tag + ".txt");
      // With shadows: both paths cast them from the same per-instance positions.
      ASSERT_EQ(shell(view_command(backend, png, true, 8, true) + " --color-by " + color_by +
                      (staged != 0 ? " --staged" : "") + " > " + out.string()),
                0);
      const std::string text = read_text(out);
      EXPECT_NE(text.find(staged != 0 ? "drawn staged" : "drawn " + path), std::string::npos)
          << text;
      pictures[staged] = load_png(png);
    }
    const double d = difference(pictures[0], pictures[1]);
    std::printf("colours by %s: %s against staged %.3f\n", color_by.c_str(), path.c_str(), d);
    EXPECT_LT(d, kSameBelow);
  }
}

// Many frames drawn without the host, under the validation layer (MOTES_VULKAN_VALIDATION=1 in
// ctest: any message is an error that ends the run): speed colours (the compute pass), a grab
// (snapshots and write_state between the frames) and a reset (the simulation made again, and
// drawn again without the host). The reset's state is a fresh 3-frame run's.
void expect_many_frames_with_a_grab_and_a_reset(const std::string& backend,
                                                const std::string& path) {
  const fs::path scene_path = write_file(backend + "-direct-box.json", kBoxScene);
  auto run = [&](const std::string& tag, int frames, const std::string& script) {
    const fs::path state = scratch(tag + ".state"), out = scratch(tag + ".txt");
    std::string command = std::string(MOTES_CLI_PATH) + " view " + scene_path.string() +
                          " --backend " + backend +
                          " --offscreen --size 320x240 --color-by speed --frames " +
                          std::to_string(frames) + " --save-state " + state.string();
    if (!script.empty()) command += " --input " + write_file(tag + "-input.txt", script).string();
    EXPECT_EQ(shell(command + " > " + out.string() + " 2>&1"), 0) << read_text(out);
    EXPECT_NE(read_text(out).find("drawn " + path), std::string::npos) << read_text(out);
    return load_saved(scene_path, state);
  };
  const motes::Snapshot three = run(backend + "-direct-three", 3, "");
  const motes::Snapshot reset =
      run(backend + "-direct-reset", 100, "5 drag 165 117 225 117 10 shift\n97 key r\n");
  EXPECT_EQ(reset.step, three.step);
  EXPECT_TRUE(same_positions(reset, three));
}

// Zero copy: on the Vulkan backend the viewer draws from the simulation's own buffers
// (Backends/ViewOffscreen.MatchesTheHeadlessRenderer/1 compares that picture with the headless
// renderer's).
TEST(ViewZeroCopy, PicturesMatchTheStagedPath) {
  if (!has_backend("vulkan")) GTEST_SKIP() << "skipped: no Vulkan device for the simulation";
  expect_pictures_match_the_staged_path("vulkan", "zero copy");
}

TEST(ViewZeroCopy, ManyFramesWithAGrabAndAReset) {
  if (!has_backend("vulkan")) GTEST_SKIP() << "skipped: no Vulkan device for the simulation";
  expect_many_frames_with_a_grab_and_a_reset("vulkan", "zero copy");
}

// The CUDA copy: on the CUDA backend, CUDA copies the particles device to device into memory
// the viewer exported (CUDA-Vulkan external memory); runs where a CUDA GPU is (the GPU machine).
TEST(ViewCudaCopy, PicturesMatchTheStagedPath) {
  if (!has_backend("cuda")) GTEST_SKIP() << "skipped: no CUDA device";
  expect_pictures_match_the_staged_path("cuda", "CUDA copy");
}

TEST(ViewCudaCopy, ManyFramesWithAGrabAndAReset) {
  if (!has_backend("cuda")) GTEST_SKIP() << "skipped: no CUDA device";
  expect_many_frames_with_a_grab_and_a_reset("cuda", "CUDA copy");
}

// A small tank of water (docs/rendering.md, "Colours of liquids").
constexpr const char* kWaterScene = R"({
  "settings": { "dt": 0.016666666666666666, "gravity": [0, -9.81, 0],
                "contact_model": "position", "particle_diameter": 0.01 },
  "materials": { "water": { "density": 1000, "friction": 0.0 },
                 "glass": { "density": 2500, "friction": 0.0 } },
  "bodies": [ { "name": "water", "kind": "fluid", "material": "water",
                "fluid": { "type": "box", "min": [0, 0, 0], "max": [0.1204, 0.0803, 0.0602] } } ],
  "planes": [ { "type": "box", "name": "tank", "min": [0, 0, 0], "max": [0.1204, 0.2, 0.0602],
                "material": "glass" } ]
})";

/// The headless renderer's pictures of kWaterScene after `frames` frames on openmp: the fluid
/// shaded as water, in its flat base colour, and the background alone.
struct WaterPictures {
  Image shaded, flat, background;
};

WaterPictures water_pictures(const motes::Scene& scene, int frames) {
  auto sim = motes::Simulation::create(scene, motes::open_device("openmp").value()).value();
  const motes::Snapshot first = sim->snapshot().value();
  EXPECT_TRUE(sim->step(static_cast<std::uint64_t>(frames)));  // dt is a 60th of a second
  const motes::Snapshot last = sim->snapshot().value();
  motes::render::RenderSettings s;
  s.size = {kWidth, kHeight};
  s.look = motes::render::look_from_scene(scene);
  s.shadows = false;
  s.camera =
      motes::render::fit_camera(first.particle_pos, s.look.up, s.size, 35.0f, s.look.ground_height);
  auto draw = [&](const motes::render::RenderSettings& settings, const motes::Snapshot& frame) {
    motes::render::FrameRenderer r(settings);
    r.render(first);  // the ground's extent from the first frame, as the viewer takes it
    return r.render(frame);
  };
  WaterPictures p;
  p.shaded = draw(s, last);
  p.background = draw(s, motes::Snapshot{});
  s.look.body_fluid.clear();
  s.look.body_colors = {motes::render::water_color()};
  p.flat = draw(s, last);
  return p;
}

/// The mean colour of the pixels where `picture` differs from `background` by more than 30.
Eigen::Vector3d mean_where_different(const Image& picture, const Image& background) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (int y = 0; y < picture.height; ++y) {
    for (int x = 0; x < picture.width; ++x) {
      const std::uint8_t *a = picture.pixel(x, y), *b = background.pixel(x, y);
      if (std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]) <= 30) continue;
      sum += Eigen::Vector3d(a[0], a[1], a[2]);
      ++count;
    }
  }
  EXPECT_GT(count, 2000);
  return sum / std::max(count, 1);
}

// Liquids: drawn staged, shaded as water by the headless renderer's rule (lighter at the surface,
// darker deep down); drawn zero copy, in the water's flat base colour (docs/viewer.md, "Not done
// yet"); blue either way. The measure tells the two looks apart.
TEST(ViewFluid, StagedShadesWaterAsTheHeadlessRendererZeroCopyDrawsItFlat) {
  constexpr int kWaterFrames = 4;
  const fs::path scene_path = write_file("water.json", kWaterScene);
  const motes::Scene scene = motes::load_scene_file(scene_path.string()).value();
  const WaterPictures ref = water_pictures(scene, kWaterFrames);
  const double apart = difference(ref.shaded, ref.flat);
  std::printf("water shaded against flat %.2f\n", apart);
  EXPECT_GT(apart, kSameBelow);
  std::vector<std::string> backends = {"openmp"};
  if (has_backend("vulkan")) backends.emplace_back("vulkan");
  for (const std::string& backend : backends) {
    const fs::path png = scratch("water-" + backend + ".png");
    ASSERT_EQ(shell(std::string(MOTES_CLI_PATH) + " view " + scene_path.string() + " --backend " +
                    backend + " --offscreen --no-shadows --size 320x240 --frames " +
                    std::to_string(kWaterFrames) + " --screenshot " + png.string() + " > " +
                    scratch("water-" + backend + ".txt").string()),
              0);
    const Image picture = load_png(png);
    const Image& expected = backend == "openmp" ? ref.shaded : ref.flat;
    const Image& other = backend == "openmp" ? ref.flat : ref.shaded;
    const double same = difference(picture, expected), wrong = difference(picture, other);
    const Eigen::Vector3d mean = mean_where_different(picture, ref.background);
    std::printf(
        "water on %s: %.2f from the headless picture, %.2f from the other look; mean "
        "colour %.0f %.0f %.0f\n",
        backend.c_str(), same, wrong, mean.x(), mean.y(), mean.z());
    EXPECT_LT(same, kSameBelow) << backend;
    EXPECT_GT(wrong, kSameBelow) << backend;
    EXPECT_GT(mean.z(), mean.x() + 40.0) << backend;
    EXPECT_GT(mean.z(), mean.y() + 20.0) << backend;
  }
}

}  // namespace

namespace {

// A soft cube (4 x 4 x 4 particles, shape matching) resting on the floor where kBoxScene's box is,
// and a cloth of 9 x 9 particles lying flat on the floor in front of the same camera (its middle at
// pixel (160, 132) of 320 x 240).
constexpr const char* kSoftScene = R"({
  "settings": { "dt": 0.016666666666666666, "substeps": 16, "contact_model": "position",
                "gravity": [0.0, -9.81, 0.0], "particle_diameter": 0.01 },
  "materials": { "rubber": { "density": 1100.0, "friction": 0.4 } },
  "bodies": [ { "name": "cube", "kind": "soft", "material": "rubber",
                "shape": { "type": "box", "particles": [4, 4, 4] }, "position": [0.0, 0.02, 0.0],
                "soft": { "frequency": 20.0, "damping": 20.0, "mode": "linear" } } ],
  "camera": { "position": [0.0, 0.1, 0.4], "target": [0.0, 0.02, 0.0], "fov": 40.0 },
  "planes": [ { "name": "floor", "normal": [0.0, 1.0, 0.0], "point": [0.0, 0.0, 0.0] } ]
})";

constexpr const char* kClothScene = R"({
  "settings": { "dt": 0.016666666666666666, "substeps": 16, "contact_model": "position",
                "gravity": [0.0, -9.81, 0.0], "particle_diameter": 0.01,
                "constraint_iterations": 2, "link_damping": 1.0 },
  "materials": { "cloth": { "density": 1000.0, "friction": 0.5 } },
  "bodies": [ { "name": "sheet", "kind": "cloth", "material": "cloth",
                "cloth": { "corner": [-0.04, 0.005, -0.04], "edge_u": [0.08, 0.0, 0.0],
                           "edge_v": [0.0, 0.0, 0.08], "particles": [9, 9] } } ],
  "camera": { "position": [0.0, 0.1, 0.4], "target": [0.0, 0.02, 0.0], "fov": 40.0 },
  "planes": [ { "name": "floor", "normal": [0.0, 1.0, 0.0], "point": [0.0, 0.0, 0.0] } ]
})";

Eigen::Vector3d mean_position(const motes::Snapshot& s) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& p : s.particle_pos) sum += Eigen::Vector3d(p.x, p.y, p.z);
  return sum / static_cast<double>(s.particle_pos.size());
}

// A soft body is pulled by the grabbed particle alone (held like a pin and moved towards the
// cursor): its shape matching drags the rest. 60 pixels to the right, as the box: the cube's
// centre moves the right way, the cube keeps its shape, and the saved state has every particle's
// mass back.
TEST(ViewGrab, ShiftDragPullsASoftCubeSideways) {
  const motes::Snapshot still = state_after(kSoftScene, "soft-still", 30, "");
  const motes::Snapshot dragged =
      state_after(kSoftScene, "soft-dragged", 30, "5 drag 165 117 225 117 10 shift\n");
  const Eigen::Vector3d a = mean_position(still), b = mean_position(dragged);
  std::printf("soft cube: moved %.4f m along x, %.4f along z\n", b.x() - a.x(), b.z() - a.z());
  EXPECT_GT(b.x() - a.x(), 0.01);
  // Pulled by one corner particle over a floor with friction, the cube turns (its centre swings
  // towards the line the corner is pulled along: measured 1.6 cm along z), as a box dragged by
  // a corner does; what must hold is its shape: the largest distance between two of its
  // particles (the cube's diagonal, 5.2 cm at rest) stays within a fifth of where it was.
  auto diagonal = [](const motes::Snapshot& s) {
    double d = 0.0;
    for (const auto& p : s.particle_pos) {
      for (const auto& q : s.particle_pos) {
        d = std::max(d, Eigen::Vector3d(p.x - q.x, p.y - q.y, p.z - q.z).norm());
      }
    }
    return d;
  };
  std::printf("soft cube: diagonal %.4f m left alone, %.4f m dragged\n", diagonal(still),
              diagonal(dragged));
  EXPECT_NEAR(diagonal(dragged), diagonal(still), 0.2 * diagonal(still));
  for (std::size_t i = 0; i < dragged.particle_vel.size(); ++i) {
    EXPECT_EQ(dragged.particle_vel[i].w, still.particle_vel[i].w) << "particle " << i;
  }
}

// A cloth lying on the floor, grabbed near its middle and lifted 40 pixels (about 5 cm at its
// depth): the grabbed part rises off the floor and the cloth's other particles follow it up.
TEST(ViewGrab, ShiftDragLiftsACloth) {
  const motes::Snapshot flat = state_after(kClothScene, "cloth-flat", 12, "");
  const motes::Snapshot lifted =
      state_after(kClothScene, "cloth-lifted", 12, "1 drag 160 132 160 92 10 shift\n");
  double top_flat = 0.0, top_lifted = 0.0;
  for (const auto& p : flat.particle_pos) top_flat = std::max(top_flat, double{p.y});
  for (const auto& p : lifted.particle_pos) top_lifted = std::max(top_lifted, double{p.y});
  std::printf("cloth: highest particle %.4f m lying, %.4f m lifted; mean height %.4f, %.4f\n",
              top_flat, top_lifted, mean_position(flat).y(), mean_position(lifted).y());
  EXPECT_LT(top_flat, 0.01);
  EXPECT_GT(top_lifted, 0.025);
  EXPECT_GT(mean_position(lifted).y(), mean_position(flat).y() + 0.002);
}

}  // namespace
