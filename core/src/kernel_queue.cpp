// The shortest repeating cycle of queued kernel calls (motes/backend/kernel_queue.h).
#include "motes/backend/kernel_queue.h"

#include <algorithm>
#include <cstring>

namespace motes {

bool same_call(const KernelCall& a, const KernelCall& b) {
  return a.kernel == b.kernel && std::memcmp(&a.params, &b.params, sizeof(shared::StepParams)) == 0;
}

bool same_calls(const std::vector<KernelCall>& a, const std::vector<KernelCall>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), same_call);
}

std::size_t repeating_period(const std::vector<KernelCall>& calls, std::size_t max_period) {
  const std::size_t n = calls.size();
  for (std::size_t p = 1; p <= std::min(n, max_period); ++p) {
    if (n % p != 0) continue;
    bool repeats = true;
    for (std::size_t i = p; i < n && repeats; ++i) repeats = same_call(calls[i], calls[i % p]);
    if (repeats) return p;
  }
  return n;
}

}  // namespace motes
