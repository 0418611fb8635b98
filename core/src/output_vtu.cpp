// VTU output: one UnstructuredGrid of VTK_VERTEX cells per frame, binary appended raw encoding,
// and a .pvd collection that lists the frames with their simulated times.
#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <utility>
#include <vector>

#include "motes/output.h"
#include "output_file.h"

namespace motes {
namespace {

using output::OutputFile;

constexpr std::uint8_t kVtkVertex = 1;

/// One DataArray of the appended section.
struct ArrayDecl {
  const char* name;
  const char* type;
  int components;
  std::size_t bytes;
};

const char* byte_order() {
  return std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
}

/// Each appended block is a UInt64 byte count followed by the bytes.
Status write_block(OutputFile& file, const void* data, std::size_t bytes) {
  const std::uint64_t header = bytes;
  if (Status s = file.write(&header, sizeof header); !s) return s;
  return file.write(data, bytes);
}

template <typename T>
Status write_block(OutputFile& file, const std::vector<T>& values) {
  return write_block(file, values.data(), values.size() * sizeof(T));
}

template <typename Int>
Status write_cells(OutputFile& file, std::size_t n) {
  std::vector<Int> ids(n);
  for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<Int>(i);
  if (Status s = write_block(file, ids); !s) return s;
  for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<Int>(i + 1);  // end of each cell
  if (Status s = write_block(file, ids); !s) return s;
  const std::vector<std::uint8_t> types(n, kVtkVertex);
  return write_block(file, types);
}

/// The XML before the appended data: every DataArray with its offset into that data.
std::string vtu_header(const Snapshot& s, bool wide_ids) {
  const std::size_t n = s.particle_pos.size();
  const std::size_t id_bytes = wide_ids ? 8 : 4;
  const char* id_type = wide_ids ? "Int64" : "Int32";
  const ArrayDecl arrays[] = {
      {"TimeValue", "Float64", 1, 8},
      {"Points", "Float32", 3, 12 * n},
      {"connectivity", id_type, 1, id_bytes * n},
      {"offsets", id_type, 1, id_bytes * n},
      {"types", "UInt8", 1, n},
      {"velocity", "Float32", 3, 12 * n},
      {"radius", "Float32", 1, 4 * n},
      {"body", "UInt32", 1, 4 * n},
      {"speed", "Float32", 1, 4 * n},
  };
  std::size_t offsets[std::size(arrays)];
  std::size_t at = 0;
  for (std::size_t i = 0; i < std::size(arrays); ++i) {
    offsets[i] = at;
    at += sizeof(std::uint64_t) + arrays[i].bytes;
  }
  auto array = [&](std::size_t i, const char* indent) {
    const ArrayDecl& a = arrays[i];
    const std::string components =
        a.components > 1 ? fmt::format(" NumberOfComponents=\"{}\"", a.components) : "";
    const std::string tuples = i == 0 ? " NumberOfTuples=\"1\"" : "";
    return fmt::format(
        "{}<DataArray type=\"{}\" Name=\"{}\"{}{} format=\"appended\" offset=\"{}\"/>\n", indent,
        a.type, a.name, components, tuples, offsets[i]);
  };
  const char* in4 = "        ";
  std::string x;
  x += "<?xml version=\"1.0\"?>\n";
  x += fmt::format(
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"{}\" "
      "header_type=\"UInt64\">\n",
      byte_order());
  x += "  <UnstructuredGrid>\n";
  x += "    <FieldData>\n" + array(0, "      ") + "    </FieldData>\n";
  x += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", n, n);
  x += "      <Points>\n" + array(1, in4) + "      </Points>\n";
  x += "      <Cells>\n" + array(2, in4) + array(3, in4) + array(4, in4) + "      </Cells>\n";
  x += "      <PointData Vectors=\"velocity\" Scalars=\"speed\">\n";
  for (std::size_t i = 5; i < std::size(arrays); ++i) x += array(i, in4);
  x += "      </PointData>\n";
  x += "    </Piece>\n";
  x += "  </UnstructuredGrid>\n";
  // Readers skip to the first '_' after this tag; the raw bytes follow it.
  x += "  <AppendedData encoding=\"raw\">\n   _";
  return x;
}

Status write_vtu(const std::string& path, const Snapshot& s) {
  if (Status st = output::check_snapshot(s); !st) return st;
  const std::size_t n = s.particle_pos.size();
  const bool wide_ids = n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());

