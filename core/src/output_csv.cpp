// CSV output: one file, one row per particle per frame, for scripts (docs/cli.md).
#include <fmt/format.h>

#include <filesystem>
#include <iterator>
#include <system_error>
#include <utility>

#include "motes/output.h"
#include "output_file.h"

namespace motes {
namespace {

using output::OutputFile;

// Rows are formatted into a buffer and written in pieces of about this size.
constexpr std::size_t kChunkBytes = std::size_t{1} << 20;

/// A CSV field: as is, or in double quotes (inner quotes doubled) when it holds a comma, a quote
/// or a line break (RFC 4180).
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

/// Writes `buf` to `file` once it holds a chunk (or always, with `force`).
Status drain(OutputFile& file, fmt::memory_buffer& buf, bool force) {
  if (!force && buf.size() < kChunkBytes) return Status::ok();
  if (Status st = file.write(buf.data(), buf.size()); !st) return st;
  buf.clear();
  return Status::ok();
}

class CsvWriter final : public FrameWriter {
 public:
  CsvWriter(OutputFile file, OutputFile bodies, std::vector<std::string> body_names,
            std::size_t frames = 0)
      : file_(std::move(file)),
        bodies_(std::move(bodies)),
        path_(file_.path()),
        body_names_(std::move(body_names)),
        frames_(frames) {}

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
    buf.clear();
    for (std::size_t b = 0; b < s.body_pos.size(); ++b) {
      const shared::vec4& x = s.body_pos[b];
      const shared::vec4& q = s.body_quat[b];
      const shared::vec4& v = s.body_vel[b];
      const shared::vec4& w = s.body_angvel[b];
      fmt::format_to(std::back_inserter(buf),
                     "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", frame, s.time, b,
                     b < body_names_.size() ? csv_field(body_names_[b]) : "", x.x, x.y, x.z, q.x,
                     q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z);
      if (Status st = drain(bodies_, buf, false); !st) return st;
    }
    if (Status st = drain(bodies_, buf, true); !st) return st;
    if (Status st = bodies_.flush(); !st) return st;
    ++frames_;
    return Status::ok();
  }

  Status finish() override {
    Status a = file_.close();
    Status b = bodies_.close();
    return a ? b : a;
  }
  [[nodiscard]] std::size_t frames() const override { return frames_; }
  [[nodiscard]] const std::string& main_path() const override { return path_; }

 private:
  OutputFile file_;
  OutputFile bodies_;
  std::string path_;
  std::vector<std::string> body_names_;
  std::size_t frames_ = 0;
};

}  // namespace

Result<std::unique_ptr<FrameWriter>> open_csv_writer(const std::string& dir,
                                                     std::vector<std::string> body_names) {
  if (Status s = create_output_directory(dir); !s) return s;
  auto opened = OutputFile::create((std::filesystem::path(dir) / "particles.csv").string());
  if (!opened) return opened.status();
  OutputFile file = std::move(opened).value();
  if (Status s = file.write(std::string("frame,time,particle,body,x,y,z,vx,vy,vz\n")); !s) return s;
  if (Status s = file.flush(); !s) return s;
  auto bodies_opened = OutputFile::create((std::filesystem::path(dir) / "bodies.csv").string());
  if (!bodies_opened) return bodies_opened.status();
  OutputFile bodies = std::move(bodies_opened).value();
  if (Status s =
          bodies.write(std::string("frame,time,body,name,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz\n"));
      !s) {
    return s;
  }
  if (Status s = bodies.flush(); !s) return s;
  return std::unique_ptr<FrameWriter>(
      std::make_unique<CsvWriter>(std::move(file), std::move(bodies), std::move(body_names)));
}

Result<std::unique_ptr<FrameWriter>> output::continue_csv_writer(
    const std::string& dir, std::vector<std::string> body_names, const SeriesState& state) {
  const std::string particles = (std::filesystem::path(dir) / "particles.csv").string();
  const std::string bodies = (std::filesystem::path(dir) / "bodies.csv").string();
  // Both sizes are checked before either file is cut.
  if (Status s = output::check_continuable(particles, state.particles_csv_bytes); !s) return s;
  if (Status s = output::check_continuable(bodies, state.bodies_csv_bytes); !s) return s;
  if (Status s = output::cut_file(particles, state.particles_csv_bytes); !s) return s;
  if (Status s = output::cut_file(bodies, state.bodies_csv_bytes); !s) return s;
  auto file = OutputFile::append(particles);
  if (!file) return file.status();
  auto body_file = OutputFile::append(bodies);
  if (!body_file) return body_file.status();
  return std::unique_ptr<FrameWriter>(
      std::make_unique<CsvWriter>(std::move(file).value(), std::move(body_file).value(),
                                  std::move(body_names), state.frame_times.size()));
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
