// Whether a program's queue can run motes (motes/vulkan_interop.h), apart from any device: the
// rule alone, so that tests can try families a machine's devices lack.
#pragma once

#include <vulkan/vulkan_core.h>

#include <cstdint>
#include <span>
#include <string>

namespace motes::vulkan {

/// Empty when queue `index` of family `family` exists among `families` (a physical device's
/// queue families) and computes; otherwise why not, as a sentence's end ("queue family 2 has no
/// compute ...").
std::string queue_family_error(std::span<const VkQueueFamilyProperties> families,
                               std::uint32_t family, std::uint32_t index);

}  // namespace motes::vulkan
