// The oracle of constraints_relax (reference.h has the contract): the sweeps over the colours, each
// colour by the oracle of constraints_solve.
#include "reference.h"

namespace motes_ref {

bool constraints_relax(Particles& particles, const std::vector<Constraint>& constraints,
                       const std::vector<uint>& colours, const StepParams& p,
                       const std::vector<vec4>& ref) {
  bool moved = false;
  for (uint sweep = 0; sweep < p.constraint_sweeps; ++sweep) {
    for (uint k = 0; k < p.constraint_count; ++k) {
      StepParams colour = p;
      colour.constraint_first = colours[k];
      colour.constraint_count = colours[k + 1] - colours[k];
      if (sweep + 1 != p.constraint_sweeps) colour.flags &= ~MOTES_FLAG_SKIN_CHECK;
      moved = constraints_solve(particles, constraints, colour, ref) || moved;
    }
  }
  return moved;
}

}  // namespace motes_ref
