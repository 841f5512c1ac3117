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

namespace {
GpuImage createImageLayers(VulkanDevice& d, VkFormat format, VkExtent3D extent, uint32_t layers,
                           VkImageUsageFlags usage, bool type3d,
                           VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT) {
  GpuImage img;
  img.format = format;
  img.extent = extent;
  img.layers = layers;
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = type3d ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D;
  ici.format = format;
  ici.extent = extent;
  ici.mipLevels = 1;
  ici.arrayLayers = layers;
  ici.samples = samples;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = usage;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VK_CHECK(vkCreateImage(d.device, &ici, nullptr, &img.image));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(d.device, img.image, &req);
  uint32_t type = UINT32_MAX;
  for (uint32_t i = 0; i < d.memory.memoryTypeCount && type == UINT32_MAX; ++i)
    if ((req.memoryTypeBits & (1u << i)) && (d.memory.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT))
      type = i;
  for (uint32_t i = 0; i < d.memory.memoryTypeCount && type == UINT32_MAX; ++i)
    if (req.memoryTypeBits & (1u << i)) type = i;
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = type;
  VK_CHECK(vkAllocateMemory(d.device, &mai, nullptr, &img.memory));
  VK_CHECK(vkBindImageMemory(d.device, img.image, img.memory, 0));
  const bool depth = format == VK_FORMAT_D32_SFLOAT;
  VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.image = img.image;
  vci.viewType = type3d ? VK_IMAGE_VIEW_TYPE_3D : layers > 1 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
  vci.format = format;
  const auto aspect = static_cast<VkImageAspectFlags>(depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT);
  vci.subresourceRange = {aspect, 0, 1, 0, layers};
  VK_CHECK(vkCreateImageView(d.device, &vci, nullptr, &img.view));
  if (layers > 1)
    for (uint32_t k = 0; k < layers; ++k) {
      vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
      vci.subresourceRange = {aspect, 0, 1, k, 1};
      VK_CHECK(vkCreateImageView(d.device, &vci, nullptr, &img.layerViews.emplace_back()));
    }
  return img;
}
}  // namespace

GpuImage createImage(VulkanDevice& d, VkFormat format, VkExtent3D extent, VkImageUsageFlags usage, bool type3d) {
  return createImageLayers(d, format, extent, 1, usage, type3d);
}

GpuImage createImageArray(VulkanDevice& d, VkFormat format, VkExtent2D extent, uint32_t layers, VkImageUsageFlags usage,
                          VkSampleCountFlagBits samples) {
  return createImageLayers(d, format, {extent.width, extent.height, 1}, layers, usage, false, samples);
}

void destroyImage(VulkanDevice& d, GpuImage& img) {
  for (VkImageView v : img.layerViews) vkDestroyImageView(d.device, v, nullptr);
  if (img.view) vkDestroyImageView(d.device, img.view, nullptr);
  if (img.image) vkDestroyImage(d.device, img.image, nullptr);
  if (img.memory) vkFreeMemory(d.device, img.memory, nullptr);
  img = GpuImage{};
}

void transitionImage(VkCommandBuffer cmd, const GpuImage& img, VkImageLayout from, VkImageLayout to) {
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  b.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
  b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = img.image;
  const bool depth = img.format == VK_FORMAT_D32_SFLOAT;
  b.subresourceRange = {static_cast<VkImageAspectFlags>(depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT), 0, 1, 0,
                        img.layers};
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.imageMemoryBarrierCount = 1;
  dep.pImageMemoryBarriers = &b;
  vkCmdPipelineBarrier2(cmd, &dep);
}

VkPipelineLayout createPipelineLayout(VulkanDevice& d, VkDescriptorSetLayout setLayout, VkShaderStageFlags pushStages,
                                      uint32_t pushBytes) {
  const VkPushConstantRange range{pushStages, 0, pushBytes};
  VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pli.setLayoutCount = setLayout ? 1 : 0;
  pli.pSetLayouts = &setLayout;
  pli.pushConstantRangeCount = 1;
  pli.pPushConstantRanges = &range;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VK_CHECK(vkCreatePipelineLayout(d.device, &pli, nullptr, &layout));
  return layout;
}

void createSingleDescriptorSet(VulkanDevice& d, VkDescriptorSetLayout layout, const VkDescriptorPoolSize* sizes,
                               uint32_t sizeCount, VkDescriptorPool& pool, VkDescriptorSet& set) {
  VkDescriptorPoolCreateInfo dpi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpi.maxSets = 1;
  dpi.poolSizeCount = sizeCount;
  dpi.pPoolSizes = sizes;
  VK_CHECK(vkCreateDescriptorPool(d.device, &dpi, nullptr, &pool));
  VkDescriptorSetAllocateInfo dai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dai.descriptorPool = pool;
  dai.descriptorSetCount = 1;
  dai.pSetLayouts = &layout;
  VK_CHECK(vkAllocateDescriptorSets(d.device, &dai, &set));
}

VkShaderModule createShaderModule(VulkanDevice& d, const uint32_t* code, size_t bytes) {
  VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  ci.codeSize = bytes;
  ci.pCode = code;
  VkShaderModule m;
  VK_CHECK(vkCreateShaderModule(d.device, &ci, nullptr, &m));
  return m;
}

Submission submitAsync(VulkanDevice& d, const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = d.commandPool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  Submission s;
  VK_CHECK(vkAllocateCommandBuffers(d.device, &ai, &s.cmd));
  try {
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(s.cmd, &bi));
    record(s.cmd);
    VK_CHECK(vkEndCommandBuffer(s.cmd));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(d.device, &fci, nullptr, &s.fence));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &s.cmd;
    VK_CHECK(vkQueueSubmit(d.queue, 1, &si, s.fence));
  } catch (...) {
    if (s.fence) vkDestroyFence(d.device, s.fence, nullptr);
    vkFreeCommandBuffers(d.device, d.commandPool, 1, &s.cmd);
    throw;
  }
  return s;
}

void finishSubmission(VulkanDevice& d, Submission& s) {
  if (!s.cmd) return;
  const VkResult waited = s.fence ? vkWaitForFences(d.device, 1, &s.fence, VK_TRUE, UINT64_MAX) : VK_SUCCESS;
  if (s.fence) vkDestroyFence(d.device, s.fence, nullptr);
  vkFreeCommandBuffers(d.device, d.commandPool, 1, &s.cmd);
  s = Submission{};
  VK_CHECK(waited);
}

void submitAndWait(VulkanDevice& d, const std::function<void(VkCommandBuffer)>& record) {
  Submission s = submitAsync(d, record);
  finishSubmission(d, s);
}

}  // namespace probecast::renderer
