// Output formats by name, and the writer for each.
#include "motes/output.h"

#include <fmt/format.h>

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
