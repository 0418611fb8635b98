// MOTES_VULKAN_SHADER_STATS: the driver's statistics of each pipeline (shader_stats.h).
#include "shader_stats.h"

#include <fmt/format.h>

#include <atomic>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace motes::vulkan {

namespace {

std::string statistic_value(const VkPipelineExecutableStatisticKHR& s) {
  switch (s.format) {
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
      return s.value.b32 ? "true" : "false";
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
      return fmt::format("{}", s.value.i64);
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
      return fmt::format("{}", s.value.u64);
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_FLOAT64_KHR:
      return fmt::format("{:g}", s.value.f64);
    default:
      return "?";
  }
}

/// A representation's name as a file name: letters, digits, '-' and '_' kept, the rest '_'.
std::string file_part(const char* name) {
  std::string out;
  for (const char* c = name; *c != '\0'; ++c) {
    out += std::isalnum(static_cast<unsigned char>(*c)) != 0 || *c == '-' ? *c : '_';
  }
  return out;
}

}  // namespace

ShaderStats ShaderStats::from_environment() {
  ShaderStats s;
  const char* env = std::getenv("MOTES_VULKAN_SHADER_STATS");
  if (env == nullptr || *env == '\0' || std::strcmp(env, "0") == 0) return s;
  s.wanted = true;
  std::error_code ec;
  if (std::filesystem::is_directory(env, ec)) s.folder = env;
  return s;
}

void ShaderStats::request(bool available, const char* device_name,
                          std::vector<const char*>& extensions,
                          VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR& feature,
                          const void*& next) {
  if (!wanted) return;
  if (!available) {
    static std::atomic<bool> said{false};  // one line a process, not one a device made
    if (said.exchange(true)) return;
    fmt::print(stderr, "vulkan shader statistics: {} lacks {}; none reported\n", device_name,
               VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
    return;
  }
  extensions.push_back(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
  feature = {};
  feature.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR;
  feature.pipelineExecutableInfo = VK_TRUE;
  feature.pNext = const_cast<void*>(next);
  next = &feature;
  enabled = true;
}

VkPipelineCreateFlags ShaderStats::create_flags() const {
  if (!enabled) return 0;
  VkPipelineCreateFlags flags = VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR;
  if (!folder.empty()) flags |= VK_PIPELINE_CREATE_CAPTURE_INTERNAL_REPRESENTATIONS_BIT_KHR;
  return flags;
}

void ShaderStats::report(VkDevice device, VkPipeline pipeline, const char* name) const {
  if (!enabled || pipeline == VK_NULL_HANDLE) return;
  VkPipelineInfoKHR info{};
  info.sType = VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR;
  info.pipeline = pipeline;
  std::uint32_t executables = 0;
  if (vkGetPipelineExecutablePropertiesKHR(device, &info, &executables, nullptr) != VK_SUCCESS) {
    return;
  }
  std::vector<VkPipelineExecutablePropertiesKHR> props(
      executables, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR, nullptr, 0, {}, {}, 0});
  vkGetPipelineExecutablePropertiesKHR(device, &info, &executables, props.data());
  for (std::uint32_t e = 0; e < executables; ++e) {
    VkPipelineExecutableInfoKHR exe{};
    exe.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR;
    exe.pipeline = pipeline;
    exe.executableIndex = e;
    std::uint32_t count = 0;
    vkGetPipelineExecutableStatisticsKHR(device, &exe, &count, nullptr);
    std::vector<VkPipelineExecutableStatisticKHR> stats(count);
    for (VkPipelineExecutableStatisticKHR& s : stats) {
      s.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR;
    }
    vkGetPipelineExecutableStatisticsKHR(device, &exe, &count, stats.data());
    std::string line = fmt::format("vulkan shader statistics: {}", name);
    if (executables > 1) line += fmt::format(" ({})", props[e].name);
    line += ":";
    for (std::uint32_t k = 0; k < count; ++k) {
      line += fmt::format("{} {} {}", k == 0 ? "" : ",", stats[k].name, statistic_value(stats[k]));
    }
    fmt::print(stderr, "{}\n", line);
    if (folder.empty()) continue;
    std::uint32_t irs = 0;
    vkGetPipelineExecutableInternalRepresentationsKHR(device, &exe, &irs, nullptr);
    std::vector<VkPipelineExecutableInternalRepresentationKHR> ir(irs);
    for (VkPipelineExecutableInternalRepresentationKHR& r : ir) {
      r.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INTERNAL_REPRESENTATION_KHR;
    }
    vkGetPipelineExecutableInternalRepresentationsKHR(device, &exe, &irs, ir.data());
    std::vector<std::vector<char>> data(irs);
    for (std::uint32_t k = 0; k < irs; ++k) {
      data[k].resize(ir[k].dataSize);
      ir[k].pData = data[k].data();
    }
    vkGetPipelineExecutableInternalRepresentationsKHR(device, &exe, &irs, ir.data());
    for (std::uint32_t k = 0; k < irs; ++k) {
      const std::filesystem::path path =
          std::filesystem::path(folder) /
          fmt::format("{}.{}{}.{}", name, executables > 1 ? fmt::format("{}.", e) : "",
                      file_part(ir[k].name), ir[k].isText ? "txt" : "bin");
      std::ofstream out(path, std::ios::binary);
      const std::size_t bytes = ir[k].isText && !data[k].empty() && data[k].back() == '\0'
                                    ? data[k].size() - 1
                                    : data[k].size();
      out.write(data[k].data(), static_cast<std::streamsize>(bytes));
      if (!out) fmt::print(stderr, "vulkan shader statistics: cannot write {}\n", path.string());
    }
  }
}

}  // namespace motes::vulkan
