// The conformance harness: devices under test, the fixture, transfers and comparisons.
#include "conformance.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>

#include "motes/devices.h"

namespace motes_conf {

namespace {

/// Lower-case, trimmed names from MOTES_CONFORMANCE_BACKENDS (empty: every backend).
std::vector<std::string> requested_backends() {
  std::vector<std::string> out;
  const char* env = std::getenv("MOTES_CONFORMANCE_BACKENDS");
  if (env == nullptr) return out;
  std::stringstream in(env);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::string name;
    for (const char c : item) {
      if (std::isspace(static_cast<unsigned char>(c)) == 0) {
        name += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      }
    }
    if (!name.empty()) out.push_back(name);
  }
  return out;
}

/// Test names allow letters, digits and '_' only.
std::string sanitize(const std::string& s) {
  std::string out;
  for (const char c : s) out += std::isalnum(static_cast<unsigned char>(c)) != 0 ? c : '_';
  return out;
}

std::vector<DeviceParam> build_params() {
  const std::vector<std::string> wanted = requested_backends();
  auto is_wanted = [&](const std::string& name) {
    return wanted.empty() || std::find(wanted.begin(), wanted.end(), name) != wanted.end();
  };
  std::vector<DeviceParam> out;
  const std::vector<motes::BackendReport> reports = motes::list_backends();
  for (const motes::BackendReport& r : reports) {
    if (!is_wanted(r.backend)) continue;
    if (!r.compiled || r.devices.empty()) {
      // A backend that is not built is only listed when asked for by name.
      if (!r.compiled && wanted.empty()) continue;
      DeviceParam p;
      p.backend = r.backend;
      p.label = sanitize(r.backend) + (r.compiled ? "_no_device" : "_not_built");
      p.skip_reason = r.backend + ": " + r.unavailable_reason;
      out.push_back(p);
      continue;
    }
    for (const motes::DeviceInfo& d : r.devices) {
      DeviceParam p;
      p.backend = r.backend;
      p.index = d.index;
      p.label = fmt::format("{}_{}", sanitize(r.backend), d.index);
      p.description = d.name + (d.detail.empty() ? "" : " (" + d.detail + ")");
      out.push_back(p);
    }
  }
  for (const std::string& name : wanted) {
    const bool known =
        std::any_of(reports.begin(), reports.end(),
                    [&](const motes::BackendReport& r) { return r.backend == name; });
    if (known) continue;
    DeviceParam p;
    p.backend = name;
    p.label = sanitize(name) + "_unknown";
    p.error = "MOTES_CONFORMANCE_BACKENDS names an unknown backend '" + name + "'";
    out.push_back(p);
  }
  return out;
}

}  // namespace

void PrintTo(const DeviceParam& p, std::ostream* os) { *os << p.label; }

const std::vector<DeviceParam>& device_params() {
  static const std::vector<DeviceParam> params = build_params();
  return params;
}

std::string param_name(const testing::TestParamInfo<DeviceParam>& info) { return info.param.label; }

std::string family_suite(motes::Kernel k) {
  std::string out = "Conformance/";
  bool upper = true;
  for (const char* c = motes::kernel_name(k); *c != '\0'; ++c) {
    if (*c == '_') {
      upper = true;
      continue;
    }
    out += upper ? static_cast<char>(std::toupper(static_cast<unsigned char>(*c))) : *c;
    upper = false;
  }
  return out;
}

bool Comparison::pass(double tolerance) const {
  if (oracle_non_finite || non_finite > 0) return false;
  return error <= (zero_reference ? kZeroReferenceBound : tolerance);
}

