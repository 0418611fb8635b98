// Result<T>: value() of a temporary gives the value itself, so that a loop over a member of a
// call's Result (`for (auto& p : sim->snapshot().value().particle_pos)`) reads a live object. It
// once gave a reference into the temporary, which C++20 lets die before the loop:
// examples/embed_vulkan read its first snapshot from freed memory and drew a wrong picture about
// one run in ten (under the sanitizers this test's loop reads freed memory if value() goes back).
#include <gtest/gtest.h>

#include <type_traits>
#include <utility>
#include <vector>

#include "motes/status.h"

namespace {

struct Held {
  std::vector<int> numbers;
};

motes::Result<Held> make_held() { return Held{{1, 2, 3, 4}}; }

static_assert(std::is_same_v<decltype(std::declval<motes::Result<Held>>().value()), Held>,
              "value() of a temporary Result must give the value, not a reference into it");
static_assert(std::is_same_v<decltype(std::declval<motes::Result<Held>&>().value()), Held&>);

TEST(Status, ValueOfATemporaryResultLivesThroughALoop) {
  int sum = 0;
  for (const int n : make_held().value().numbers) sum += n;
  EXPECT_EQ(sum, 10);
}

TEST(Status, ValueOfATemporaryErrorThrowsWithItsMessage) {
  const auto failing = []() -> motes::Result<Held> { return motes::Status::error("no such file"); };
  try {
    (void)failing().value();
    FAIL() << "value() of an error did not throw";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos) << e.what();
  }
}

}  // namespace
