// VTU output: one UnstructuredGrid of VTK_VERTEX cells per frame, binary appended raw encoding,
// and a .pvd collection that lists the frames with their simulated times.
#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <system_error>
#include <utility>
#include <vector>

#include "motes/output.h"
#include "output_file.h"

namespace motes {
namespace {

using output::OutputFile;

constexpr std::uint8_t kVtkVertex = 1;

/// x, y, z of every vec4, packed.
std::vector<float> xyz_floats(const std::vector<shared::vec4>& v) {
  std::vector<float> out(3 * v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    out[3 * i + 0] = v[i].x;
    out[3 * i + 1] = v[i].y;
    out[3 * i + 2] = v[i].z;
  }
  return out;
}

/// |xyz| of every vec4, computed in double and rounded to float.
std::vector<float> speeds(const std::vector<shared::vec4>& v) {
  std::vector<float> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const auto x = static_cast<double>(v[i].x), y = static_cast<double>(v[i].y),
               z = static_cast<double>(v[i].z);
    out[i] = static_cast<float>(std::sqrt(x * x + y * y + z * z));
  }
  return out;
}

/// One point-data array of a .vtu file: its name, VTK type, components and raw bytes.
struct PointArray {
  const char* name;
  const char* type;  // "Float32", "UInt32"
  int components;
  const void* data;
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

/// The XML before the appended data: every DataArray with its offset into that data. The
/// appended blocks follow in the same order: TimeValue, Points, connectivity, offsets, types,
/// then the point arrays.
std::string vtu_header(std::size_t n, bool wide_ids, const std::vector<PointArray>& arrays) {
  const std::size_t id_bytes = wide_ids ? 8 : 4;
  const char* id_type = wide_ids ? "Int64" : "Int32";
  struct Decl {
    const char* name;
    const char* type;
    int components;
    std::size_t bytes;
  };
  std::vector<Decl> decls = {
      {"TimeValue", "Float64", 1, 8},
      {"Points", "Float32", 3, 12 * n},
      {"connectivity", id_type, 1, id_bytes * n},
      {"offsets", id_type, 1, id_bytes * n},
      {"types", "UInt8", 1, n},
  };
  for (const PointArray& a : arrays) decls.push_back({a.name, a.type, a.components, a.bytes});
  std::vector<std::size_t> offsets;
  std::size_t at = 0;
  for (const Decl& d : decls) {
    offsets.push_back(at);
    at += sizeof(std::uint64_t) + d.bytes;
  }
  auto array = [&](std::size_t i, const char* indent) {
    const Decl& a = decls[i];
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
  for (std::size_t i = 5; i < decls.size(); ++i) x += array(i, in4);
  x += "      </PointData>\n";
  x += "    </Piece>\n";
  x += "  </UnstructuredGrid>\n";
  // Readers skip to the first '_' after this tag; the raw bytes follow it.
  x += "  <AppendedData encoding=\"raw\">\n   _";
  return x;
}

/// A .vtu of n VTK_VERTEX cells at `points` (xyz of each vec4) with these point arrays.
Status write_point_set(const std::string& path, double time,
                       const std::vector<shared::vec4>& points,
                       const std::vector<PointArray>& arrays) {
  const std::size_t n = points.size();
  const bool wide_ids = n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  auto opened = OutputFile::create(path);
  if (!opened) return opened.status();
  OutputFile file = std::move(opened).value();
  if (Status st = file.write(vtu_header(n, wide_ids, arrays)); !st) return st;
  if (Status st = write_block(file, &time, sizeof time); !st) return st;
  if (Status st = write_block(file, xyz_floats(points)); !st) return st;
  if (Status st =
          wide_ids ? write_cells<std::int64_t>(file, n) : write_cells<std::int32_t>(file, n);
      !st) {
    return st;
  }
  for (const PointArray& a : arrays) {
    if (Status st = write_block(file, a.data, a.bytes); !st) return st;
  }
  if (Status st = file.write(std::string("\n  </AppendedData>\n</VTKFile>\n")); !st) return st;
  return file.close();
}

/// The particles of a snapshot: velocity, radius, body and speed per particle.
Status write_vtu(const std::string& path, const Snapshot& s) {
  if (Status st = output::check_snapshot(s); !st) return st;
  const std::size_t n = s.particle_pos.size();
  const std::vector<float> velocity = xyz_floats(s.particle_vel);
  std::vector<float> radius(n);
  for (std::size_t i = 0; i < n; ++i) radius[i] = s.particle_pos[i].w;
  const std::vector<float> speed = speeds(s.particle_vel);
  return write_point_set(path, s.time, s.particle_pos,
                         {{"velocity", "Float32", 3, velocity.data(), 4 * velocity.size()},
                          {"radius", "Float32", 1, radius.data(), 4 * n},
                          {"body", "UInt32", 1, s.particle_body.data(), 4 * n},
                          {"speed", "Float32", 1, speed.data(), 4 * n}});
}

/// The bodies of a snapshot: a point at each centre of mass with its orientation (quaternion x,
/// y, z, w), velocity, angular velocity, index and speed.
Status write_bodies_vtu(const std::string& path, const Snapshot& s) {
  const std::size_t b = s.body_pos.size();
  std::vector<float> orientation(4 * b);
  for (std::size_t i = 0; i < b; ++i) {
    const shared::vec4& q = s.body_quat[i];
    const float c[4] = {q.x, q.y, q.z, q.w};
    std::copy(c, c + 4, orientation.begin() + static_cast<std::ptrdiff_t>(4 * i));
  }
  const std::vector<float> velocity = xyz_floats(s.body_vel);
  const std::vector<float> angular = xyz_floats(s.body_angvel);
  std::vector<std::uint32_t> index(b);
  for (std::size_t i = 0; i < b; ++i) index[i] = static_cast<std::uint32_t>(i);
  const std::vector<float> speed = speeds(s.body_vel);
  return write_point_set(path, s.time, s.body_pos,
                         {{"orientation", "Float32", 4, orientation.data(), 4 * orientation.size()},
                          {"velocity", "Float32", 3, velocity.data(), 4 * velocity.size()},
                          {"angular_velocity", "Float32", 3, angular.data(), 4 * angular.size()},
                          {"body", "UInt32", 1, index.data(), 4 * b},
                          {"speed", "Float32", 1, speed.data(), 4 * b}});
}

/// A .pvd collection: every frame with its simulated time, written beside the frames and renamed
/// over the old one (an interrupted run still opens).
Status write_collection(const std::string& path,
                        const std::vector<std::pair<double, std::string>>& frames) {
  std::string x;
  x += "<?xml version=\"1.0\"?>\n";
  x += fmt::format("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"{}\">\n",
                   byte_order());
  x += "  <Collection>\n";
  for (const auto& [time, name] : frames) {
    x += fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>\n", time,
                     name);
  }
  x += "  </Collection>\n</VTKFile>\n";
  const std::string tmp = path + ".tmp";
  auto opened = OutputFile::create(tmp);
  if (!opened) return opened.status();
  OutputFile file = std::move(opened).value();
  if (Status s = file.write(x); !s) return s;
  if (Status s = file.close(); !s) return s;
  return output::replace_file(tmp, path);
}

class VtuWriter final : public FrameWriter {
 public:
  explicit VtuWriter(std::string dir)
      : dir_(std::move(dir)),
        pvd_path_((std::filesystem::path(dir_) / "particles.pvd").string()),
        bodies_pvd_path_((std::filesystem::path(dir_) / "bodies.pvd").string()) {}

