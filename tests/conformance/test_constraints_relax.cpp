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

MOTES_CONSTRAINTS_CASES(ConstraintsRelax)

INSTANTIATE_TEST_SUITE_P(Conformance, ConstraintsRelax, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
