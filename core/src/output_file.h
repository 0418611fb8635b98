// Helpers shared by the output writers: files whose errors become Status messages naming the path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "motes/output.h"
#include "motes/simulation.h"
#include "motes/status.h"

namespace motes::output {

/// A file opened for binary writing; every failure names the path and the system's reason.
class OutputFile {
 public:
  OutputFile() = default;
  OutputFile(OutputFile&& other) noexcept;
  OutputFile& operator=(OutputFile&& other) noexcept;
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  /// Closes the file if still open, ignoring errors (call close() to see them).
  ~OutputFile();

  /// Creates or truncates `path`.
  static Result<OutputFile> create(const std::string& path);
  /// Opens an existing `path` for writing at its end.
  static Result<OutputFile> append(const std::string& path);

  Status write(const void* data, std::size_t bytes);
  Status write(const std::string& text) { return write(text.data(), text.size()); }
  /// Pushes buffered bytes to the operating system.
  Status flush();
  /// Flushes and closes; the file is closed afterwards even on error.
  Status close();

  [[nodiscard]] bool is_open() const { return file_ != nullptr; }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  Status fail(const char* what, int error);

  std::FILE* file_ = nullptr;
  std::string path_;
};

/// Renames `from` to `to`, replacing `to` atomically.
Status replace_file(const std::string& from, const std::string& to);

/// Ok when `path` exists and has at least `bytes` bytes (what a checkpoint's series wrote); else
/// an error naming it and both sizes.
Status check_continuable(const std::string& path, std::uint64_t bytes);
/// Cuts `path` to `bytes` (check_continuable first): the rows of a CSV series written after a
/// checkpoint go.
Status cut_file(const std::string& path, std::uint64_t bytes);

/// continue_frame_writer for each format (output_vtu.cpp, output_csv.cpp).
Result<std::unique_ptr<FrameWriter>> continue_vtu_writer(const std::string& dir,
                                                         const std::vector<double>& times);
Result<std::unique_ptr<FrameWriter>> continue_csv_writer(const std::string& dir,
                                                         std::vector<std::string> body_names,
                                                         const SeriesState& state);

/// Checks that a snapshot's particle arrays have one entry per particle.
Status check_snapshot(const Snapshot& snapshot);

}  // namespace motes::output
