#include "area_light_shadows.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "probecast/renderer/view_sets.h"

namespace probecast::renderer {

void planAreaLights(VulkanDevice& d, const scene::Scene& scene, const scene::AreaLightSet& set, ShadowMaps& maps,
                    AreaLightBuffers& out) {
  const glm::vec3 center = 0.5f * (scene.boundsMin + scene.boundsMax);
  const float radius = std::max(0.5f * glm::length(scene.boundsMax - scene.boundsMin), 1e-3f);
  const float fov = glm::radians(kAreaShadowFovDegrees);
  std::vector<shaders::RsAreaLight> records;
  std::vector<shaders::vec4> corners;
  maps.matrices.clear();
  for (const scene::AreaLight& l : set.lights) {
    shaders::RsAreaLight r{};
    r.radiance = {l.radiance.r, l.radiance.g, l.radiance.b, 0.0f};
    r.centroidSize = {l.centroid.x, l.centroid.y, l.centroid.z, std::sqrt(l.area)};
    r.axisTanHalf = {l.normal.x, l.normal.y, l.normal.z, std::tan(0.5f * fov)};
    r.firstCorner = static_cast<uint32_t>(corners.size());
    r.triangleCount = static_cast<uint32_t>(l.corners.size() / 3);
    for (const glm::vec3& c : l.corners) corners.push_back({c.x, c.y, c.z, 1.0f});
    // Near plane just in front of the emitter's own corners (a curved or boxy emitter included).
    float front = 0.0f;
    for (const glm::vec3& c : l.corners) front = std::max(front, glm::dot(c - l.centroid, l.normal));
    r.znear = front + std::max(1e-3f * radius, 1e-4f);
    r.zfar = std::max(2.0f * radius + glm::length(l.centroid - center), 2.0f * r.znear);
    r.shadowLayer = RS_AREA_UNSHADOWED;
    if (maps.matrices.size() < maps.maxLayers) {
      const glm::vec3 up = std::abs(l.normal.y) > 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
      r.shadowLayer = static_cast<uint32_t>(maps.matrices.size());
      maps.matrices.push_back(vulkanPerspective(fov, 1.0f, r.znear, r.zfar) *
                              glm::lookAtRH(l.centroid, l.centroid + l.normal, up));
    }
    records.push_back(r);
  }
  out.count = static_cast<uint32_t>(records.size());
  if (records.empty()) records.push_back({});
  if (corners.empty()) corners.push_back({0.0f, 0.0f, 0.0f, 0.0f});
  destroyAreaLights(d, out);
  constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  out.lights = createBufferWithData(d, records.data(), records.size() * sizeof records[0], kStorage);
  out.corners = createBufferWithData(d, corners.data(), corners.size() * sizeof corners[0], kStorage);
  // Transmissive casters are drawn into the colour layers only (drawShadowMaps), which the
  // area-light shader does not read: glass lets an area light through untinted.
  maps.transmissiveFirst = scene::leadingTrianglesBelowClass(scene, 2);
  const std::vector<shaders::RsShadowLight> none{{RS_SHADOW_NONE, 0, 0.0f, 1u}};
  uploadShadowPlan(d, none, maps.transmissiveFirst < scene.triangleCount(), maps);
}

void destroyAreaLights(VulkanDevice& d, AreaLightBuffers& b) {
  destroyBuffer(d, b.lights);
  destroyBuffer(d, b.corners);
}

}  // namespace probecast::renderer
