// Shadow maps of a scene's punctual lights, for the raster client: one layer of a D32 2D array
// per face — six 90° faces for a point light (+x −x +y −y +z −z; spot lights wider than 150° are
// treated the same), one perspective layer for a spot light, one orthographic layer over the
// scene for a directional light — drawn depth-only with a slope-scaled bias; non-opaque triangles
// with shadow.frag (cut-outs pass light, transmissive surfaces dithered). The fragment shader
// reads them through RsShadowLight / RsShadowLayer (raster_shared.h). Lights past the layer budget
// (in scene order) stay unshadowed.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "gpu_scene.h"
#include "probecast/scene/scene.h"
#include "raster_shared.h"
#include "vk_resources.h"

namespace probecast::renderer {

struct ShadowMaps {
  uint32_t size = 1024;      // texels per side of a layer
  uint32_t maxLayers = 24;
  GpuImage depth;            // at least 2 layers, so the shaders always see an array
  Buffer lights;             // RsShadowLight per scene light
  Buffer layers;             // RsShadowLayer per layer in use
  std::vector<glm::mat4> matrices;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;         // opaque triangles, depth only
  VkPipeline cutoutPipeline = VK_NULL_HANDLE;   // the rest, through shadow.frag
  bool dirty = true;         // planned but not drawn yet
  double lastDrawMs = 0.0;
};

// `materials`: a set layout with the raster client's material bindings (RS_BINDING_*).
void createShadowMaps(VulkanDevice& d, uint32_t size, uint32_t maxLayers, VkDescriptorSetLayout materials,
                      ShadowMaps& out);
// Plans the layers for the scene's lights (bounds from the scene); drawn at the next draw call.
void planShadowMaps(VulkanDevice& d, const scene::Scene& scene, ShadowMaps& maps);
// Uploads a plan made in maps.matrices (and one record per light) and sizes the depth array for it;
// the layers are drawn at the next drawShadowMaps.
void uploadShadowPlan(VulkanDevice& d, const std::vector<shaders::RsShadowLight>& records, ShadowMaps& maps);
// Draws every planned layer of `gpu`'s triangles if the plan changed since the last draw;
// `materials` is a set of the layout given at creation.
void drawShadowMaps(VulkanDevice& d, const GpuScene& gpu, uint32_t indexCount, VkDescriptorSet materials,
                    ShadowMaps& maps);
void destroyShadowMaps(VulkanDevice& d, ShadowMaps& maps);

}  // namespace probecast::renderer
