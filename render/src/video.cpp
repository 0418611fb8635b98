// Video through an ffmpeg child process: raw RGB frames into its stdin, an H.264 MP4 out.
#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string_view>
#include <vector>

#include "motes/render_output.h"

extern char** environ;

namespace motes::render {

namespace {

constexpr double kMinFps = 1.0;
constexpr double kMaxFps = 60.0;

bool is_executable_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(path.c_str(), X_OK) == 0;
}

}  // namespace

FrameRate frame_rate_for_interval(double interval) {
  FrameRate rate;
  if (!(interval > 0.0) || !std::isfinite(interval)) {
    rate.fps = 30.0;
    rate.note = "no frame interval known: 30 fps";
    return rate;
  }
  const double real = 1.0 / interval;
  rate.fps = std::clamp(real, kMinFps, kMaxFps);
  if (rate.fps != real) {
    const double speed = rate.fps / real;  // > 1: faster than real time
    rate.note = fmt::format(
        "frames {:.4g} s apart are {:.4g} per simulated second, clamped to {:g} fps: the video "
        "plays {:.3g}x {} than real time",
        interval, real, rate.fps, speed > 1.0 ? speed : 1.0 / speed,
        speed > 1.0 ? "faster" : "slower");
  }
  return rate;
}

std::optional<std::string> find_program(const std::string& name) {
  if (name.find('/') != std::string::npos) {
    if (is_executable_file(name)) return name;
    return std::nullopt;
  }
  const char* path = std::getenv("PATH");
  if (path == nullptr) return std::nullopt;
  std::string_view rest(path);
  while (true) {
    const std::size_t colon = rest.find(':');
    const std::filesystem::path dir(colon == 0 ? std::string_view(".") : rest.substr(0, colon));
    const std::string candidate = (dir / name).string();
    if (is_executable_file(candidate)) return candidate;
    if (colon == std::string_view::npos) break;
    rest.remove_prefix(colon + 1);
  }
  return std::nullopt;
}

std::optional<std::string> find_ffmpeg() {
  if (const char* chosen = std::getenv("MOTES_FFMPEG"); chosen != nullptr) {
    if (*chosen == '\0') return std::nullopt;
    return find_program(chosen);
  }
  return find_program("ffmpeg");
}

Result<std::unique_ptr<VideoEncoder>> VideoEncoder::open(const std::string& ffmpeg,
                                                         const std::string& path, Size size,
                                                         double fps) {
  // A dead ffmpeg must show up as EPIPE from write(), not end motes by SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
  const std::vector<std::string> args = {
      ffmpeg, "-hide_banner", "-loglevel", "error", "-y",
      // Input: raw frames on stdin.
      "-f", "rawvideo", "-pix_fmt", "rgb24", "-video_size",
      fmt::format("{}x{}", size.width, size.height), "-framerate", fmt::format("{}", fps), "-i",
      "-",
      // Output: H.264 in yuv420p (what every player reads), even sizes for 4:2:0.
      "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-preset", "medium", "-crf", "20",
      "-pix_fmt", "yuv420p", "-movflags", "+faststart", path};
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    return Status::error(
        fmt::format("cannot start ffmpeg for '{}': pipe: {}", path, std::strerror(errno)));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, ffmpeg.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (spawned != 0) {
    ::close(fds[1]);
    return Status::error(
        fmt::format("cannot start '{}' for '{}': {}", ffmpeg, path, std::strerror(spawned)));
  }
  auto encoder = std::unique_ptr<VideoEncoder>(new VideoEncoder());
  encoder->path_ = path;
  encoder->size_ = size;
  encoder->pid_ = pid;
  encoder->fd_ = fds[1];
  return encoder;
}

VideoEncoder::~VideoEncoder() { (void)finish(); }

Status VideoEncoder::add_frame(const Image& image) {
  if (!failed_) return failed_;
  if (fd_ < 0) return Status::error(fmt::format("cannot write video '{}': closed", path_));
  if (image.width != size_.width || image.height != size_.height) {
    return Status::error(fmt::format("cannot write video '{}': a {}x{} frame in a {}x{} video",
                                     path_, image.width, image.height, size_.width, size_.height));
  }
  const std::uint8_t* data = image.rgb.data();
  std::size_t left = image.rgb.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, data, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      failed_ = Status::error(fmt::format(
          "cannot write video '{}': ffmpeg stopped reading frames ({}); see its message above",
          path_, std::strerror(errno)));
      return failed_;
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  ++frames_;
  return Status::ok();
}

Status VideoEncoder::finish() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (pid_ > 0) {
    int status = 0;
    pid_t waited;
    do {
      waited = ::waitpid(pid_, &status, 0);
    } while (waited < 0 && errno == EINTR);
    pid_ = -1;
    if (waited < 0) {
      failed_ = Status::error(fmt::format("cannot write video '{}': waiting for ffmpeg: {}", path_,
                                          std::strerror(errno)));
    } else if (WIFSIGNALED(status)) {
      failed_ = Status::error(fmt::format("cannot write video '{}': ffmpeg was killed by signal {}",
                                          path_, WTERMSIG(status)));
    } else if (WIFEXITED(status) && WEXITSTATUS(status) != 0) {
      failed_ = Status::error(fmt::format(
          "cannot write video '{}': ffmpeg failed with exit status {} (its message is above)",
          path_, WEXITSTATUS(status)));
    }
  }
  return failed_;
}

}  // namespace motes::render
