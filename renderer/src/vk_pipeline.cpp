#include "vk_pipeline.h"

#include "vk_resources.h"

namespace probecast::renderer {

VkPipeline createGraphicsPipeline(VulkanDevice& d, const GraphicsPipelineDesc& desc) {
  const bool depthOnly = desc.fragmentCode == nullptr;
  const bool colorless = depthOnly || desc.colorFormat == VK_FORMAT_UNDEFINED;
  const VkShaderModule vs = createShaderModule(d, desc.vertexCode, desc.vertexBytes);
  const VkShaderModule fs = depthOnly ? VK_NULL_HANDLE : createShaderModule(d, desc.fragmentCode, desc.fragmentBytes);
  VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                               {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vs;
  stages[0].pName = "main";
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = fs;
  stages[1].pName = "main";
  const VkVertexInputBindingDescription vb[3] = {
      {0, 12, VK_VERTEX_INPUT_RATE_VERTEX}, {1, 12, VK_VERTEX_INPUT_RATE_VERTEX}, {2, 16, VK_VERTEX_INPUT_RATE_VERTEX}};
  const VkVertexInputAttributeDescription va[3] = {
      {0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}, {1, 1, VK_FORMAT_R32G32B32_SFLOAT, 0}, {2, 2, VK_FORMAT_R32G32B32A32_SFLOAT, 0}};
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = desc.vertexStreams;
  vi.pVertexBindingDescriptions = vb;
  vi.vertexAttributeDescriptionCount = desc.vertexStreams;
  vi.pVertexAttributeDescriptions = va;
  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo vps{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vps.viewportCount = 1;
  vps.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = VK_CULL_MODE_NONE;  // scenes are two-sided, as in the path tracer
  rs.lineWidth = 1.0f;
  rs.depthBiasEnable = desc.depthBias ? VK_TRUE : VK_FALSE;
  rs.depthBiasConstantFactor = 1.0f;
  rs.depthBiasSlopeFactor = 1.5f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = desc.samples;
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = desc.blend == ColorBlend::None ? VK_TRUE : VK_FALSE;
  ds.depthCompareOp = VK_COMPARE_OP_LESS;
  VkPipelineColorBlendAttachmentState cba{};
  cba.colorWriteMask = 0xF;
  if (desc.blend != ColorBlend::None) {
    cba.blendEnable = VK_TRUE;
    const bool multiply = desc.blend == ColorBlend::Multiply || desc.blend == ColorBlend::MultiplyMinAlpha;
    cba.srcColorBlendFactor = multiply ? VK_BLEND_FACTOR_ZERO : VK_BLEND_FACTOR_ONE;
    cba.dstColorBlendFactor = multiply ? VK_BLEND_FACTOR_SRC_COLOR : VK_BLEND_FACTOR_ONE;
    cba.colorBlendOp = VK_BLEND_OP_ADD;
    cba.srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
    cba.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    cba.alphaBlendOp = desc.blend == ColorBlend::MultiplyMinAlpha ? VK_BLEND_OP_MIN : VK_BLEND_OP_ADD;
  }
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = colorless ? 0 : 1;
  cb.pAttachments = &cba;
  const VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dys{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dys.dynamicStateCount = 2;
  dys.pDynamicStates = dyn;
  VkPipelineRenderingCreateInfo rci{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  rci.viewMask = desc.viewMask;
  rci.colorAttachmentCount = colorless ? 0 : 1;
  rci.pColorAttachmentFormats = &desc.colorFormat;
  rci.depthAttachmentFormat = desc.depthFormat;
  VkGraphicsPipelineCreateInfo gci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  gci.pNext = &rci;
  gci.stageCount = depthOnly ? 1 : 2;
  gci.pStages = stages;
  gci.pVertexInputState = &vi;
  gci.pInputAssemblyState = &ia;
  gci.pViewportState = &vps;
  gci.pRasterizationState = &rs;
  gci.pMultisampleState = &ms;
  gci.pDepthStencilState = &ds;
  gci.pColorBlendState = &cb;
  gci.pDynamicState = &dys;
  gci.layout = desc.layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VK_CHECK(vkCreateGraphicsPipelines(d.device, VK_NULL_HANDLE, 1, &gci, nullptr, &pipeline));
  vkDestroyShaderModule(d.device, vs, nullptr);
  if (fs) vkDestroyShaderModule(d.device, fs, nullptr);
  return pipeline;
}

VkRenderingAttachmentInfo clearedAttachment(VkImageView view, VkImageLayout layout, VkAttachmentStoreOp store) {
  VkRenderingAttachmentInfo a{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  a.imageView = view;
  a.imageLayout = layout;
  a.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  a.storeOp = store;
  if (layout == VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL)
    a.clearValue.depthStencil = {1.0f, 0};
  else
    a.clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
  return a;
}

void setViewportScissor(VkCommandBuffer cmd, uint32_t width, uint32_t height) {
  const VkViewport viewport{0, 0, static_cast<float>(width), static_cast<float>(height), 0, 1};
  const VkRect2D scissor{{0, 0}, {width, height}};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

}  // namespace probecast::renderer
