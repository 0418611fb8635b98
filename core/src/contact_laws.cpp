#include "contact_laws.h"

#include <algorithm>

namespace motes {

std::vector<shared::ContactLaw> contact_law_table(const std::vector<Material>& materials) {
  const std::size_t m = materials.size();
  std::vector<shared::ContactLaw> table(m * m);
  for (std::size_t a = 0; a < m; ++a) {
    for (std::size_t b = 0; b < m; ++b) {
      const Material& x = materials[a];
      const Material& y = materials[b];
      double mu = -1.0;
      if (x.friction >= 0.0 && y.friction >= 0.0) {
        mu = std::min(x.friction, y.friction);
      } else if (x.friction >= 0.0 || y.friction >= 0.0) {
        mu = std::max(x.friction, y.friction);
      }
      shared::ContactLaw& law = table[a * m + b];
      law.stiffness = static_cast<float>(0.5 * (x.stiffness + y.stiffness));
      law.damping = static_cast<float>(0.5 * (x.damping + y.damping));
      law.tangential = static_cast<float>(0.5 * (x.tangential + y.tangential));
      law.friction = static_cast<float>(mu);
      law.restitution = static_cast<float>(0.5 * (x.restitution + y.restitution));
    }
  }
  return table;
}

}  // namespace motes
