// The SPIR-V of every shader in shaders/*.comp, compiled and embedded at build time
// (cmake/MotesShaders.cmake), looked up by the shader's file stem.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace motes::vulkan {

struct Shader {
  const char* name;  ///< file stem, e.g. "contacts_compute"
  const std::uint32_t* words;
  std::size_t word_count;
};

/// Every embedded shader (generated file).
std::span<const Shader> shader_table();

/// The shader called `name`, or nullptr.
inline const Shader* find_shader(std::string_view name) {
  for (const Shader& s : shader_table()) {
    if (name == s.name) return &s;
  }
  return nullptr;
}

}  // namespace motes::vulkan
