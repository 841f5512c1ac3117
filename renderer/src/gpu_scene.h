// A scene on the device: acceleration structures plus the shading buffers the raygens read.
#pragma once

#include <vector>

#include "probecast/renderer/environment.h"
#include "probecast/scene/scene.h"
#include "vk_acceleration.h"

namespace probecast::renderer {

struct GpuScene {
  SceneAccel accel;
  Buffer triangleMaterial;  // uint per triangle
  Buffer materials;         // PtMaterial[]
  Buffer lights;            // PtLight[]
  Buffer emitters;          // PtEmitter[]: emissive triangles with a power CDF
  Buffer normals;           // float3 per vertex
  Buffer texcoords;         // float4 per vertex: TEXCOORD_0, TEXCOORD_1
  Buffer texels;            // packed sRGB RGBA8 of every texture
  Buffer textures;          // PtTexture[]
  Buffer environment;       // PtEnvironment
  Buffer environmentData;   // radiance, row CDF, column CDFs (PT_BINDING_ENV_DATA)
  uint32_t lightCount = 0;
  uint32_t textureCount = 0;  // in `textures`: a material's texture index beyond them reads none
  uint32_t emitterCount = 0;
  float emitterPower = 0.0f;
};

// The surfaces (normals, texture coordinates, textures) a GpuScene was last given, to tell whether
// an animated scene needs uploadGpuSurfaces again.
struct SurfaceRecord {
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> texcoords, texcoords1;
  std::vector<scene::Texture> textures;
  // Whether `s` has other surfaces than the record; the record becomes `s`'s.
  bool changedBy(const scene::Scene& s);
};

void uploadGpuScene(VulkanDevice& d, const scene::Scene& scene, GpuScene& out);  // geometry + surfaces + shading
// The vertices' normals and texture coordinates and the textures (same positions and indices),
// then the shading.
void uploadGpuSurfaces(VulkanDevice& d, const scene::Scene& scene, GpuScene& out);
void uploadGpuShading(VulkanDevice& d, const scene::Scene& scene, GpuScene& out);  // materials, lights only
// The environment the ray-tracing passes see (none when `env` is null or empty); `sampling`:
// next-event estimation importance-samples it. uploadGpuScene starts with none.
void uploadGpuEnvironment(VulkanDevice& d, const Environment* env, bool sampling, GpuScene& out);
// Flags the materials whose emission the raster client lights itself (one byte per material, as
// scene::AreaLightSet::clientLitMaterial; missing entries count as 0): the probe tracer's first
// segment skips their emission. Only the probe updater calls it; the reference camera sees all.
void markClientLitMaterials(const std::vector<uint8_t>& clientLit, GpuScene& g);
void destroyGpuScene(VulkanDevice& d, GpuScene& g);

}  // namespace probecast::renderer
