// Graphics pipelines for offscreen dynamic rendering: scene vertex streams, depth test, dynamic
// viewport and scissor. One description, one create call; destroy with vkDestroyPipeline.
#pragma once

#include <cstddef>
#include <cstdint>

#include "vk_device.h"

namespace probecast::renderer {

struct GraphicsPipelineDesc {
  const uint32_t* vertexCode = nullptr;
  size_t vertexBytes = 0;
  const uint32_t* fragmentCode = nullptr;  // null: depth only (no colour attachment)
  size_t fragmentBytes = 0;
  // Vertex streams bound in this order: 1 = positions (float3); 3 = positions, normals (float3),
  // texture coordinates (float2).
  uint32_t vertexStreams = 3;
  bool depthBias = false;                  // slope-scaled bias, for shadow maps
  uint32_t viewMask = 0;                   // multiview: one bit per view rendered by the pass
  VkFormat colorFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
  VkFormat depthFormat = VK_FORMAT_D32_SFLOAT;
  VkPipelineLayout layout = VK_NULL_HANDLE;
};

VkPipeline createGraphicsPipeline(VulkanDevice& d, const GraphicsPipelineDesc& desc);

// An attachment cleared at the start of rendering (colour to 0, depth to 1).
VkRenderingAttachmentInfo clearedAttachment(VkImageView view, VkImageLayout layout, VkAttachmentStoreOp store);
// Viewport and scissor covering width × height.
void setViewportScissor(VkCommandBuffer cmd, uint32_t width, uint32_t height);

}  // namespace probecast::renderer