  Status write_frame(const Snapshot& snapshot) override {
    const std::string name = fmt::format("particles_{:06}.vtu", frames_.size());
    const std::string bodies = fmt::format("bodies_{:06}.vtu", frames_.size());
    if (Status s = write_vtu((std::filesystem::path(dir_) / name).string(), snapshot); !s) {
      return s;
    }
    if (Status s = write_bodies_vtu((std::filesystem::path(dir_) / bodies).string(), snapshot);
        !s) {
      return s;
    }
    frames_.emplace_back(snapshot.time, name);
    body_frames_.emplace_back(snapshot.time, bodies);
    return write_collections();
  }

  /// Lists the first `times.size()` frames of an earlier run in `dir_` (their files must exist):
  /// the next frame is numbered after them.
  Status adopt(const std::vector<double>& times) {
    for (std::size_t k = 0; k < times.size(); ++k) {
      const std::string name = fmt::format("particles_{:06}.vtu", k);
      const std::string bodies = fmt::format("bodies_{:06}.vtu", k);
      for (const std::string& file : {name, bodies}) {
        const std::filesystem::path path = std::filesystem::path(dir_) / file;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec)) {
          return Status::error(fmt::format(
              "cannot continue the series in '{}': '{}' (frame {} of {} written before the "
              "checkpoint) is missing",
              dir_, path.string(), k, times.size()));
        }
      }
      frames_.emplace_back(times[k], name);
      body_frames_.emplace_back(times[k], bodies);
    }
    return Status::ok();
  }

  Status finish() override { return Status::ok(); }
  [[nodiscard]] std::size_t frames() const override { return frames_.size(); }
  [[nodiscard]] const std::string& main_path() const override { return pvd_path_; }

  /// Both .pvd series: particles.pvd and bodies.pvd.
  Status write_collections() {
    if (Status s = write_collection(pvd_path_, frames_); !s) return s;
    return write_collection(bodies_pvd_path_, body_frames_);
  }

 private:
  std::string dir_;
  std::string pvd_path_;
  std::string bodies_pvd_path_;
  std::vector<std::pair<double, std::string>> frames_;
  std::vector<std::pair<double, std::string>> body_frames_;
};

}  // namespace

Result<std::unique_ptr<FrameWriter>> open_vtu_writer(const std::string& dir) {
  if (Status s = create_output_directory(dir); !s) return s;
  auto writer = std::make_unique<VtuWriter>(dir);
  // Empty collections at once: a bad directory fails here, before any step runs.
  if (Status s = writer->write_collections(); !s) return s;
  return std::unique_ptr<FrameWriter>(std::move(writer));
}

Result<std::unique_ptr<FrameWriter>> output::continue_vtu_writer(const std::string& dir,
                                                                 const std::vector<double>& times) {
  auto writer = std::make_unique<VtuWriter>(dir);
  if (Status s = writer->adopt(times); !s) return s;
  if (Status s = writer->write_collections(); !s) return s;
  return std::unique_ptr<FrameWriter>(std::move(writer));
}

Status write_vtu_file(const std::string& path, const Snapshot& snapshot) {
  return write_vtu(path, snapshot);
}

}  // namespace motes
