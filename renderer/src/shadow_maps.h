// Shadow maps of a scene's punctual lights, for the raster client: one layer of a D32 2D array
// per face — six 90° faces for a point light (+x −x +y −y +z −z; spot lights wider than 150° are
// treated the same), one perspective layer for a spot light, and for a directional light either
// one orthographic layer over the scene (1 cascade) or 2..4 cascades fitted to slices of the
// current view set's depth range (fitShadowCascades) — drawn depth-only with a slope-scaled bias;
// cut-outs with shadow.frag (their holes pass light). Transmissive triangles (scene.h's rule) go
// to a colour layer per depth layer instead (shadow_transmit.frag): the product of their T in front
// of the opaque depth and the nearest one's depth, so light through glass is tinted and attenuated
// as the tracers' visibility rays have it. The fragment shader reads them through RsShadowLight /
// RsShadowLayer (raster_shared.h). Lights past
// the layer budget (in scene order) stay unshadowed; a directional light takes all its cascades or
// none.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "gpu_scene.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/scene/scene.h"
#include "raster_shared.h"
#include "vk_resources.h"

namespace probecast::renderer {

struct ShadowMaps {
  uint32_t size = 1024;      // texels per side of a layer
  uint32_t maxLayers = 24;
  GpuImage depth;            // at least 2 layers, so the shaders always see an array
  GpuImage transmit;         // RGBA16F, a layer per depth layer; 1 × 1 (clear) without transmissive triangles
  uint32_t transmissiveFirst = 0;  // scene triangle index where the transmissive run starts
  Buffer lights;             // RsShadowLight per scene light
  Buffer layers;             // RsShadowLayer per layer in use
  uint32_t cascades = 1;     // per directional light, 1..RS_MAX_CASCADES
  std::vector<glm::mat4> matrices;
  std::vector<glm::vec4> texels;          // RsShadowLayer::texel per layer (y = 1: perspective)
  std::vector<uint8_t> layerDirty;        // per layer: planned or refitted, not drawn yet
  struct Sun {
    uint32_t firstLayer, count;  // its layers (count < cascades where the budget ran out)
    glm::vec3 direction;  // unit, the way the light travels
  };
  std::vector<Sun> suns;                  // directional lights with cascades (cascades > 1)
  glm::vec3 sceneMin{0.0f}, sceneMax{0.0f};
  std::vector<float> fittedViews;         // the view set the cascades were fitted to
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;         // opaque triangles, depth only
  VkPipeline cutoutPipeline = VK_NULL_HANDLE;   // cut-outs, through shadow.frag
  VkPipeline transmitPipeline = VK_NULL_HANDLE; // transmissive triangles into `transmit`
  double lastDrawMs = 0.0;
  uint32_t lastLayersDrawn = 0;
};

// Moved geometry under the same lights: marks for drawing the layers whose light volume holds the
// box around a moved triangle's old and new corners (`before`, `after`: positions of the same
// triangles `indices`); the other layers keep their depth. Returns the layers marked.
uint32_t markLayersOfMovedGeometry(const std::vector<glm::vec3>& before, const std::vector<glm::vec3>& after,
                                   const std::vector<uint32_t>& indices, ShadowMaps& maps);

// `materials`: a set layout with the raster client's material bindings (RS_BINDING_*).
// `cascades`: layers per directional light (1..RS_MAX_CASCADES; 1 = one layer over the scene).
// The depth-only pipelines of the scene's triangles from a point of view (shadow.vert): opaque, and
// cut-out with shadow.frag's alpha-test discard. Shadow layers and probe depth cubes both use them.
void createDepthPipelines(VulkanDevice& d, VkPipelineLayout layout, bool depthBias, VkPipeline& opaque,
                          VkPipeline& cutout);

void createShadowMaps(VulkanDevice& d, uint32_t size, uint32_t maxLayers, uint32_t cascades,
                      VkDescriptorSetLayout materials, ShadowMaps& out);
// Plans the layers for the scene's lights (bounds from the scene); drawn at the next draw call.
void planShadowMaps(VulkanDevice& d, const scene::Scene& scene, ShadowMaps& maps);
// Fits the cascades of every directional light to the view set (a no-op for the same views as the
// last fit, or with 1 cascade): only the refitted layers are drawn again.
void fitShadowCascades(const std::vector<ViewInfo>& views, ShadowMaps& maps);
// Uploads a plan made in maps.matrices (and one record per light) and sizes the depth array (and,
// with transmissive casters, the colour layers) for it; the layers are drawn at the next drawShadowMaps.
void uploadShadowPlan(VulkanDevice& d, const std::vector<shaders::RsShadowLight>& records, bool transmissive,
                      ShadowMaps& maps);
// Draws every planned layer of `gpu`'s triangles if the plan changed since the last draw;
// `materials` is a set of the layout given at creation.
void drawShadowMaps(VulkanDevice& d, const GpuScene& gpu, uint32_t indexCount, VkDescriptorSet materials,
                    ShadowMaps& maps);
void destroyShadowMaps(VulkanDevice& d, ShadowMaps& maps);

}  // namespace probecast::renderer