  auto opened = OutputFile::create(path);
  if (!opened) return opened.status();
  OutputFile file = std::move(opened).value();

  if (Status st = file.write(vtu_header(s, wide_ids)); !st) return st;
  const double time = s.time;
  if (Status st = write_block(file, &time, sizeof time); !st) return st;

  std::vector<float> floats(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    floats[3 * i + 0] = s.particle_pos[i].x;
    floats[3 * i + 1] = s.particle_pos[i].y;
    floats[3 * i + 2] = s.particle_pos[i].z;
  }
  if (Status st = write_block(file, floats); !st) return st;
  if (Status st =
          wide_ids ? write_cells<std::int64_t>(file, n) : write_cells<std::int32_t>(file, n);
      !st) {
    return st;
  }
  for (std::size_t i = 0; i < n; ++i) {
    floats[3 * i + 0] = s.particle_vel[i].x;
    floats[3 * i + 1] = s.particle_vel[i].y;
    floats[3 * i + 2] = s.particle_vel[i].z;
  }
  if (Status st = write_block(file, floats); !st) return st;
  floats.resize(n);
  for (std::size_t i = 0; i < n; ++i) floats[i] = s.particle_pos[i].w;
  if (Status st = write_block(file, floats); !st) return st;
  if (Status st = write_block(file, s.particle_body); !st) return st;
  for (std::size_t i = 0; i < n; ++i) {
    const shared::vec4& v = s.particle_vel[i];
    const double vx = v.x, vy = v.y, vz = v.z;
    floats[i] = static_cast<float>(std::sqrt(vx * vx + vy * vy + vz * vz));
  }
  if (Status st = write_block(file, floats); !st) return st;

  if (Status st = file.write(std::string("\n  </AppendedData>\n</VTKFile>\n")); !st) return st;
  return file.close();
}

class VtuWriter final : public FrameWriter {
 public:
  explicit VtuWriter(std::string dir)
      : dir_(std::move(dir)), pvd_path_((std::filesystem::path(dir_) / "particles.pvd").string()) {}

  Status write_frame(const Snapshot& snapshot) override {
    const std::string name = fmt::format("particles_{:06}.vtu", frames_.size());
    const std::string path = (std::filesystem::path(dir_) / name).string();
    if (Status s = write_vtu(path, snapshot); !s) return s;
    frames_.emplace_back(snapshot.time, name);
    return write_collection();
  }

  Status finish() override { return Status::ok(); }
  [[nodiscard]] std::size_t frames() const override { return frames_.size(); }
  [[nodiscard]] const std::string& main_path() const override { return pvd_path_; }

  /// Writes the .pvd beside the frames, then renames it over the old one.
  Status write_collection() {
    std::string x;
    x += "<?xml version=\"1.0\"?>\n";
    x += fmt::format("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"{}\">\n",
                     byte_order());
    x += "  <Collection>\n";
    for (const auto& [time, name] : frames_) {
      x += fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>\n", time,
                       name);
    }
    x += "  </Collection>\n</VTKFile>\n";
    const std::string tmp = pvd_path_ + ".tmp";
    auto opened = OutputFile::create(tmp);
    if (!opened) return opened.status();
    OutputFile file = std::move(opened).value();
    if (Status s = file.write(x); !s) return s;
    if (Status s = file.close(); !s) return s;
    return output::replace_file(tmp, pvd_path_);
  }

 private:
  std::string dir_;
  std::string pvd_path_;
  std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace

Result<std::unique_ptr<FrameWriter>> open_vtu_writer(const std::string& dir) {
  if (Status s = create_output_directory(dir); !s) return s;
  auto writer = std::make_unique<VtuWriter>(dir);
  // An empty collection at once: a bad directory fails here, before any step runs.
  if (Status s = writer->write_collection(); !s) return s;
  return std::unique_ptr<FrameWriter>(std::move(writer));
}

Status write_vtu_file(const std::string& path, const Snapshot& snapshot) {
  return write_vtu(path, snapshot);
}

}  // namespace motes
