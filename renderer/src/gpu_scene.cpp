#include "gpu_scene.h"

#include <cmath>
#include <vector>

#include "probe_trace_shared.h"

namespace probecast::renderer {

void uploadGpuShading(VulkanDevice& d, const scene::Scene& s, GpuScene& g) {
  constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  destroyBuffer(d, g.triangleMaterial);
  destroyBuffer(d, g.materials);
  destroyBuffer(d, g.lights);
  g.triangleMaterial = createBufferWithData(d, s.triangleMaterial.data(), s.triangleMaterial.size() * 4, kStorage);
  std::vector<shaders::PtMaterial> mats;
  for (const scene::Material& m : s.materials)
    mats.push_back({{m.baseColor.r, m.baseColor.g, m.baseColor.b, m.metallic},
                    {m.emission.r, m.emission.g, m.emission.b, m.roughness}});
  g.materials = createBufferWithData(d, mats.data(), mats.size() * sizeof(shaders::PtMaterial), kStorage);
  std::vector<shaders::PtLight> ls;
  for (const scene::Light& l : s.lights) {
    const glm::vec3 dir = glm::length(l.direction) > 0 ? glm::normalize(l.direction) : glm::vec3(0, -1, 0);
    ls.push_back({{l.position.x, l.position.y, l.position.z, static_cast<float>(static_cast<uint32_t>(l.type))},
                  {dir.x, dir.y, dir.z, l.range},
                  {l.color.r, l.color.g, l.color.b, l.intensity},
                  {std::cos(l.outerConeAngle), std::cos(l.innerConeAngle), 0.0f, 0.0f}});
  }
  g.lights = createBufferWithData(d, ls.data(), ls.size() * sizeof(shaders::PtLight), kStorage);
  g.lightCount = static_cast<uint32_t>(ls.size());
}

void uploadGpuScene(VulkanDevice& d, const scene::Scene& s, GpuScene& g) {
  if (g.accel.tlas.handle) destroySceneAccel(d, g.accel);
  buildSceneAccel(d, s, g.accel);
  uploadGpuShading(d, s, g);
}

void destroyGpuScene(VulkanDevice& d, GpuScene& g) {
  destroySceneAccel(d, g.accel);
  destroyBuffer(d, g.triangleMaterial);
  destroyBuffer(d, g.materials);
  destroyBuffer(d, g.lights);
  g.lightCount = 0;
}

}  // namespace probecast::renderer
