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

  // Emissive triangles, chosen for next-event estimation in proportion to luminance × area.
  destroyBuffer(d, g.emitters);
  std::vector<shaders::PtEmitter> emitters;
  double total = 0.0;
  for (uint32_t t = 0; t < s.triangleCount(); ++t) {
    const glm::vec3 e = s.materials[s.triangleMaterial[t]].emission;
    const float luma = 0.2126f * e.r + 0.7152f * e.g + 0.0722f * e.b;
    const glm::vec3 p0 = s.positions[s.indices[3 * t]], p1 = s.positions[s.indices[3 * t + 1]],
                    p2 = s.positions[s.indices[3 * t + 2]];
    const float area = 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
    const float power = luma * area;
    if (!(power > 0.0f) || !std::isfinite(power)) continue;
    total += power;
    emitters.push_back({t, static_cast<float>(total), power, 0.0f});
  }
  g.emitters = createBufferWithData(d, emitters.data(), emitters.size() * sizeof(shaders::PtEmitter), kStorage);
  g.emitterCount = static_cast<uint32_t>(emitters.size());
  g.emitterPower = static_cast<float>(total);
  if (!emitters.empty()) {  // the last CDF entry equals the total exactly, so a draw never runs past it
    static_cast<shaders::PtEmitter*>(g.emitters.mapped)[emitters.size() - 1].cdf = g.emitterPower;
  }
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
  destroyBuffer(d, g.emitters);
  g.lightCount = 0;
  g.emitterCount = 0;
}

}  // namespace probecast::renderer
