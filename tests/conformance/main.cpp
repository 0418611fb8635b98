// The conformance driver: GoogleTest's main, plus --family (run the suites of some kernel families
// only) and --backend (run on some backends only: MOTES_CONFORMANCE_BACKENDS). docs/conformance.md,
// "Running it".
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "conformance.h"
#include "motes/backend/device.h"

namespace {

constexpr const char* kUsage =
    R"(motes_conformance_tests: the cross-backend conformance suite (docs/conformance.md)

Usage: motes_conformance_tests [--family NAME[,NAME...]]... [--backend NAME[,NAME...]]...
                               [gtest flags]

  --family NAME    run the suites of kernel family NAME only (Conformance/CamelCaseName*.*, e.g.
                   constraints_solve: Conformance/ConstraintsSolve*.*); repeatable or
                   comma-separated; combined with --gtest_filter (a test must match both)
  --backend NAME   run on backend NAME only (openmp, cuda, vulkan); repeatable or comma-separated;
                   sets MOTES_CONFORMANCE_BACKENDS, replacing what the environment holds
  --help           this text, then GoogleTest's flags

Example: motes_conformance_tests --family constraints_solve --backend vulkan
)";

/// Every family's name, for messages.
std::string family_names() {
  std::string out;
  for (std::size_t i = 0; i < motes::kKernelCount; ++i) {
    out += std::string(i == 0 ? "" : " ") + motes::kernel_name(static_cast<motes::Kernel>(i));
  }
  return out;
}

/// The comma-separated items of `value`, appended to `out` (empty items skipped).
void split_into(std::string_view value, std::vector<std::string>& out) {
  std::stringstream in{std::string(value)};
  std::string item;
  while (std::getline(in, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
}

/// Whether `name` matches the glob `pattern` ('*': any run of characters, '?': any one).
bool glob_matches(std::string_view pattern, std::string_view name) {
  std::size_t p = 0, n = 0, star = std::string_view::npos, resume = 0;
  while (n < name.size()) {
    if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == name[n])) {
      ++p;
      ++n;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      resume = n;
    } else if (star != std::string_view::npos) {
      p = star + 1;
      n = ++resume;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

/// Whether `name` passes a gtest filter "POSITIVE[-NEGATIVE]" (':'-separated globs; an empty
/// positive part is "*").
bool filter_matches(const std::string& filter, const std::string& name) {
  const std::size_t dash = filter.find('-');
  const std::string positive = filter.substr(0, dash);
  const std::string negative = dash == std::string::npos ? "" : filter.substr(dash + 1);
  const auto any = [&](const std::string& globs) {
    std::stringstream in(globs);
    std::string glob;
    while (std::getline(in, glob, ':')) {
      if (glob_matches(glob, name)) return true;
    }
    return false;
  };
  return (positive.empty() || any(positive)) && !any(negative);
}

}  // namespace

int main(int argc, char** argv) {
  // Our flags out of argv before GoogleTest reads it (it rejects none, but they are ours).
  std::vector<std::string> families;
  std::vector<std::string> backends;
  bool help = false;
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const auto value_of = [&](std::string_view flag, std::vector<std::string>& out) {
      if (arg == flag) {
        if (i + 1 >= argc) {
          std::fprintf(stderr, "%s needs a value (--help)\n", std::string(flag).c_str());
          std::exit(2);
        }
        split_into(argv[++i], out);
        return true;
      }
      if (arg.substr(0, flag.size() + 1) == std::string(flag) + "=") {
        split_into(arg.substr(flag.size() + 1), out);
        return true;
      }
      return false;
    };
    if (value_of("--family", families) || value_of("--backend", backends)) continue;
    if (arg == "--help" || arg == "-h") help = true;
    rest.push_back(argv[i]);
  }
  if (help) std::fputs(kUsage, stdout);

  std::string family_filter;
  for (const std::string& name : families) {
    const motes::Kernel k = motes::kernel_from_name(name);
    if (k == motes::Kernel::Count) {
      std::fprintf(stderr, "--family: no kernel family '%s'; the families: %s\n", name.c_str(),
                   family_names().c_str());
      return 2;
    }
    family_filter += (family_filter.empty() ? "" : ":") + motes_conf::family_suite(k) + "*.*";
  }
  // Before GoogleTest's setup, which generates the test parameters (device_params() reads it).
  if (!backends.empty()) {
    std::string list;
    for (const std::string& b : backends) list += (list.empty() ? "" : ",") + b;
    setenv("MOTES_CONFORMANCE_BACKENDS", list.c_str(), 1);
  }

  int rest_count = static_cast<int>(rest.size());
  rest.push_back(nullptr);
  testing::InitGoogleTest(&rest_count, rest.data());

  if (!family_filter.empty()) {
    // The tests that match both the families and --gtest_filter (globs do not intersect, so the
    // registered tests are listed by name).
    const std::string given = GTEST_FLAG_GET(filter);
    std::string filter;
    const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
    for (int s = 0; s < unit.total_test_suite_count(); ++s) {
      const testing::TestSuite& suite = *unit.GetTestSuite(s);
      for (int t = 0; t < suite.total_test_count(); ++t) {
        const std::string name = std::string(suite.name()) + "." + suite.GetTestInfo(t)->name();
        if (filter_matches(family_filter, name) && filter_matches(given, name)) {
          filter += (filter.empty() ? "" : ":") + name;
        }
      }
    }
    if (filter.empty()) {  // GoogleTest then runs nothing and passes: say so
      std::fprintf(stderr, "--family: no test of %s matches --gtest_filter=%s\n",
                   family_filter.c_str(), given.c_str());
      filter = "-*";
    }
    GTEST_FLAG_SET(filter, filter);
  }
  return RUN_ALL_TESTS();
}
