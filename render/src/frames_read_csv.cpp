// Reading back particles.csv (frame,time,particle,body,x,y,z,vx,vy,vz), one frame at a time.
#include <fmt/format.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <optional>
#include <string_view>

#include "frames_read.h"

namespace motes::render::detail {

namespace {

constexpr std::string_view kHeader = "frame,time,particle,body,x,y,z,vx,vy,vz";

struct Row {
  std::uint64_t frame = 0;
  double time = 0.0;
  std::uint32_t body = 0;
  std::array<float, 6> values{};  // x, y, z, vx, vy, vz
};

template <typename T>
bool parse_field(std::string_view text, T& value) {
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  return ec == std::errc() && ptr == end;
}

bool parse_row(std::string_view line, Row& row) {
  std::array<std::string_view, 10> fields;
  std::size_t count = 0;
  while (count < fields.size()) {
    const std::size_t comma = line.find(',');
    fields[count++] = line.substr(0, comma);
    if (comma == std::string_view::npos) break;
    line.remove_prefix(comma + 1);
  }
  if (count != fields.size() || fields[9].find(',') != std::string_view::npos) return false;
  std::uint64_t particle = 0;
  if (!parse_field(fields[0], row.frame) || !parse_field(fields[1], row.time) ||
      !parse_field(fields[2], particle) || !parse_field(fields[3], row.body)) {
    return false;
  }
  for (std::size_t i = 0; i < 6; ++i) {
    if (!parse_field(fields[4 + i], row.values[i])) return false;
  }
  return true;
}

class CsvFrames final : public FrameReader {
 public:
  CsvFrames(std::string path, double radius) : path_(std::move(path)), radius_(radius) {}

  Status rewind() override {
    in_ = std::ifstream(path_, std::ios::binary);
    if (!in_)
      return Status::error(fmt::format("cannot read '{}': {}", path_, std::strerror(errno)));
    std::string header;
    std::getline(in_, header);
    if (!header.empty() && header.back() == '\r') header.pop_back();
    if (header != kHeader) {
      return Status::error(
          fmt::format("'{}':1: expected the header \"{}\", as motes run writes", path_, kHeader));
    }
    line_ = 1;
    pending_.reset();
    return Status::ok();
  }

  Result<bool> next(Snapshot& frame) override {
    frame = Snapshot{};
    std::optional<std::uint64_t> number;
    std::string line;
    while (true) {
      Row row;
      if (pending_) {
        row = *pending_;
        pending_.reset();
      } else {
        if (!std::getline(in_, line)) break;
        ++line_;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        if (!parse_row(line, row)) {
          return Status::error(
              fmt::format("'{}':{}: expected 10 numbers: frame,time,particle,body,x,y,z,vx,vy,vz",
                          path_, line_));
        }
      }
      if (number && row.frame != *number) {
        pending_ = row;
        break;
      }
      number = row.frame;
      frame.time = row.time;
      frame.step = row.frame;
      frame.particle_pos.emplace_back(row.values[0], row.values[1], row.values[2], 0.0f);
      frame.particle_vel.emplace_back(row.values[3], row.values[4], row.values[5], 0.0f);
      frame.particle_body.push_back(row.body);
    }
    if (in_.bad()) {
      return Status::error(fmt::format("cannot read '{}': {}", path_, std::strerror(errno)));
    }
    if (!number) return false;
    if (!(radius_ > 0.0)) radius_ = static_cast<double>(typical_radius(frame.particle_pos));
    for (shared::vec4& p : frame.particle_pos) p.w = static_cast<float>(radius_);
    return true;
  }

  [[nodiscard]] const std::string& source() const override { return path_; }

 private:
  std::string path_;
  double radius_;
  std::ifstream in_;
  std::size_t line_ = 0;
  std::optional<Row> pending_;
};

}  // namespace

Result<std::unique_ptr<FrameReader>> open_csv_frames(const std::string& path, double radius) {
  auto reader = std::make_unique<CsvFrames>(path, radius);
  if (Status s = reader->rewind(); !s) return s;
  return std::unique_ptr<FrameReader>(std::move(reader));
}

}  // namespace motes::render::detail
