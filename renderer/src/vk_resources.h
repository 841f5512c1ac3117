// Buffers and one-off command submission.
#pragma once

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

// Records commands into a fresh command buffer, submits it and waits.
void submitAndWait(VulkanDevice& d, const std::function<void(VkCommandBuffer)>& record);

}  // namespace probecast::renderer
