// Graphics pipelines for offscreen dynamic rendering: scene vertex streams, depth test, dynamic
// viewport and scissor. One description, one create call; destroy with vkDestroyPipeline.
#pragma once

#include <cstddef>
#include <cstdint>

#include "vk_device.h"

namespace probecast::renderer {

// Colour blending of a pass: none (depth written), or depth-tested passes that do not write depth
// and combine the colour with what is there: dst · src, or dst + src (alpha kept), or dst · src
// with the smaller alpha kept (shadow maps' transmittance layers).
enum class ColorBlend { None, Multiply, Add, MultiplyMinAlpha };

struct GraphicsPipelineDesc {
  const uint32_t* vertexCode = nullptr;
  size_t vertexBytes = 0;
  const uint32_t* fragmentCode = nullptr;  // null: depth only (no colour attachment)
  size_t fragmentBytes = 0;
  // Vertex streams bound in this order: 1 = positions (float3); 3 = positions, normals (float3),
  // texture coordinates (float4: TEXCOORD_0, TEXCOORD_1).
  uint32_t vertexStreams = 3;
  bool depthBias = false;                  // slope-scaled bias, for shadow maps
  ColorBlend blend = ColorBlend::None;
  uint32_t viewMask = 0;                   // multiview: one bit per view rendered by the pass
  VkFormat colorFormat = VK_FORMAT_R32G32B32A32_SFLOAT;  // UNDEFINED: no colour attachment
  VkFormat depthFormat = VK_FORMAT_D32_SFLOAT;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;  // of the attachments (MSAA)
};

VkPipeline createGraphicsPipeline(VulkanDevice& d, const GraphicsPipelineDesc& desc);

// An attachment cleared at the start of rendering (colour to 0, depth to 1).
VkRenderingAttachmentInfo clearedAttachment(VkImageView view, VkImageLayout layout, VkAttachmentStoreOp store);
// Viewport and scissor covering width × height.
void setViewportScissor(VkCommandBuffer cmd, uint32_t width, uint32_t height);

}  // namespace probecast::renderer