Comparison compare(const std::vector<vec4>& device, const std::vector<vec4>& oracle, Part part) {
  const int components = part == Part::All ? 4 : 3;
  Comparison c;
  double err2 = 0.0;
  double ref2 = 0.0;
  double dev2 = 0.0;
  const std::size_t n = std::min(device.size(), oracle.size());
  for (std::size_t i = 0; i < n; ++i) {
    const float a[4] = {device[i].x, device[i].y, device[i].z, device[i].w};
    const float b[4] = {oracle[i].x, oracle[i].y, oracle[i].z, oracle[i].w};
    for (int k = 0; k < components; ++k) {
      if (!std::isfinite(b[k])) {
        c.oracle_non_finite = true;
        continue;
      }
      if (!std::isfinite(a[k])) {
        if (c.non_finite++ == 0) c.first_bad = i;
        continue;
      }
      const double d = static_cast<double>(a[k]) - static_cast<double>(b[k]);
      err2 += d * d;
      ref2 += static_cast<double>(b[k]) * static_cast<double>(b[k]);
      dev2 += static_cast<double>(a[k]) * static_cast<double>(a[k]);
    }
  }
  c.zero_reference = ref2 == 0.0;
  c.error = c.zero_reference ? dev2 : err2 / ref2;
  return c;
}

std::string to_text(std::uint32_t v) { return std::to_string(v); }

std::string to_text(std::uint64_t v) { return fmt::format("{:016x}", v); }

std::string to_text(const vec4& v) {
  return fmt::format("({:.9g}, {:.9g}, {:.9g}, {:.9g})", v.x, v.y, v.z, v.w);
}

std::size_t count_mismatches(const void* a, const void* b, std::size_t elements,
                             std::size_t element_bytes, std::size_t& first) {
  const auto* pa = static_cast<const unsigned char*>(a);
  const auto* pb = static_cast<const unsigned char*>(b);
  std::size_t bad = 0;
  first = elements;
  for (std::size_t i = 0; i < elements; ++i) {
    if (std::memcmp(pa + i * element_bytes, pb + i * element_bytes, element_bytes) != 0) {
      if (bad++ == 0) first = i;
    }
  }
  return bad;
}

void DeviceTest::SetUp() {
  const DeviceParam& p = GetParam();
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const std::string test = std::string(info->test_suite_name()) + "." + info->name();
  if (!p.error.empty()) {
    record({p.label, test, "-", "-", 0.0, 0.0, "FAIL: " + p.error});
    FAIL() << p.error;
  }
  if (!p.skip_reason.empty()) {
    record({p.label, test, "-", "-", 0.0, 0.0, "skip: " + p.skip_reason});
    GTEST_SKIP() << p.skip_reason;
  }
  if (!wants_device()) return;
  auto opened = motes::open_device(p.backend, p.index);
  ASSERT_TRUE(opened) << p.label << ": " << opened.message();
  device_ = std::move(opened).value();
}

void DeviceTest::TearDown() {
  if (case_.open) {  // the case stopped at a fatal failure
    case_.ok = false;
    case_.failed += std::string(case_.failed.empty() ? "" : ", ") + "aborted";
    end_case();
  }
  if (!device_) return;
  // Every case ends clean: no error queued on the device (the Vulkan device reports validation
  // layer messages here) and no guard word overwritten.
  const motes::Status sync = device_->synchronize();
  EXPECT_TRUE(sync) << "synchronize: " << sync.message();
  const motes::Status guards = device_->check_guards();
  EXPECT_TRUE(guards) << "check_guards: " << guards.message();
  if (!sync || !guards) {
    std::string why = sync ? "" : "synchronize: " + sync.message();
    if (!guards) why += (why.empty() ? "" : "; ") + ("check_guards: " + guards.message());
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    record({label(), std::string(info->test_suite_name()) + "." + info->name(), "-", "device clean",
            1.0, 0.0, "FAIL: " + why});
  }
  device_.reset();
}

void DeviceTest::allocate(const motes::Sizes& sizes) {
  const motes::Status st = device_->allocate(sizes);
  ASSERT_TRUE(st) << "allocate: " << st.message();
  sizes_ = sizes;
}

