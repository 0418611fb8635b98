// CSV output: one file, one row per particle per frame, for scripts (docs/cli.md).
#include <fmt/format.h>

#include <filesystem>
#include <iterator>
#include <utility>

#include "motes/output.h"
#include "output_file.h"

namespace motes {
namespace {

using output::OutputFile;

// Rows are formatted into a buffer and written in pieces of about this size.
constexpr std::size_t kChunkBytes = std::size_t{1} << 20;

class CsvWriter final : public FrameWriter {
 public:
  explicit CsvWriter(OutputFile file) : file_(std::move(file)), path_(file_.path()) {}

  Status write_frame(const Snapshot& s) override {
    if (Status st = output::check_snapshot(s); !st) return st;
    if (!file_.is_open()) return Status::error(fmt::format("cannot write '{}': closed", path_));
    fmt::memory_buffer buf;
    const std::size_t frame = frames_;
    for (std::size_t i = 0; i < s.particle_pos.size(); ++i) {
      const shared::vec4& p = s.particle_pos[i];
      const shared::vec4& v = s.particle_vel[i];
      // {} prints the shortest text that reads back to the same float (or double, for time).
      fmt::format_to(std::back_inserter(buf), "{},{},{},{},{},{},{},{},{},{}\n", frame, s.time, i,
                     s.particle_body[i], p.x, p.y, p.z, v.x, v.y, v.z);
      if (buf.size() >= kChunkBytes) {
        if (Status st = file_.write(buf.data(), buf.size()); !st) return st;
        buf.clear();
      }
    }
    if (Status st = file_.write(buf.data(), buf.size()); !st) return st;
    if (Status st = file_.flush(); !st) return st;
    ++frames_;
    return Status::ok();
  }

  Status finish() override { return file_.close(); }
  [[nodiscard]] std::size_t frames() const override { return frames_; }
  [[nodiscard]] const std::string& main_path() const override { return path_; }

 private:
  OutputFile file_;
  std::string path_;
  std::size_t frames_ = 0;
};

}  // namespace

Result<std::unique_ptr<FrameWriter>> open_csv_writer(const std::string& dir) {
  if (Status s = create_output_directory(dir); !s) return s;
  auto opened = OutputFile::create((std::filesystem::path(dir) / "particles.csv").string());
  if (!opened) return opened.status();
  OutputFile file = std::move(opened).value();
  if (Status s = file.write(std::string("frame,time,particle,body,x,y,z,vx,vy,vz\n")); !s) return s;
  if (Status s = file.flush(); !s) return s;
  return std::unique_ptr<FrameWriter>(std::make_unique<CsvWriter>(std::move(file)));
}

Status write_points_csv(const std::string& path, const std::vector<Eigen::Vector3f>& points) {
  auto opened = OutputFile::create(path);
  if (!opened) return opened.status();
  OutputFile file = std::move(opened).value();
  fmt::memory_buffer buf;
  fmt::format_to(std::back_inserter(buf), "x,y,z\n");
  for (const Eigen::Vector3f& p : points) {
    fmt::format_to(std::back_inserter(buf), "{},{},{}\n", p.x(), p.y(), p.z());
    if (buf.size() >= kChunkBytes) {
      if (Status s = file.write(buf.data(), buf.size()); !s) return s;
      buf.clear();
    }
  }
  if (Status s = file.write(buf.data(), buf.size()); !s) return s;
  return file.close();
}

}  // namespace motes
