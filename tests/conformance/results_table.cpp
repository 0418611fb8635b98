// The results table: every case records a row; at the end of the run a gtest Environment prints
// the table (device x case x error x verdict) and writes it as Markdown to
// $MOTES_CONFORMANCE_TABLE when that is set.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "conformance.h"

namespace motes_conf {

namespace {

std::vector<Row>& rows() {
  static std::vector<Row> table;
  return table;
}

std::string number(double x) { return x == 0.0 ? "0" : fmt::format("{:.2e}", x); }

/// A table cell: '|' would end it.
std::string cell(const std::string& s) {
  std::string out;
  for (const char c : s) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

/// Rows go by device, then in the order a step runs the kernels, then whole scenes.
int family_rank(const std::string& name) {
  const char* order[] = {"grid_build",       "contacts_compute", "bodies_reduce",
                         "bodies_integrate", "particles_update", "scene"};
  for (int k = 0; k < 6; ++k) {
    if (name.rfind(order[k], 0) == 0) return k;
  }
  return 6;
}

/// The whole table as Markdown: a legend of the devices, then one line per row.
std::string markdown() {
  std::vector<Row> sorted = rows();
  std::stable_sort(sorted.begin(), sorted.end(), [](const Row& a, const Row& b) {
    if (a.device != b.device) return a.device < b.device;
    return family_rank(a.name) < family_rank(b.name);
  });
  std::string out = "| device | description |\n|---|---|\n";
  for (const DeviceParam& p : device_params()) {
    const std::string& why = !p.error.empty() ? p.error : p.skip_reason;
    out += fmt::format("| {} | {} |\n", p.label, cell(p.description.empty() ? why : p.description));
  }
  out += "\n| device | case | size | metric | error | tolerance | verdict |\n";
  out += "|---|---|---|---|---|---|---|\n";
  for (const Row& r : sorted) {
    const bool measured = r.metric != "-";
    out += fmt::format("| {} | {} | {} | {} | {} | {} | {} |\n", r.device, cell(r.name), r.size,
                       cell(r.metric), measured ? number(r.error) : "-",
                       measured ? number(r.tolerance) : "-", cell(r.verdict));
  }
  return out;
}

class TableEnvironment : public testing::Environment {
 public:
  void TearDown() override {
    if (rows().empty()) return;
    std::printf("\n[conformance] results\n%s\n", markdown().c_str());
    const char* path = std::getenv("MOTES_CONFORMANCE_TABLE");
    if (path != nullptr && *path != '\0') {
      std::ofstream out(path);
      out << markdown();
      if (!out) {
        ADD_FAILURE() << "could not write the table to MOTES_CONFORMANCE_TABLE=" << path;
      } else {
        std::printf("[conformance] table written to %s\n", path);
      }
    }
  }
};

// Registered before main runs (gtest_main owns main); gtest deletes it.
[[maybe_unused]] testing::Environment* const kTable =
    testing::AddGlobalTestEnvironment(new TableEnvironment);

}  // namespace

void record(Row row) { rows().push_back(std::move(row)); }

}  // namespace motes_conf
