#include "vk_resources.h"

#include <algorithm>
#include <cstring>

namespace probecast::renderer {
namespace {

uint32_t findMemoryType(const VulkanDevice& d, uint32_t typeBits, VkMemoryPropertyFlags flags) {
  for (uint32_t i = 0; i < d.memory.memoryTypeCount; ++i)
    if ((typeBits & (1u << i)) && (d.memory.memoryTypes[i].propertyFlags & flags) == flags) return i;
  throw std::runtime_error("no host-visible coherent Vulkan memory type");
}

}  // namespace

Buffer createBuffer(VulkanDevice& d, VkDeviceSize size, VkBufferUsageFlags usage) {
  Buffer b;
  b.size = std::max<VkDeviceSize>(size, 4);
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = b.size;
  bci.usage = usage;
  VK_CHECK(vkCreateBuffer(d.device, &bci, nullptr, &b.buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(d.device, b.buffer, &req);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.pNext = (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) ? &flags : nullptr;
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = findMemoryType(d, req.memoryTypeBits,
                                       VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  VK_CHECK(vkAllocateMemory(d.device, &mai, nullptr, &b.memory));
  VK_CHECK(vkBindBufferMemory(d.device, b.buffer, b.memory, 0));
  VK_CHECK(vkMapMemory(d.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
  if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) {
    VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    info.buffer = b.buffer;
    b.address = vkGetBufferDeviceAddress(d.device, &info);
  }
  return b;
}

void destroyBuffer(VulkanDevice& d, Buffer& b) {
  if (b.buffer) vkDestroyBuffer(d.device, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(d.device, b.memory, nullptr);
  b = Buffer{};
}

Buffer createBufferWithData(VulkanDevice& d, const void* data, size_t bytes, VkBufferUsageFlags usage) {
  Buffer b = createBuffer(d, bytes, usage);
  if (bytes) std::memcpy(b.mapped, data, bytes);
  return b;
}

void submitAndWait(VulkanDevice& d, const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = d.commandPool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd;
  VK_CHECK(vkAllocateCommandBuffers(d.device, &ai, &cmd));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
  record(cmd);
  VK_CHECK(vkEndCommandBuffer(cmd));
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence;
  VK_CHECK(vkCreateFence(d.device, &fci, nullptr, &fence));
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  VK_CHECK(vkQueueSubmit(d.queue, 1, &si, fence));
  VK_CHECK(vkWaitForFences(d.device, 1, &fence, VK_TRUE, UINT64_MAX));
  vkDestroyFence(d.device, fence, nullptr);
  vkFreeCommandBuffers(d.device, d.commandPool, 1, &cmd);
}

}  // namespace probecast::renderer
