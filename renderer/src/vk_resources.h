// Buffers and one-off command submission.
#pragma once

#include <vector>

#include <cstddef>
#include <functional>

#include "vk_device.h"

namespace probecast::renderer {

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  void* mapped = nullptr;  // host-visible buffers stay mapped
  VkDeviceAddress address = 0;
};

// Host-visible, coherent, mapped; with a device address when `usage` asks for one.
Buffer createBuffer(VulkanDevice& d, VkDeviceSize size, VkBufferUsageFlags usage);
void destroyBuffer(VulkanDevice& d, Buffer& b);
// Creates a buffer holding `bytes` (at least 4 bytes are allocated so empty arrays stay valid).
Buffer createBufferWithData(VulkanDevice& d, const void* data, size_t bytes, VkBufferUsageFlags usage);

struct GpuImage {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent3D extent{};
  uint32_t layers = 1;
  std::vector<VkImageView> layerViews;  // 2D arrays only: one 2D view per layer
};

// A 2D or 3D image (depth > 1 or `type3d`) with one mip level and a view of all of it.
GpuImage createImage(VulkanDevice& d, VkFormat format, VkExtent3D extent, VkImageUsageFlags usage, bool type3d = false);
// A 2D array of `layers` layers: `view` sees them all (2D array), `layerViews[k]` layer k alone.
// `samples` > 1: a multisampled target (rendered into, then resolved).
GpuImage createImageArray(VulkanDevice& d, VkFormat format, VkExtent2D extent, uint32_t layers, VkImageUsageFlags usage,
                          VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT);
void destroyImage(VulkanDevice& d, GpuImage& image);
// A whole-image layout transition (synchronisation2, all commands): simple and correct, not fast.
void transitionImage(VkCommandBuffer cmd, const GpuImage& image, VkImageLayout from, VkImageLayout to);

// A pipeline layout of at most one descriptor set (null: none) and one push-constant range.
VkPipelineLayout createPipelineLayout(VulkanDevice& d, VkDescriptorSetLayout setLayout, VkShaderStageFlags pushStages,
                                      uint32_t pushBytes);

// A pool sized for exactly one set of `layout`, and that set.
void createSingleDescriptorSet(VulkanDevice& d, VkDescriptorSetLayout layout, const VkDescriptorPoolSize* sizes,
                               uint32_t sizeCount, VkDescriptorPool& pool, VkDescriptorSet& set);

// A shader module from embedded SPIR-V.
VkShaderModule createShaderModule(VulkanDevice& d, const uint32_t* code, size_t bytes);

// Records commands into a fresh command buffer, submits it and waits.
void submitAndWait(VulkanDevice& d, const std::function<void(VkCommandBuffer)>& record);

// Work submitted without waiting: the host goes on while the device runs it. finishSubmission
// waits for it and frees it (a default one is nothing to wait for).
struct Submission {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
};
Submission submitAsync(VulkanDevice& d, const std::function<void(VkCommandBuffer)>& record);
void finishSubmission(VulkanDevice& d, Submission& s);

}  // namespace probecast::renderer
