// The conformance harness: the devices under test, buffer transfers that assert, the error
// measures, and the results table (docs/conformance.md).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "motes/backend/device.h"
#include "shared/common.h"

namespace motes_conf {

using motes::shared::vec4;

/// One test parameter: a device of a backend, or a backend with nothing to run on.
struct DeviceParam {
  std::string backend;      ///< "openmp", "cuda", "vulkan"
  int index = 0;            ///< device index within the backend
  std::string label;        ///< the parameter's name in test names and the table: "openmp_0"
  std::string description;  ///< device name and detail
  std::string skip_reason;  ///< non-empty: every test skips, saying this
  std::string error;        ///< non-empty: every test fails, saying this (e.g. unknown backend)
};
void PrintTo(const DeviceParam& p, std::ostream* os);

/// Every device of every compiled backend (one parameter each), plus one skipping parameter per
/// compiled backend without devices. MOTES_CONFORMANCE_BACKENDS="openmp,vulkan" keeps only those
/// backends; a named backend that is not built also gets a skipping parameter and an unknown name
/// a failing one, so that nothing asked for disappears silently.
const std::vector<DeviceParam>& device_params();

/// The parameter's label, for INSTANTIATE_TEST_SUITE_P.
std::string param_name(const testing::TestParamInfo<DeviceParam>& info);

/// How the suites of family k start: "Conformance/" and the family's name in CamelCase
/// (constraints_solve: "Conformance/ConstraintsSolve"). Every suite of a family is named so
/// (ConstraintsSolve, or ConstraintsSolve and more: NeighboursBuildStamps is neighbours_build's),
/// in its file tests/conformance/test_FAMILY.cpp; the driver's --family selects them by it.
std::string family_suite(motes::Kernel k);

/// Bound on the error when the oracle is exactly zero: the error is then the plain sum of
/// squares of the device's output (in its own units squared), which must be at most this.
constexpr double kZeroReferenceBound = 1.0e-12;

/// A float comparison of a device output with the oracle's.
struct Comparison {
  double error = 0.0;              ///< NMSE, or the sum of squares when the oracle is all zero
  bool zero_reference = false;     ///< the oracle was all zero
  std::size_t non_finite = 0;      ///< device components that are NaN or infinite (oracle finite)
  std::size_t first_bad = 0;       ///< first such element
  bool oracle_non_finite = false;  ///< the oracle itself had a NaN or infinity: bad test data
  /// NMSE <= tolerance (kZeroReferenceBound when the oracle is all zero), every value finite.
  [[nodiscard]] bool pass(double tolerance) const;
};

/// Which components of a vec4 a comparison covers.
enum class Part {
  All,  ///< x, y, z and w: one quantity (a force with w = 0, a quaternion)
  Xyz,  ///< x, y, z only: w is another quantity (radius, inverse mass), compared on its own
};

/// NMSE(a, b) = sum (a - b)^2 / sum b^2 over the compared components of every element, a =
/// device, b = oracle, in double.
Comparison compare(const std::vector<vec4>& device, const std::vector<vec4>& oracle,
                   Part part = Part::All);

/// One line of the results table.
struct Row {
  std::string device;  ///< parameter label, e.g. "openmp_0"
  std::string name;    ///< "kernel/case", e.g. "grid_build/on_cell_faces"
  std::string size;    ///< N (or B), or a description
  std::string metric;  ///< "mismatches", "nmse", "sum a^2", "max |dx| (m)", ...
  double error = 0.0;
  double tolerance = 0.0;
  std::string verdict;  ///< "pass", "FAIL", "skip: ..."
};

/// Appends a row to the table printed at the end of the run (and written to
/// $MOTES_CONFORMANCE_TABLE as Markdown when that is set).
void record(Row row);

/// Synchronizes a device and checks its guard words (ASSERTs).
void expect_clean(motes::Device& d);

/// Base fixture: opens the parameter's device, or skips (or fails) as the parameter says. After
/// the test it asserts that the device synchronizes cleanly and that every guard word is intact.
class DeviceTest : public testing::TestWithParam<DeviceParam> {
 protected:
  void SetUp() override;
  void TearDown() override;

  /// False in fixtures that make their own devices (through motes::Simulation).
  [[nodiscard]] virtual bool wants_device() const { return true; }
  motes::Device& device() { return *device_; }
  [[nodiscard]] const std::string& label() const { return GetParam().label; }