void DeviceTest::write_bytes(motes::Buffer b, const void* src, std::size_t bytes) {
  const motes::Status st = device_->write(b, src, bytes);
  ASSERT_TRUE(st) << "write " << motes::buffer_name(b) << ": " << st.message();
}

void DeviceTest::read_bytes(motes::Buffer b, void* dst, std::size_t bytes) {
  const motes::Status st = device_->read(b, dst, bytes);
  ASSERT_TRUE(st) << "read " << motes::buffer_name(b) << ": " << st.message();
}

void DeviceTest::poison_all_but(std::initializer_list<motes::Buffer> inputs) {
  for (std::size_t i = 0; i < motes::kBufferCount; ++i) {
    const auto b = static_cast<motes::Buffer>(i);
    if (std::find(inputs.begin(), inputs.end(), b) != inputs.end()) continue;
    const std::vector<unsigned char> junk(motes::buffer_layout(b, sizes_).bytes(), 0xFF);
    ASSERT_NO_FATAL_FAILURE(write_bytes(b, junk.data(), junk.size()));
  }
}

void expect_clean(motes::Device& d) {
  const motes::Status sync = d.synchronize();
  ASSERT_TRUE(sync) << "synchronize: " << sync.message();
  const motes::Status guards = d.check_guards();
  ASSERT_TRUE(guards) << "check_guards: " << guards.message();
}

void DeviceTest::finish_kernel() { expect_clean(*device_); }

namespace {

bool poison_unread() {
  const char* v = std::getenv("MOTES_CONFORMANCE_POISON_UNREAD");
  return v != nullptr && std::string(v) == "1";
}

}  // namespace

void DeviceTest::run(motes::Kernel k, const motes::shared::StepParams& p) {
  const motes::BufferMask reads = motes::kernel_reads(k);
  const motes::BufferMask writes = motes::kernel_writes(k);
  const bool poison = poison_unread();
  std::vector<std::vector<unsigned char>> before(motes::kBufferCount);
  std::vector<bool> poisoned(motes::kBufferCount, false);
  for (std::size_t i = 0; i < motes::kBufferCount; ++i) {
    const auto b = static_cast<motes::Buffer>(i);
    const std::size_t bytes = motes::buffer_layout(b, sizes_).bytes();
    if ((writes & motes::buffer_bit(b)) != 0 || bytes == 0) continue;
    before[i].resize(bytes);
    ASSERT_NO_FATAL_FAILURE(read_bytes(b, before[i].data(), bytes));
    if (poison && (reads & motes::buffer_bit(b)) == 0) {
      const std::vector<unsigned char> junk(bytes, 0xFF);
      ASSERT_NO_FATAL_FAILURE(write_bytes(b, junk.data(), bytes));
      poisoned[i] = true;
    }
  }
  device_->enqueue(k, p);
  ASSERT_NO_FATAL_FAILURE(finish_kernel());
  std::vector<unsigned char> after;
  for (std::size_t i = 0; i < motes::kBufferCount; ++i) {
    if (before[i].empty()) continue;
    const auto b = static_cast<motes::Buffer>(i);
    after.resize(before[i].size());
    ASSERT_NO_FATAL_FAILURE(read_bytes(b, after.data(), after.size()));
    const bool same = poisoned[i] ? std::all_of(after.begin(), after.end(),
                                                [](unsigned char c) { return c == 0xFF; })
                                  : after == before[i];
    if (!same) {
      ADD_FAILURE() << motes::kernel_name(k) << " changed " << motes::buffer_name(b)
                    << ", which is not among its writes in motes/backend/kernels.h";
      if (case_.open) add_mismatches("a buffer outside the family's writes", 1);
    }
    if (poisoned[i]) {
      ASSERT_NO_FATAL_FAILURE(write_bytes(b, before[i].data(), before[i].size()));
    }
  }
}

void DeviceTest::begin_case(const std::string& name, std::size_t size) {
  case_ = OpenCase{};
  case_.open = true;
  case_.name = name;
  case_.size = size;
}

