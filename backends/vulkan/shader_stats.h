// What the driver made of each shader, for performance work: with MOTES_VULKAN_SHADER_STATS set,
// a device that has VK_KHR_pipeline_executable_properties reports each pipeline's statistics as
// it is created (NVIDIA: registers, shared and local memory, code size; lavapipe: LLVM's
// instruction counts), one line each on stderr; when the variable names a folder, the driver's
// internal representations (where it offers any) are written there, one file per pipeline and
// representation. Unset, nothing changes: the extension is not even enabled.
#pragma once

#include <volk.h>

#include <string>
#include <vector>

namespace motes::vulkan {

struct ShaderStats {
  bool wanted = false;   ///< MOTES_VULKAN_SHADER_STATS is set and not "0"
  std::string folder;    ///< its value when that is a folder: where representations go
  bool enabled = false;  ///< the device has the extension and it was enabled

  /// Reads MOTES_VULKAN_SHADER_STATS.
  static ShaderStats from_environment();

  /// Adds the extension and its feature to a device's creation (`feature` must outlive the
  /// vkCreateDevice call), where wanted and available; says on stderr when the device lacks it.
  void request(bool available, const char* device_name, std::vector<const char*>& extensions,
               VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR& feature, const void*& next);

  /// The pipeline-creation flags that capture what report() reads (0 when not enabled).
  [[nodiscard]] VkPipelineCreateFlags create_flags() const;

  /// Prints the statistics of `pipeline` (made from shader `name`) and writes its representations.
  void report(VkDevice device, VkPipeline pipeline, const char* name) const;
};

}  // namespace motes::vulkan
