// Kernel calls queued by a GPU backend until the host must wait, and the shortest cycle they
// repeat (a step: the five families once per substep). The Vulkan backend records that cycle up to
// 16 times back to back into a command buffer, the CUDA backend captures it once into a CUDA
// graph; both replay it.
#pragma once

#include <cstddef>
#include <vector>

#include "motes/backend/device.h"

namespace motes {

/// One queued kernel-family call.
struct KernelCall {
  Kernel kernel = Kernel::Count;
  shared::StepParams params{};
};

/// Same family with bit-identical parameters.
bool same_call(const KernelCall& a, const KernelCall& b);

/// True when both lists hold the same calls in the same order.
bool same_calls(const std::vector<KernelCall>& a, const std::vector<KernelCall>& b);

/// The shortest period p <= max_period that divides calls.size() and with which the calls repeat
/// (calls[i] == calls[i % p]); calls.size() when there is none.
std::size_t repeating_period(const std::vector<KernelCall>& calls, std::size_t max_period = 1024);

}  // namespace motes
