// RenderOutput: PNG frames and the video of a run in one directory.
#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <system_error>
#include <utility>

#include "motes/output.h"
#include "motes/render_output.h"

namespace motes::render {

RenderOutput::RenderOutput(RenderSettings settings, OutputOptions options)
    : renderer_(std::move(settings)), options_(std::move(options)) {}

RenderOutput::~RenderOutput() { (void)finish(); }

Result<std::unique_ptr<RenderOutput>> RenderOutput::open(RenderSettings settings,
                                                         OutputOptions options) {
  if (Status s = create_output_directory(options.dir, "render"); !s) return s;
  const Size size = settings.size;
  auto out = std::unique_ptr<RenderOutput>(new RenderOutput(std::move(settings), options));
  if (!options.video) {
    out->notice_ = "no video (--no-video)";
    return out;
  }
  const std::optional<std::string> ffmpeg = find_ffmpeg();
  if (!ffmpeg) {
    out->notice_ =
        "no video: ffmpeg was not found on PATH; install it (Debian/Ubuntu: apt-get install "
        "ffmpeg) to get an MP4 next to the PNG frames";
    return out;
  }
  const std::string path = (std::filesystem::path(options.dir) / "video.mp4").string();
  Result<std::unique_ptr<VideoEncoder>> video =
      VideoEncoder::open(*ffmpeg, path, size, options.fps);
  if (!video) return video.status();
  out->video_ = std::move(video).value();
  return out;
}

Status RenderOutput::add_frame(const Snapshot& frame) {
  const auto start = std::chrono::steady_clock::now();
  const Image& image = renderer_.render(frame);
  const std::string name = fmt::format("frame_{:06}.png", frames_);
  const std::string path = (std::filesystem::path(options_.dir) / name).string();
  if (Status s = write_png(path, image); !s) return s;
  if (video_) {
    if (Status s = video_->add_frame(image); !s) return s;
  }
  ++frames_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::ok();
}

Status RenderOutput::finish() {
  if (!video_) return Status::ok();
  const auto start = std::chrono::steady_clock::now();
  Status s = video_->finish();
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

std::string RenderOutput::video_path() const { return video_ ? video_->path() : std::string(); }

}  // namespace motes::render
