// `motes devices`: every backend motes knows, its devices, or why it has none.
#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <vector>

#include "commands.h"
#include "motes/devices.h"

namespace motes::cli {

namespace {

/// The reason, starting with `prefix` unless it already says so.
std::string with_prefix(const std::string& prefix, const std::string& reason) {
  if (reason.rfind(prefix, 0) == 0) return reason;
  return prefix + (reason.empty() ? std::string("no reason given") : reason);
}

void print_devices() {
  const std::vector<BackendReport> reports = list_backends();
  std::size_t width = 0;
  for (const BackendReport& r : reports) width = std::max(width, r.backend.size());
  for (const BackendReport& r : reports) {
    if (!r.compiled || r.devices.empty()) {
      fmt::print("{:<{}}  {}\n", r.backend, width,
                 with_prefix(r.compiled ? "unavailable: " : "not built: ", r.unavailable_reason));
    } else {
      for (const DeviceInfo& d : r.devices) {
        fmt::print("{:<{}}  {}  {}{}\n", r.backend, width, d.index, d.name,
                   d.detail.empty() ? "" : fmt::format(" ({})", d.detail));
      }
    }
  }
}

}  // namespace

void add_devices_command(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "devices", "List every backend and its devices, or why a backend is unavailable");
  sub->callback(print_devices);
}

}  // namespace motes::cli