  /// Allocates every buffer for these sizes (ASSERTs).
  void allocate(const motes::Sizes& sizes);
  /// Writes a whole vector at the start of a buffer (ASSERTs).
  template <typename T>
  void write(motes::Buffer b, const std::vector<T>& data) {
    write_bytes(b, data.data(), data.size() * sizeof(T));
  }
  /// Reads a whole buffer (ASSERTs).
  template <typename T>
  void read(motes::Buffer b, std::vector<T>& out) {
    const motes::BufferLayout layout = motes::buffer_layout(b, sizes_);
    ASSERT_EQ(layout.element_bytes, sizeof(T)) << motes::buffer_name(b);
    out.resize(layout.count);
    read_bytes(b, out.data(), layout.bytes());
  }
  /// Fills every buffer except `inputs` with 0xFF bytes (NaN floats, 0xFFFFFFFF indices): a
  /// kernel must write all of its outputs and read only its inputs, or the comparison fails.
  void poison_all_but(std::initializer_list<motes::Buffer> inputs);
  /// Synchronizes and checks the guard words (ASSERTs); call after the kernel, before reading.
  void finish_kernel();
  /// Runs one call of family k and checks it against its entry in motes/backend/kernels.h:
  /// every buffer outside the family's writes must hold the same bytes afterwards. With
  /// MOTES_CONFORMANCE_POISON_UNREAD=1 every buffer the family neither reads nor writes is also
  /// filled with 0xFF bytes for the call (and put back after it), so that a kernel reading a
  /// buffer its entry does not list gets garbage and fails the comparison with the oracle.
  /// Synchronizes (ASSERTs) like finish_kernel().
  void run(motes::Kernel k, const motes::shared::StepParams& p);

  /// Starts a case (one row of the table): name "kernel/layout", size N (or B).
  void begin_case(const std::string& name, std::size_t size);
  /// EXPECTs integer or bitwise-copied outputs identical to the oracle's.
  template <typename T>
  void check_identical(const char* what, const std::vector<T>& device,
                       const std::vector<T>& oracle);
  /// EXPECTs a float output within `tolerance` NMSE of the oracle, and finite.
  void check_close(const char* what, const std::vector<vec4>& device,
                   const std::vector<vec4>& oracle, double tolerance, Part part = Part::All);
  /// EXPECTs every element's w bitwise equal to the oracle's (for Part::Xyz comparisons).
  void check_w_identical(const char* what, const std::vector<vec4>& device,
                         const std::vector<vec4>& oracle);
  /// EXPECTs a condition (counted as one mismatch when false).
  void check_that(const char* what, bool ok);
  /// EXPECTs a scalar measure (e.g. a position difference in m) to be at most `tolerance`.
  void check_at_most(const char* what, const char* metric, double value, double tolerance);
  /// Records the case's row: the error is the worst of its checks (relative to its tolerance),
  /// the verdict FAIL when any check failed.
  void end_case();

 private:
  void write_bytes(motes::Buffer b, const void* src, std::size_t bytes);
  void read_bytes(motes::Buffer b, void* dst, std::size_t bytes);
  void add_mismatches(const char* what, std::size_t mismatches);
  /// Keeps the check with the largest error / tolerance as the case's reported error.
  void add_measure(const char* metric, double error, double tolerance, bool ok);

  struct OpenCase {
    bool open = false;
    std::string name;
    std::size_t size = 0;
    std::string metric;
    double error = 0.0;
    double tolerance = 0.0;
    double ratio = -1.0;
    bool ok = true;
    std::string failed;  // names of the failed checks
  };
  OpenCase case_;
  std::unique_ptr<motes::Device> device_;
  motes::Sizes sizes_;
};

/// An element as text, for failure messages.
std::string to_text(std::uint32_t v);
std::string to_text(std::uint64_t v);
std::string to_text(const vec4& v);

/// Number of elements whose bytes differ, and the first of them (count if none).
std::size_t count_mismatches(const void* a, const void* b, std::size_t elements,
                             std::size_t element_bytes, std::size_t& first);

template <typename T>
void DeviceTest::check_identical(const char* what, const std::vector<T>& device,
                                 const std::vector<T>& oracle) {
  if (device.size() != oracle.size()) {
    ADD_FAILURE() << what << ": " << device.size() << " elements, the oracle has " << oracle.size();
    add_mismatches(what, std::max(device.size(), oracle.size()));
    return;
  }
  std::size_t first = 0;
  const std::size_t bad =
      count_mismatches(device.data(), oracle.data(), device.size(), sizeof(T), first);
  EXPECT_EQ(bad, 0u) << what << ": " << bad << " of " << device.size()
                     << " elements differ from the oracle";
  if (bad > 0) {
    ADD_FAILURE() << what << "[" << first << "]: device " << to_text(device[first]) << ", oracle "
                  << to_text(oracle[first]);
  }
  add_mismatches(what, bad);
}

}  // namespace motes_conf
