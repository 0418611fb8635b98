// Finding the frames of a result directory: particles.pvd, particles_*.vtu or particles.csv.
#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "frames_read.h"

namespace motes::render {

namespace fs = std::filesystem;

namespace detail {

std::string attribute(const std::string& tag, const std::string& name) {
  const std::string key = " " + name + "=\"";
  const std::size_t at = tag.find(key);
  if (at == std::string::npos) return {};
  const std::size_t start = at + key.size();
  const std::size_t end = tag.find('"', start);
  return end == std::string::npos ? std::string() : tag.substr(start, end - start);
}

Result<std::vector<std::string>> read_pvd(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::error(fmt::format("cannot read '{}': {}", path, std::strerror(errno)));
  std::stringstream text;
  text << in.rdbuf();
  const std::string xml = text.str();
  if (xml.find("<VTKFile") == std::string::npos || xml.find("Collection") == std::string::npos) {
    return Status::error(
        fmt::format("'{}': not a .pvd collection (no <VTKFile type=\"Collection\">)", path));
  }
  std::vector<std::string> files;
  const fs::path dir = fs::path(path).parent_path();
  for (std::size_t at = xml.find("<DataSet"); at != std::string::npos;
       at = xml.find("<DataSet", at + 1)) {
    const std::size_t end = xml.find('>', at);
    if (end == std::string::npos) break;
    const std::string file = attribute(xml.substr(at, end - at), "file");
    if (file.empty()) {
      return Status::error(fmt::format("'{}': a <DataSet> without a file attribute", path));
    }
    files.push_back(fs::path(file).is_absolute() ? file : (dir / file).string());
  }
  if (files.empty()) return Status::error(fmt::format("'{}' lists no frames", path));
  return files;
}

float typical_radius(const std::vector<shared::vec4>& particles) {
  const std::size_t n = particles.size();
  if (n < 2) return 0.005f;
  // A few hundred particles spread over the index range, each against every particle.
  const std::size_t samples = std::min<std::size_t>(n, 256);
  std::vector<float> nearest;
  for (std::size_t s = 0; s < samples; ++s) {
    const shared::vec4& a = particles[s * n / samples];
    float best = std::numeric_limits<float>::infinity();
    for (const shared::vec4& b : particles) {
      const float dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
      const float d2 = dx * dx + dy * dy + dz * dz;
      if (d2 > 0.0f && d2 < best) best = d2;
    }
    if (std::isfinite(best)) nearest.push_back(std::sqrt(best));
  }
  if (nearest.empty()) return 0.005f;
  std::nth_element(nearest.begin(),
                   nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2),
                   nearest.end());
  return 0.5f * nearest[nearest.size() / 2];
}

}  // namespace detail

Result<std::unique_ptr<FrameReader>> FrameReader::open(const std::string& path, double csv_radius) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) {
    return Status::error(fmt::format("cannot read results '{}': {}", path,
                                     ec ? ec.message() : "No such file or directory"));
  }
  if (fs::is_regular_file(status)) {
    const std::string ext = fs::path(path).extension().string();
    if (ext == ".pvd") {
      Result<std::vector<std::string>> files = detail::read_pvd(path);
      if (!files) return files.status();
      return detail::open_vtu_frames(path, std::move(files).value());
    }
    if (ext == ".vtu") return detail::open_vtu_frames(path, {path});
    if (ext == ".csv") return detail::open_csv_frames(path, csv_radius);
    return Status::error(fmt::format(
        "cannot read results '{}': expected a directory, a .pvd, a .vtu or a .csv file", path));
  }
  if (!fs::is_directory(status)) {
    return Status::error(fmt::format("cannot read results '{}': not a file or directory", path));
  }
  const fs::path dir(path);
  if (fs::exists(dir / "particles.pvd", ec)) {
    const std::string pvd = (dir / "particles.pvd").string();
    Result<std::vector<std::string>> files = detail::read_pvd(pvd);
    if (!files) return files.status();
    return detail::open_vtu_frames(pvd, std::move(files).value());
  }
  if (fs::exists(dir / "particles.csv", ec)) {
    return detail::open_csv_frames((dir / "particles.csv").string(), csv_radius);
  }
  std::vector<std::string> vtu;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.starts_with("particles_") && name.ends_with(".vtu"))
      vtu.push_back(it->path().string());
  }
  if (ec) return Status::error(fmt::format("cannot read results '{}': {}", path, ec.message()));
  if (vtu.empty()) {
    return Status::error(fmt::format(
        "cannot read results '{}': no particles.pvd, particles_*.vtu or particles.csv in it "
        "(the files motes run --out writes)",
        path));
  }
  std::sort(vtu.begin(), vtu.end());
  return detail::open_vtu_frames(path, std::move(vtu));
}

}  // namespace motes::render
