// The SPIR-V of the viewer's shaders (viewer/shaders), compiled and embedded at build time
// (viewer/CMakeLists.txt), looked up by file name ("sphere.frag").
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace motes::viewer {

struct Shader {
  const char* name;
  const std::uint32_t* words;
  std::size_t word_count;
};

/// Every embedded shader (generated file).
std::span<const Shader> shader_table();

}  // namespace motes::viewer
