// Every kernel family of motes/backend/kernels.h has its conformance suites, its conformance file
// and its oracle file (docs/conformance.md): a family added to the list without them fails here.
// A suite belongs to the family whose CamelCase name is the longest start of its own
// (ImpulsesComputeThenApply: impulses_compute), so that one family's name starting another's
// could not lend it its suites.
#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "conformance.h"
#include "motes/backend/device.h"

namespace motes_conf {
namespace {

TEST(ConformanceFamilies, EveryFamilyHasSuitesAConformanceFileAndAnOracleFile) {
  std::vector<std::size_t> suites(motes::kKernelCount, 0);
  const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
  for (int s = 0; s < unit.total_test_suite_count(); ++s) {
    const std::string name = unit.GetTestSuite(s)->name();
    std::size_t best = motes::kKernelCount;
    std::size_t best_length = 0;
    for (std::size_t k = 0; k < motes::kKernelCount; ++k) {
      const std::string start = family_suite(static_cast<motes::Kernel>(k));
      if (name.rfind(start, 0) == 0 && start.size() > best_length) {
        best = k;
        best_length = start.size();
      }
    }
    if (best < motes::kKernelCount) ++suites[best];
  }
  const std::filesystem::path root = MOTES_SOURCE_DIR;
  for (std::size_t k = 0; k < motes::kKernelCount; ++k) {
    const auto kernel = static_cast<motes::Kernel>(k);
    const std::string family = motes::kernel_name(kernel);
    EXPECT_GT(suites[k], 0u) << family << " has no conformance suite (" << family_suite(kernel)
                             << "*)";
    EXPECT_TRUE(std::filesystem::exists(root / "tests/conformance" / ("test_" + family + ".cpp")))
        << family << " has no tests/conformance/test_" << family << ".cpp";
    EXPECT_TRUE(std::filesystem::exists(root / "tests/reference" / (family + ".cpp")))
        << family << " has no oracle file tests/reference/" << family << ".cpp";
  }
}

}  // namespace
}  // namespace motes_conf