void DeviceTest::add_measure(const char* metric, double error, double tolerance, bool ok) {
  double ratio = 0.0;
  if (tolerance > 0.0) {
    ratio = error / tolerance;
  } else if (error > 0.0) {
    ratio = std::numeric_limits<double>::infinity();
  }
  if (!ok) ratio = std::numeric_limits<double>::infinity();
  // The worst check names the row; at a tie a measured error beats a count of mismatches.
  if (ratio > case_.ratio || (ratio == case_.ratio && case_.metric == "mismatches")) {
    case_.ratio = ratio;
    case_.metric = metric;
    case_.error = error;
    case_.tolerance = tolerance;
  }
}

void DeviceTest::add_mismatches(const char* what, std::size_t mismatches) {
  add_measure("mismatches", static_cast<double>(mismatches), 0.0, mismatches == 0);
  if (mismatches > 0) {
    case_.ok = false;
    case_.failed += std::string(case_.failed.empty() ? "" : ", ") + what;
  }
}

void DeviceTest::check_close(const char* what, const std::vector<vec4>& device,
                             const std::vector<vec4>& oracle, double tolerance, Part part) {
  if (device.size() != oracle.size()) {
    ADD_FAILURE() << what << ": " << device.size() << " elements, the oracle has " << oracle.size();
    add_mismatches(what, std::max(device.size(), oracle.size()));
    return;
  }
  const Comparison c = compare(device, oracle, part);
  const bool ok = c.pass(tolerance);
  add_measure(c.zero_reference ? "sum a^2" : "nmse", c.error,
              c.zero_reference ? kZeroReferenceBound : tolerance, ok);
  if (!ok) {
    case_.ok = false;
    case_.failed += std::string(case_.failed.empty() ? "" : ", ") + what;
  }
  EXPECT_FALSE(c.oracle_non_finite) << what << ": the oracle is not finite (bad test data)";
  EXPECT_EQ(c.non_finite, 0u) << what << ": " << c.non_finite
                              << " components are NaN or infinite where the oracle is finite; "
                              << "the first in element " << c.first_bad << " = "
                              << (c.non_finite > 0 ? to_text(device[c.first_bad]) : "")
                              << ", oracle "
                              << (c.non_finite > 0 ? to_text(oracle[c.first_bad]) : "");
  if (c.zero_reference) {
    EXPECT_LE(c.error, kZeroReferenceBound)
        << what << ": the oracle is all zero, the device's sum of squares is " << c.error;
  } else {
    EXPECT_LE(c.error, tolerance) << what << ": NMSE " << c.error << " > " << tolerance;
  }
}

void DeviceTest::check_w_identical(const char* what, const std::vector<vec4>& device,
                                   const std::vector<vec4>& oracle) {
  auto w_bits = [](const std::vector<vec4>& v) {
    std::vector<std::uint32_t> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) std::memcpy(&out[i], &v[i].w, sizeof(float));
    return out;
  };
  check_identical(what, w_bits(device), w_bits(oracle));
}

void DeviceTest::check_that(const char* what, bool ok) {
  EXPECT_TRUE(ok) << what;
  add_mismatches(what, ok ? 0 : 1);
}

void DeviceTest::check_at_most(const char* what, const char* metric, double value,
                               double tolerance) {
  const bool ok = value <= tolerance;  // NaN fails
  add_measure(metric, value, tolerance, ok);
  if (!ok) {
    case_.ok = false;
    case_.failed += std::string(case_.failed.empty() ? "" : ", ") + what;
  }
  EXPECT_LE(value, tolerance) << what << " (" << metric << ")";
}

void DeviceTest::end_case() {
  if (!case_.open) return;
  record({label(), case_.name, std::to_string(case_.size), case_.metric, case_.error,
          case_.tolerance, case_.ok ? "pass" : "FAIL: " + case_.failed});
  case_.open = false;
}

}  // namespace motes_conf
