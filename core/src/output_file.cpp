// Files and directories for the output writers, with errors that name the path.
#include "output_file.h"

#include "motes/output.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <utility>

namespace motes::output {

OutputFile::OutputFile(OutputFile&& other) noexcept
    : file_(std::exchange(other.file_, nullptr)), path_(std::move(other.path_)) {}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
  if (this != &other) {
    if (file_ != nullptr) std::fclose(file_);
    file_ = std::exchange(other.file_, nullptr);
    path_ = std::move(other.path_);
  }
  return *this;
}

OutputFile::~OutputFile() {
  if (file_ != nullptr) std::fclose(file_);
}

Result<OutputFile> OutputFile::create(const std::string& path) {
  OutputFile f;
  f.path_ = path;
  errno = 0;
  f.file_ = std::fopen(path.c_str(), "wb");
  if (f.file_ == nullptr) {
    const int error = errno;
    return Status::error(fmt::format("cannot create '{}': {}", path,
                                     error != 0 ? std::strerror(error) : "unknown error"));
  }
  // Large writes go straight through; a bigger buffer helps the many small CSV rows.
  std::setvbuf(f.file_, nullptr, _IOFBF, std::size_t{1} << 20);
  return f;
}

Result<OutputFile> OutputFile::append(const std::string& path) {
  OutputFile f;
  f.path_ = path;
  errno = 0;
  f.file_ = std::fopen(path.c_str(), "ab");
  if (f.file_ == nullptr) {
    const int error = errno;
    return Status::error(fmt::format("cannot open '{}' to append: {}", path,
                                     error != 0 ? std::strerror(error) : "unknown error"));
  }
  std::setvbuf(f.file_, nullptr, _IOFBF, std::size_t{1} << 20);
  return f;
}

Status OutputFile::fail(const char* what, int error) {
  return Status::error(fmt::format("cannot {} '{}': {}", what, path_,
                                   error != 0 ? std::strerror(error) : "write error"));
}

Status OutputFile::write(const void* data, std::size_t bytes) {
  if (file_ == nullptr) return Status::error(fmt::format("cannot write '{}': not open", path_));
  if (bytes == 0) return Status::ok();
  errno = 0;
  if (std::fwrite(data, 1, bytes, file_) != bytes) return fail("write", errno);
  return Status::ok();
}

Status OutputFile::flush() {
  if (file_ == nullptr) return Status::error(fmt::format("cannot write '{}': not open", path_));
  errno = 0;
  if (std::fflush(file_) != 0 || std::ferror(file_) != 0) return fail("write", errno);
  return Status::ok();
}

Status OutputFile::close() {
  if (file_ == nullptr) return Status::ok();
  errno = 0;
  const bool flushed = std::fflush(file_) == 0 && std::ferror(file_) == 0;
  const int flush_error = errno;
  errno = 0;
  const bool closed = std::fclose(file_) == 0;
  const int close_error = errno;
  file_ = nullptr;
  if (!flushed) return fail("write", flush_error);
  if (!closed) return fail("close", close_error);
  return Status::ok();
}

}  // namespace motes::output

namespace motes {

Status create_output_directory(const std::string& dir, const std::string& purpose) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path p(dir);
  if (fs::is_directory(p, ec)) return Status::ok();
  fs::create_directories(p, ec);
  if (ec) {
    return Status::error(
        fmt::format("cannot create {} directory '{}': {}", purpose, dir, ec.message()));
  }
  if (!fs::is_directory(p, ec)) {
    return Status::error(
        fmt::format("cannot create {} directory '{}': not a directory", purpose, dir));
  }
  return Status::ok();
}

}  // namespace motes

namespace motes::output {

Status replace_file(const std::string& from, const std::string& to) {
  std::error_code ec;
  std::filesystem::rename(from, to, ec);
  if (ec) {
    return Status::error(fmt::format("cannot rename '{}' to '{}': {}", from, to, ec.message()));
  }
  return Status::ok();
}

Status check_continuable(const std::string& path, std::uint64_t bytes) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) return Status::error(fmt::format("cannot continue '{}': {}", path, ec.message()));
  if (size < bytes) {
    return Status::error(fmt::format(
        "cannot continue '{}': it has {} bytes, fewer than the {} written before the checkpoint",
        path, size, bytes));
  }
  return Status::ok();
}

Status cut_file(const std::string& path, std::uint64_t bytes) {
  if (Status s = check_continuable(path, bytes); !s) return s;
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) == bytes && !ec) return Status::ok();
  std::filesystem::resize_file(path, bytes, ec);
  if (ec)
    return Status::error(fmt::format("cannot cut '{}' to {} bytes: {}", path, bytes, ec.message()));
  return Status::ok();
}

Status check_snapshot(const Snapshot& s) {
  const std::size_t n = s.particle_pos.size();
  if (s.particle_vel.size() != n || s.particle_body.size() != n) {
    return Status::error(fmt::format(
        "inconsistent snapshot at step {}: {} particle positions, {} velocities, {} body ids",
        s.step, n, s.particle_vel.size(), s.particle_body.size()));
  }
  const std::size_t b = s.body_pos.size();
  if (s.body_quat.size() != b || s.body_vel.size() != b || s.body_angvel.size() != b) {
    return Status::error(fmt::format(
        "inconsistent snapshot at step {}: {} body positions, {} orientations, {} velocities, {} "
        "angular velocities",
        s.step, b, s.body_quat.size(), s.body_vel.size(), s.body_angvel.size()));
  }
  return Status::ok();
}

}  // namespace motes::output
