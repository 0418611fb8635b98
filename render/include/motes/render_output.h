// Rendered runs on disk: PNG frames in a directory and, when ffmpeg is installed, an H.264 MP4;
// and reading the frames that `motes run --out` wrote back (docs/rendering.md).
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "motes/api.h"
#include "motes/render.h"
#include "motes/simulation.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes::render {

/// The video frame rate for frames `interval` simulated seconds apart: 1 / interval, clamped to
/// 1..60 fps; `note` says when it was clamped and how much faster or slower than real time the
/// video plays (empty when it plays in real time).
struct FrameRate {
  double fps = 30.0;
  std::string note;
};
FrameRate frame_rate_for_interval(double interval);

/// The full path of `name` found on PATH, if any (an executable regular file).
std::optional<std::string> find_program(const std::string& name);

/// The ffmpeg that encodes videos: $MOTES_FFMPEG when set (an empty value: none), else ffmpeg on
/// PATH.
std::optional<std::string> find_ffmpeg();

/// Streams raw RGB frames into an ffmpeg child process that writes an MP4 (H.264 by libx264,
/// yuv420p, odd sizes padded to even). Move-only; the destructor waits for the child.
class VideoEncoder {
 public:
  /// Starts `ffmpeg` writing `path` for frames of `size` at `fps`.
  static Result<std::unique_ptr<VideoEncoder>> open(const std::string& ffmpeg,
                                                    const std::string& path, Size size, double fps);
  ~VideoEncoder();
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  /// Sends one frame (its size must be the size given to open()).
  Status add_frame(const Image& image);
  /// Closes ffmpeg's input and waits for it; an error when it failed (its exit status). Idempotent.
  Status finish();
  [[nodiscard]] std::size_t frames() const { return frames_; }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  VideoEncoder() = default;
  std::string path_;
  Size size_;
  int pid_ = -1;
  int fd_ = -1;
  std::size_t frames_ = 0;
  Status failed_;
};

/// How a rendered run is written.
struct OutputOptions {
  std::string dir;    ///< created if missing: frame_000000.png, ... and video.mp4
  bool video = true;  ///< encode video.mp4 when ffmpeg is found
  double fps = 30.0;  ///< video frame rate
};

/// PNG frames plus the video of a run. Every error names the file.
class RenderOutput {
 public:
  /// Creates the directory and, when asked and ffmpeg is found, starts the encoder. Without
  /// ffmpeg, `notice()` says how to get it and only PNGs are written.
  static Result<std::unique_ptr<RenderOutput>> open(RenderSettings settings, OutputOptions options);
  ~RenderOutput();
  RenderOutput(const RenderOutput&) = delete;
  RenderOutput& operator=(const RenderOutput&) = delete;

  /// Renders a frame, writes its PNG and sends it to the video.
  Status add_frame(const Snapshot& frame);
  /// Ends the video (waits for ffmpeg). Idempotent.
  Status finish();

  [[nodiscard]] std::size_t frames() const { return frames_; }
  /// The video's path, or empty when no video is written.
  [[nodiscard]] std::string video_path() const;
  /// A line for the user about the video: why there is none, or none needed.
  [[nodiscard]] const std::string& notice() const { return notice_; }
  [[nodiscard]] const std::string& dir() const { return options_.dir; }
  /// Seconds spent rendering, writing PNGs and encoding so far.
  [[nodiscard]] double seconds() const { return seconds_; }

 private:
  RenderOutput(RenderSettings settings, OutputOptions options);
  FrameRenderer renderer_;
  OutputOptions options_;
  std::unique_ptr<VideoEncoder> video_;
  std::string notice_;
  std::size_t frames_ = 0;
  double seconds_ = 0.0;
};

/// The frames `motes run --out DIR` wrote, read back one at a time: VTU files (listed by
/// particles.pvd, or particles_*.vtu in name order) or particles.csv. CSV has no radius: each
/// frame's radius is `csv_radius` when > 0, else half the typical nearest-neighbour distance of
/// the first frame.
class FrameReader {
 public:
  /// `path`: a result directory, a .pvd file or a .csv file.
  static Result<std::unique_ptr<FrameReader>> open(const std::string& path,
                                                   double csv_radius = 0.0);
  virtual ~FrameReader() = default;
  FrameReader(const FrameReader&) = delete;
  FrameReader& operator=(const FrameReader&) = delete;

  /// Reads the next frame into `frame` (positions with radius, velocities, body ids, time);
  /// false at the end.
  virtual Result<bool> next(Snapshot& frame) = 0;
  /// Starts again at the first frame.
  virtual Status rewind() = 0;
  /// What is being read (a file name, for messages).
  [[nodiscard]] virtual const std::string& source() const = 0;

 protected:
  FrameReader() = default;
};

}  // namespace motes::render
MOTES_API_END
