// constraints_relax against the oracle: the cases of constraints_solve (test_constraints_solve.cpp:
// the layouts, the poisoned buffers, the tolerances and what is checked), each as one call of
// both sweeps over every colour (ConstraintColours written too), with MOTES_FLAG_SKIN_CHECK on the
// call (the last sweep tests the skin) but in the "unchecked" case. The colours of the 256 x 256
// cloth (about 33,000 constraints each) and of the random links (up to about 600) are wider than
// one workgroup, so each thread projects several constraints of a colour.
#include <gtest/gtest.h>

#include "constraints_cases.h"

namespace motes_conf {
namespace {

class ConstraintsRelax : public ConstraintsCaseTest {
 protected:
  void run_case(const std::string& layout, LinkedCase c, bool far, bool checked = true) {
    ConstraintsCaseTest::run_case(true, layout, std::move(c), far, checked);
  }
};

TEST_P(ConstraintsRelax, Empty) { run_case("none", random_links(171, 31, 0), false); }
TEST_P(ConstraintsRelax, Rope31) { run_case("rope", from_linked(172, rope(31), 0.003f), true); }
TEST_P(ConstraintsRelax, Cloth25) {
  run_case("cloth 25x25", from_linked(173, cloth(25), 0.003f), false);
}
TEST_P(ConstraintsRelax, Cloth25Moved) {
  run_case("cloth 25x25 moved_far", from_linked(173, cloth(25), 0.003f), true);
}
TEST_P(ConstraintsRelax, Cloth25MovedUnchecked) {
  // No launch asks for the skin test: the particle 0.6 skin from its reference asks for nothing.
  run_case("cloth 25x25 moved_far unchecked", from_linked(173, cloth(25), 0.003f), true, false);
}
TEST_P(ConstraintsRelax, Random1234) {
  run_case("random links", random_links(174, 1234, 3000), true);
}
TEST_P(ConstraintsRelax, Cloth256) {
  run_case("cloth 256x256", from_linked(175, cloth(256), 0.002f), false);
}

INSTANTIATE_TEST_SUITE_P(Conformance, ConstraintsRelax, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
