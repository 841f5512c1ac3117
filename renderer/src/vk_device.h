// Instance, device, queue, and the extension entry points the renderer uses.
#pragma once

#include <atomic>
#include <string>

#include "probecast/renderer/vulkan_context.h"
#include "vk_common.h"

namespace probecast::renderer {

struct VulkanDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkCommandPool commandPool = VK_NULL_HANDLE;
  std::string name;
  VkPhysicalDeviceMemoryProperties memory{};
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR rtProperties{};
  uint32_t maxMultiviewViewCount = 1;
  bool rayTracing = false;  // the ray-tracing extensions are enabled (the entry points below are loaded)
  bool swapchain = false;   // VK_KHR_swapchain is enabled
  std::atomic<uint32_t> validationMessages{0};

  PFN_vkCreateAccelerationStructureKHR vkCreateAccelerationStructureKHR = nullptr;
  PFN_vkDestroyAccelerationStructureKHR vkDestroyAccelerationStructureKHR = nullptr;
  PFN_vkGetAccelerationStructureBuildSizesKHR vkGetAccelerationStructureBuildSizesKHR = nullptr;
  PFN_vkCmdBuildAccelerationStructuresKHR vkCmdBuildAccelerationStructuresKHR = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR vkGetAccelerationStructureDeviceAddressKHR = nullptr;
  PFN_vkCreateRayTracingPipelinesKHR vkCreateRayTracingPipelinesKHR = nullptr;
  PFN_vkGetRayTracingShaderGroupHandlesKHR vkGetRayTracingShaderGroupHandlesKHR = nullptr;
  PFN_vkCmdTraceRaysKHR vkCmdTraceRaysKHR = nullptr;
};

void createDevice(VulkanDevice& d, const ContextOptions& options);
// Throws std::runtime_error naming `what` unless the device was made with ray tracing.
void requireRayTracing(const VulkanDevice& d, const char* what);
void destroyDevice(VulkanDevice& d);

}  // namespace probecast::renderer
