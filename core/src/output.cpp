// Output formats by name, and the writer for each.
#include "motes/output.h"
#include "output_file.h"

#include <fmt/format.h>

#include <filesystem>
#include <system_error>

namespace motes {

Result<OutputFormat> parse_output_format(const std::string& name) {
  if (name == "vtu") return OutputFormat::Vtu;
  if (name == "csv") return OutputFormat::Csv;
  if (name == "none") return OutputFormat::None;
  return Status::error(fmt::format("unknown output format '{}' (expected vtu, csv or none)", name));
}

const char* output_format_name(OutputFormat format) {
  switch (format) {
    case OutputFormat::Vtu:
      return "vtu";
    case OutputFormat::Csv:
      return "csv";
    case OutputFormat::None:
      return "none";
  }
  return "?";
}

Result<std::unique_ptr<FrameWriter>> open_frame_writer(OutputFormat format, const std::string& dir,
                                                       std::vector<std::string> body_names) {
  switch (format) {
    case OutputFormat::Vtu:
      return open_vtu_writer(dir);
    case OutputFormat::Csv:
      return open_csv_writer(dir, std::move(body_names));
    case OutputFormat::None:
      break;
  }
  return Status::error(fmt::format("output format 'none' writes no files (directory '{}')", dir));
}

Result<std::unique_ptr<FrameWriter>> continue_frame_writer(OutputFormat format,
                                                           const std::string& dir,
                                                           std::vector<std::string> body_names,
                                                           const SeriesState& state) {
  switch (format) {
    case OutputFormat::Vtu:
      return output::continue_vtu_writer(dir, state.frame_times);
    case OutputFormat::Csv:
      return output::continue_csv_writer(dir, std::move(body_names), state);
    case OutputFormat::None:
      break;
  }
  return Status::error(fmt::format("output format 'none' writes no files (directory '{}')", dir));
}

Status csv_series_sizes(const std::string& dir, SeriesState& state) {
  std::error_code ec;
  const std::filesystem::path d(dir);
  state.particles_csv_bytes = std::filesystem::file_size(d / "particles.csv", ec);
  if (!ec) state.bodies_csv_bytes = std::filesystem::file_size(d / "bodies.csv", ec);
  if (ec)
    return Status::error(
        fmt::format("cannot read the size of the CSV files in '{}': {}", dir, ec.message()));
  return Status::ok();
}

Snapshot particle_set_snapshot(const std::vector<Eigen::Vector3f>& points, double diameter) {
  Snapshot s;
  const auto radius = static_cast<float>(diameter / 2.0);
  s.particle_pos.reserve(points.size());
  for (const Eigen::Vector3f& p : points) s.particle_pos.emplace_back(p.x(), p.y(), p.z(), radius);
  s.particle_vel.assign(points.size(), shared::vec4(0.0f));
  s.particle_body.assign(points.size(), 0U);
  return s;
}

}  // namespace motes
