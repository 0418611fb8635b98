// Output files: per-frame VTU files with a .pvd series (ParaView), and CSV (scripts).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "motes/api.h"
#include "motes/simulation.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes {

/// What `motes run --format` writes.
enum class OutputFormat { Vtu, Csv, None };

/// "vtu", "csv" or "none"; anything else is an error naming the value.
Result<OutputFormat> parse_output_format(const std::string& name);
/// The name parse_output_format() accepts for `format`.
const char* output_format_name(OutputFormat format);

/// Receives the frames of a run, one Snapshot each. Frames are numbered 0, 1, 2... in call order.
/// Every error is a Status whose message names the file or directory involved.
class FrameWriter {
 public:
  FrameWriter() = default;
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;
  virtual ~FrameWriter() = default;

  /// Writes the next frame. After it returns ok, the frame is complete on disk.
  virtual Status write_frame(const Snapshot& snapshot) = 0;
  /// Closes the files; reports any error that closing revealed. Idempotent.
  virtual Status finish() = 0;
  /// Frames written so far.
  [[nodiscard]] virtual std::size_t frames() const = 0;
  /// The file a user opens to see the run: the .pvd series or the .csv file.
  [[nodiscard]] virtual const std::string& main_path() const = 0;
};

/// Two VTU series in `dir` (created if missing): particles_000000.vtu, particles_000001.vtu, ...
/// with particles.pvd, and bodies_000000.vtu, ... with bodies.pvd, each .pvd listing every frame
/// with its simulated time. The .pvd files are rewritten (atomically, by rename) after each
/// frame, so an interrupted run still opens in ParaView.
///
/// Each .vtu is an UnstructuredGrid of VTK_VERTEX cells in binary appended raw encoding
/// (header_type UInt64, the machine's byte order); field data "TimeValue" (Float64) holds the
/// simulated time. Particles: one point per particle at its centre (Float32); point data
/// "velocity" (Float32 x 3), "radius" (Float32), "body" (UInt32 body index) and "speed" (Float32:
/// the length of the velocity, computed in double and rounded to float). Bodies: one point per
/// body at its centre of mass; point data "orientation" (Float32 x 4: the quaternion x, y, z, w,
/// body frame to world), "velocity", "angular_velocity" (Float32 x 3, world), "body" (UInt32) and
/// "speed".
Result<std::unique_ptr<FrameWriter>> open_vtu_writer(const std::string& dir);

/// CSV files in `dir` (created if missing): particles.csv, one row per particle per frame, with
/// the header line `frame,time,particle,body,x,y,z,vx,vy,vz`, and bodies.csv, one row per body
/// per frame, with `frame,time,body,name,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz` (centre of mass,
/// orientation quaternion body frame to world, velocity, angular velocity in world axes; `name`
/// from body_names, quoted when it holds a comma or a quote, empty without one). Floats are
/// printed with the fewest digits that read back to the same float32 (time: the same double).
/// Flushed after each frame.
Result<std::unique_ptr<FrameWriter>> open_csv_writer(const std::string& dir,
                                                     std::vector<std::string> body_names = {});

/// open_vtu_writer or open_csv_writer; OutputFormat::None is an error (write nothing instead).
Result<std::unique_ptr<FrameWriter>> open_frame_writer(OutputFormat format, const std::string& dir,
                                                       std::vector<std::string> body_names = {});

/// Where a series of frames stands, so that another process can continue it (motes resume): the
/// frames written so far and, for CSV, the files' sizes after the last of them.
struct SeriesState {
  std::vector<double> frame_times;        ///< simulated time of every frame written, in order
  std::uint64_t particles_csv_bytes = 0;  ///< CSV: size of particles.csv after the last frame
  std::uint64_t bodies_csv_bytes = 0;     ///< CSV: size of bodies.csv after the last frame
};

/// Sizes of particles.csv and bodies.csv in `dir` now (the CSV writer flushes after each frame):
/// the SeriesState of a CSV series after its last frame.
Status csv_series_sizes(const std::string& dir, SeriesState& state);

/// Continues a series that open_frame_writer started in `dir`, whose first
/// state.frame_times.size() frames are kept: the next frame is numbered after them. VTU: those
/// frames' files must exist (they are not rewritten) and the .pvd files are rewritten to list
/// them; files of later frames are replaced as the frames come. CSV: particles.csv and bodies.csv
/// must hold at least the recorded sizes; they are cut to them (rows written after that point
/// go) and appended to. A missing or short file is an error naming it, and then nothing has been
/// written. OutputFormat::None is an error, as for open_frame_writer.
Result<std::unique_ptr<FrameWriter>> continue_frame_writer(OutputFormat format,
                                                           const std::string& dir,
                                                           std::vector<std::string> body_names,
                                                           const SeriesState& state);

/// Writes one snapshot as a single .vtu file (same layout as the series), not listed in any .pvd.
Status write_vtu_file(const std::string& path, const Snapshot& snapshot);

/// Writes points as CSV with the header `x,y,z` (shortest round-trip float32 values).
Status write_points_csv(const std::string& path, const std::vector<Eigen::Vector3f>& points);

/// A snapshot at time 0 of one body made of `points` (radius = diameter / 2, velocity zero),
/// for writing a particle set with write_vtu_file.
Snapshot particle_set_snapshot(const std::vector<Eigen::Vector3f>& points, double diameter);

/// Creates `dir` and its parents if missing; an error naming it as the `purpose` directory
/// ("output", "render") if it cannot, or if it is not a directory.
Status create_output_directory(const std::string& dir, const std::string& purpose = "output");

}  // namespace motes
MOTES_API_END
