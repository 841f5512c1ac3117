#include "vk_acceleration.h"

#include <cstring>
#include <stdexcept>
#include <vector>

namespace probecast::renderer {
namespace {

constexpr VkBufferUsageFlags kInputUsage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                           VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                           VK_BUFFER_USAGE_INDEX_BUFFER_BIT;  // the raster client draws them too

// Builds `out` (mode BUILD), or refits it in place (`refit`: mode UPDATE from itself; it must have
// been built with `updatable`).
void build(VulkanDevice& d, VkAccelerationStructureTypeKHR type, const VkAccelerationStructureGeometryKHR& geometry,
           uint32_t primitives, bool updatable, bool refit, AccelerationStructure& out) {
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = type;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
               (updatable ? VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR : 0);
  info.mode = refit ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &geometry;
  VkDeviceSize scratchBytes = out.updateScratch;
  if (!refit) {
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    d.vkGetAccelerationStructureBuildSizesKHR(d.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                                              &primitives, &sizes);
    out.storage = createBuffer(d, sizes.accelerationStructureSize,
                               VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                   VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
    VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    ci.buffer = out.storage.buffer;
    ci.size = sizes.accelerationStructureSize;
    ci.type = type;
    VK_CHECK(d.vkCreateAccelerationStructureKHR(d.device, &ci, nullptr, &out.handle));
    scratchBytes = sizes.buildScratchSize;
    out.updateScratch = updatable ? sizes.updateScratchSize : 0;
  }
  Buffer scratch = createBuffer(d, scratchBytes + 256,
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  info.srcAccelerationStructure = refit ? out.handle : VK_NULL_HANDLE;
  info.dstAccelerationStructure = out.handle;
  info.scratchData.deviceAddress = (scratch.address + 255) & ~VkDeviceAddress(255);
  VkAccelerationStructureBuildRangeInfoKHR range{};
  range.primitiveCount = primitives;
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  submitAndWait(d, [&](VkCommandBuffer cmd) { d.vkCmdBuildAccelerationStructuresKHR(cmd, 1, &info, &ranges); });
  destroyBuffer(d, scratch);
  if (!refit) {
    VkAccelerationStructureDeviceAddressInfoKHR ai{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
    ai.accelerationStructure = out.handle;
    out.address = d.vkGetAccelerationStructureDeviceAddressKHR(d.device, &ai);
  }
}

void destroyAs(VulkanDevice& d, AccelerationStructure& a) {
  if (a.handle) d.vkDestroyAccelerationStructureKHR(d.device, a.handle, nullptr);
  destroyBuffer(d, a.storage);
  a = AccelerationStructure{};
}

VkAccelerationStructureGeometryKHR triangles(const SceneAccel& a, const BlasRun& run) {
  VkAccelerationStructureGeometryKHR tri{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  tri.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  // Any-hit must see each candidate once: the shadow any-hit multiplies transmittances.
  tri.flags = run.opaque ? VK_GEOMETRY_OPAQUE_BIT_KHR : VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR;
  auto& t = tri.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexData.deviceAddress = a.positions.address;
  t.vertexStride = sizeof(glm::vec3);
  t.maxVertex = a.maxVertex;
  t.indexType = VK_INDEX_TYPE_UINT32;
  t.indexData.deviceAddress = a.indices.address + static_cast<VkDeviceAddress>(run.first) * 3 * sizeof(uint32_t);
  return tri;
}

// The instances of the runs and the TLAS over them (built anew: a handful of instances).
void buildTopLevel(VulkanDevice& d, SceneAccel& a) {
  destroyAs(d, a.tlas);
  destroyBuffer(d, a.instances);
  std::vector<VkAccelerationStructureInstanceKHR> instances;
  for (const BlasRun& run : a.blases) {
    VkAccelerationStructureInstanceKHR instance{};
    instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
    // gl_InstanceCustomIndexEXT + gl_PrimitiveID = the scene's triangle (24 bits: checked when built).
    instance.instanceCustomIndex = run.first & 0xFFFFFFu;
    instance.mask = 0xFF;
    instance.flags = 0;  // back faces are reported, not culled: classification needs them
    instance.accelerationStructureReference = run.as.address;
    instances.push_back(instance);
  }
  a.instances = createBufferWithData(d, instances.data(), instances.size() * sizeof instances[0],
                                     VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                         VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  VkAccelerationStructureGeometryKHR inst{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  inst.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  inst.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  inst.geometry.instances.data.deviceAddress = a.instances.address;
  build(d, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, inst, static_cast<uint32_t>(instances.size()), false, false,
        a.tlas);
}

}  // namespace

void buildSceneAccel(VulkanDevice& d, const scene::Scene& scene, SceneAccel& out) {
  const uint32_t count = scene.triangleCount();
  if (count >= (1u << 24)) throw std::invalid_argument("scene " + scene.name + " has more than 2^24 triangles");
  // Without ray tracing (a raster-only device) the vertex and index buffers are all there is.
  const VkBufferUsageFlags usage =
      d.rayTracing ? kInputUsage
                   : VkBufferUsageFlags{VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                        VK_BUFFER_USAGE_INDEX_BUFFER_BIT};
  out.positions = createBufferWithData(d, scene.positions.data(), scene.positions.size() * sizeof(glm::vec3), usage);
  out.indices = createBufferWithData(d, scene.indices.data(), scene.indices.size() * sizeof(uint32_t), usage);
  out.opaqueTriangles = scene::leadingTrianglesBelowClass(scene, 1);
  out.maxVertex = static_cast<uint32_t>(scene.positions.size()) - 1;
  // Runs of the same kind (finalizeScene keeps each one contiguous).
  const std::vector<uint8_t> moves = scene::movingTriangles(scene);
  out.blases.clear();
  for (uint32_t t = 0; t < count; ++t) {
    const bool opaque = t < out.opaqueTriangles, moving = moves[t] != 0;
    if (out.blases.empty() || out.blases.back().opaque != opaque || out.blases.back().moves != moving) {
      BlasRun run;
      run.first = t;
      run.opaque = opaque;
      run.moves = moving;
      out.blases.push_back(run);
    }
    ++out.blases.back().count;
  }
  if (!d.rayTracing) return;
  for (BlasRun& run : out.blases)
    build(d, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, triangles(out, run), run.count, run.moves, false, run.as);
  buildTopLevel(d, out);
}

bool refitSceneAccel(VulkanDevice& d, const scene::Scene& scene, const std::vector<glm::vec3>& before, SceneAccel& a) {
  requireRayTracing(d, "refitting acceleration structures");
  if (scene.positions.size() != before.size() || scene.positions.size() != static_cast<size_t>(a.maxVertex) + 1 ||
      a.blases.empty())
    return false;
  const std::vector<uint8_t> moving = scene::movingVertices(scene);
  for (size_t v = 0; v < before.size(); ++v)
    if (!moving[v] && scene.positions[v] != before[v]) return false;
  for (const BlasRun& run : a.blases)  // a still run must not hold a moving vertex (the order keeps them apart)
    if (!run.moves)
      for (uint32_t i = 3 * run.first; i < 3 * (run.first + run.count); ++i)
        if (moving[scene.indices[i]]) return false;
  std::memcpy(a.positions.mapped, scene.positions.data(), scene.positions.size() * sizeof(glm::vec3));
  for (BlasRun& run : a.blases) {
    if (!run.moves) continue;
    if (run.refits >= kMaxRefits) {
      destroyAs(d, run.as);
      build(d, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, triangles(a, run), run.count, true, false, run.as);
      run.refits = 0;
      ++a.rebuilds;
    } else {
      build(d, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, triangles(a, run), run.count, true, true, run.as);
      ++run.refits;
      ++a.refits;
    }
  }
  buildTopLevel(d, a);
  return true;
}

void destroySceneAccel(VulkanDevice& d, SceneAccel& a) {
  destroyAs(d, a.tlas);
  for (BlasRun& run : a.blases) destroyAs(d, run.as);
  a.blases.clear();
  destroyBuffer(d, a.instances);
  destroyBuffer(d, a.positions);
  destroyBuffer(d, a.indices);
}

VkDeviceSize sceneAccelBytes(const SceneAccel& a) {
  VkDeviceSize total = a.tlas.storage.size + a.instances.size;
  for (const BlasRun& run : a.blases) total += run.as.storage.size;
  return total;
}

}  // namespace probecast::renderer
