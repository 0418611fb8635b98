// constraints_solve against the oracle: every colour of a coloured constraint set relaxed in order,
// for two iterations (one launch per colour, each with its own constraint range, all queued before
// the host waits). ParticlePos, ParticleVel, Constraints, NeighbourRefPos and NeighbourState are
// written, every other buffer is poisoned. Positions xyz by NMSE, velocities by their largest
// difference in units of ulp(largest coordinate) / dt (below), w (radius, inverse mass) bitwise;
// particles in no constraint must come back bitwise as written; the rebuild word of NeighbourState
// must be set exactly when a particle ends 0.45 skin or more from its NeighbourRefPos, tested in
// the launches with MOTES_FLAG_SKIN_CHECK (the last sweep, as the core launches them; none in the
// "unchecked" case, which must leave the word alone), nothing else of it may change.
//
// Layouts: a rope and a 25 x 25 cloth (with bend links) stretched and pinned, constraints among
// random particles of a random world (pinned ones included: inverse mass 0), none at all, and a
// 256 x 256 cloth (more workgroups than one dispatch dimension holds under the 2D test).
//
// Tolerance: positions NMSE 1e-10, as particles_integrate: the shared constraint_correction on the
// same floats (openmp: bitwise), a GPU's fused multiply-adds moving a component by an ulp or two.
// A projection changes a velocity by its displacement / dt, so a position that rounds the other
// way on another backend (an ulp of the coordinate) moves the velocity by ulp / dt: 2.4e-4 m/s
// for the 2.56 m wide cloth at dt = 1e-3 s, whose velocities are about 1 m/s. Velocities: at most
// 16 ulp / dt apart (two sweeps, each particle in up to 12 constraints per sweep). First measured
// as an NMSE on an H100: 2.5e-10 (CUDA) and 5.1e-10 (Vulkan) for the 256 x 256 cloth, about
// 0.1 ulp / dt RMS.
#include <gtest/gtest.h>

#include "constraints_cases.h"

namespace motes_conf {
namespace {

class ConstraintsSolve : public ConstraintsCaseTest {
 protected:
  void run_case(const std::string& layout, LinkedCase c, bool far, bool checked = true) {
    ConstraintsCaseTest::run_case(false, layout, std::move(c), far, checked);
  }
};

MOTES_CONSTRAINTS_CASES(ConstraintsSolve)

INSTANTIATE_TEST_SUITE_P(Conformance, ConstraintsSolve, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
