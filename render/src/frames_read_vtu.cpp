// Reading back the VTU frames motes writes (binary appended raw, UInt64 headers, native order).
#include <fmt/format.h>

#include <bit>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "frames_read.h"

namespace motes::render::detail {

namespace {

/// One VTU file in memory, its arrays found by name.
class VtuFile {
 public:
  static Result<VtuFile> read(const std::string& path) {
    VtuFile f;
    f.path_ = path;
    std::ifstream in(path, std::ios::binary);
    if (!in) return Status::error(fmt::format("cannot read '{}': {}", path, std::strerror(errno)));
    std::stringstream text;
    text << in.rdbuf();
    f.bytes_ = text.str();
    const std::size_t appended = f.bytes_.find("<AppendedData encoding=\"raw\">");
    const std::size_t head_end = f.bytes_.find("<AppendedData");
    if (head_end == std::string::npos || appended != head_end ||
        f.bytes_.find("header_type=\"UInt64\"") > head_end ||
        f.bytes_.find("type=\"UnstructuredGrid\"") > head_end) {
      return Status::error(fmt::format(
          "'{}': not a VTU file as motes writes them (an UnstructuredGrid with raw appended data "
          "and UInt64 headers)",
          path));
    }
    const char* order = std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
    if (f.bytes_.find(fmt::format("byte_order=\"{}\"", order)) > head_end) {
      return Status::error(fmt::format("'{}': written with the other byte order", path));
    }
    f.data_ = f.bytes_.find('_', appended);
    if (f.data_ == std::string::npos) {
      return Status::error(fmt::format("'{}': truncated (no appended data)", path));
    }
    ++f.data_;
    f.header_ = f.bytes_.substr(0, head_end);
    const std::size_t piece = f.header_.find("<Piece");
    const std::string points = piece == std::string::npos
                                   ? std::string()
                                   : attribute(f.header_.substr(piece, 200), "NumberOfPoints");
    char* end = nullptr;
    f.points_ = std::strtoull(points.c_str(), &end, 10);
    if (points.empty() || *end != '\0') {
      return Status::error(fmt::format("'{}': no NumberOfPoints in its <Piece>", path));
    }
    // The Points array alone holds 12 bytes per point: a larger count is a corrupt file, refused
    // before anything is allocated for it.
    if (f.points_ > f.bytes_.size() / 12) {
      return Status::error(fmt::format("'{}': NumberOfPoints {} does not fit in its {} bytes", path,
                                       points, f.bytes_.size()));
    }
    return f;
  }

  [[nodiscard]] std::size_t points() const { return points_; }

  /// The bytes of array `name` (of `type`), which must hold `expected` bytes; false when absent.
  Result<bool> array(const std::string& name, const std::string& type, std::size_t expected,
                     void* out) const {
    const std::string key = fmt::format("Name=\"{}\"", name);
    const std::size_t at = header_.find(key);
    if (at == std::string::npos) return false;
    const std::size_t open = header_.rfind('<', at);
    const std::size_t close = header_.find('>', at);
    if (open == std::string::npos || close == std::string::npos) {
      return Status::error(
          fmt::format("'{}': array \"{}\" is not named inside a tag", path_, name));
    }
    const std::string tag = header_.substr(open, close - open);
    if (attribute(tag, "type") != type || attribute(tag, "format") != "appended") {
      return Status::error(
          fmt::format("'{}': array \"{}\" is not {} in appended format", path_, name, type));
    }
    const std::size_t offset = std::strtoull(attribute(tag, "offset").c_str(), nullptr, 10);
    std::uint64_t size = 0;
    // offset is compared before it is added: a huge one must not wrap around to a small start.
    if (offset > bytes_.size() - data_ || bytes_.size() - data_ - offset < sizeof size) {
      return Status::error(fmt::format("'{}': truncated at array \"{}\"", path_, name));
    }
    const std::size_t start = data_ + offset;
    std::memcpy(&size, bytes_.data() + start, sizeof size);
    if (size != expected || bytes_.size() - start - sizeof size < size) {
      return Status::error(fmt::format("'{}': array \"{}\" is truncated or has {} bytes, not {}",
                                       path_, name, size, expected));
    }
    // A file of 0 points has empty arrays: `out` is then the null data() of an empty vector.
    if (expected > 0) std::memcpy(out, bytes_.data() + start + sizeof size, expected);
    return true;
  }

 private:
  std::string path_;
  std::string bytes_;
  std::string header_;
  std::size_t data_ = 0;
  std::size_t points_ = 0;
};

class VtuFrames final : public FrameReader {
 public:
  VtuFrames(std::string source, std::vector<std::string> files)
      : source_(std::move(source)), files_(std::move(files)) {}

  Result<bool> next(Snapshot& frame) override {
    if (next_ >= files_.size()) return false;
    const std::string& path = files_[next_];
    Result<VtuFile> file = VtuFile::read(path);
    if (!file) return file.status();
    const std::size_t n = file->points();
    std::vector<float> floats(3 * n);
    frame = Snapshot{};
    frame.step = next_;
    Result<bool> got = file->array("Points", "Float32", 12 * n, floats.data());
    if (!got) return got.status();
    if (!got.value()) return Status::error(fmt::format("'{}': no \"Points\" array", path));
    frame.particle_pos.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      frame.particle_pos[i] = shared::vec4(floats[3 * i], floats[3 * i + 1], floats[3 * i + 2], 0);
    }
    frame.particle_vel.assign(n, shared::vec4(0.0f));
    got = file->array("velocity", "Float32", 12 * n, floats.data());
    if (!got) return got.status();
    if (got.value()) {
      for (std::size_t i = 0; i < n; ++i) {
        frame.particle_vel[i] =
            shared::vec4(floats[3 * i], floats[3 * i + 1], floats[3 * i + 2], 0);
      }
    }
    got = file->array("radius", "Float32", 4 * n, floats.data());
    if (!got) return got.status();
    if (!got.value()) return Status::error(fmt::format("'{}': no \"radius\" array", path));
    for (std::size_t i = 0; i < n; ++i) frame.particle_pos[i].w = floats[i];
    frame.particle_body.assign(n, 0U);
    got = file->array("body", "UInt32", 4 * n, frame.particle_body.data());
    if (!got) return got.status();
    double time = 0.0;
    got = file->array("TimeValue", "Float64", 8, &time);
    if (!got) return got.status();
    frame.time = time;
    ++next_;
    return true;
  }

  Status rewind() override {
    next_ = 0;
    return Status::ok();
  }
  [[nodiscard]] const std::string& source() const override { return source_; }

 private:
  std::string source_;
  std::vector<std::string> files_;
  std::size_t next_ = 0;
};

}  // namespace

Result<std::unique_ptr<FrameReader>> open_vtu_frames(std::string source,
                                                     std::vector<std::string> files) {
  return std::unique_ptr<FrameReader>(
      std::make_unique<VtuFrames>(std::move(source), std::move(files)));
}

}  // namespace motes::render::detail
