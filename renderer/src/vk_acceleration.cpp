#include "vk_acceleration.h"

#include <stdexcept>
#include <vector>

namespace probecast::renderer {
namespace {

constexpr VkBufferUsageFlags kInputUsage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                           VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                           VK_BUFFER_USAGE_INDEX_BUFFER_BIT;  // the raster client draws them too

void build(VulkanDevice& d, VkAccelerationStructureTypeKHR type, const VkAccelerationStructureGeometryKHR& geometry,
           uint32_t primitives, AccelerationStructure& out) {
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = type;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &geometry;
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
  Buffer scratch = createBuffer(d, sizes.buildScratchSize + 256,
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  info.dstAccelerationStructure = out.handle;
  info.scratchData.deviceAddress = (scratch.address + 255) & ~VkDeviceAddress(255);
  VkAccelerationStructureBuildRangeInfoKHR range{};
  range.primitiveCount = primitives;
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  submitAndWait(d, [&](VkCommandBuffer cmd) { d.vkCmdBuildAccelerationStructuresKHR(cmd, 1, &info, &ranges); });
  destroyBuffer(d, scratch);
  VkAccelerationStructureDeviceAddressInfoKHR ai{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  ai.accelerationStructure = out.handle;
  out.address = d.vkGetAccelerationStructureDeviceAddressKHR(d.device, &ai);
}

void destroyAs(VulkanDevice& d, AccelerationStructure& a) {
  if (a.handle) d.vkDestroyAccelerationStructureKHR(d.device, a.handle, nullptr);
  destroyBuffer(d, a.storage);
  a = AccelerationStructure{};
}

}  // namespace

void buildSceneAccel(VulkanDevice& d, const scene::Scene& scene, SceneAccel& out) {
  out.positions = createBufferWithData(d, scene.positions.data(), scene.positions.size() * sizeof(glm::vec3), kInputUsage);
  out.indices = createBufferWithData(d, scene.indices.data(), scene.indices.size() * sizeof(uint32_t), kInputUsage);
  const uint32_t count = scene.triangleCount();
  if (count >= (1u << 24)) throw std::invalid_argument("scene " + scene.name + " has more than 2^24 triangles");
  out.opaqueTriangles = scene::leadingTrianglesBelowClass(scene, 1);

  std::vector<VkAccelerationStructureInstanceKHR> instances;
  const auto addBlas = [&](uint32_t first, uint32_t triangles, bool opaque, AccelerationStructure& blas) {
    if (triangles == 0) return;
    VkAccelerationStructureGeometryKHR tri{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    tri.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    // Any-hit must see each candidate once: the shadow any-hit multiplies transmittances.
    tri.flags = opaque ? VK_GEOMETRY_OPAQUE_BIT_KHR : VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR;
    auto& t = tri.geometry.triangles;
    t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    t.vertexData.deviceAddress = out.positions.address;
    t.vertexStride = sizeof(glm::vec3);
    t.maxVertex = static_cast<uint32_t>(scene.positions.size()) - 1;
    t.indexType = VK_INDEX_TYPE_UINT32;
    t.indexData.deviceAddress = out.indices.address + static_cast<VkDeviceAddress>(first) * 3 * sizeof(uint32_t);
    build(d, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, tri, triangles, blas);
    VkAccelerationStructureInstanceKHR instance{};
    instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
    // gl_InstanceCustomIndexEXT + gl_PrimitiveID = the scene's triangle (24 bits: checked above).
    instance.instanceCustomIndex = first & 0xFFFFFFu;
    instance.mask = 0xFF;
    instance.flags = 0;  // back faces are reported, not culled: classification needs them
    instance.accelerationStructureReference = blas.address;
    instances.push_back(instance);
  };
  addBlas(0, out.opaqueTriangles, true, out.blas);
  addBlas(out.opaqueTriangles, count - out.opaqueTriangles, false, out.blasNonOpaque);
  out.instances = createBufferWithData(d, instances.data(), instances.size() * sizeof instances[0],
                                       VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                           VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  VkAccelerationStructureGeometryKHR inst{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  inst.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  inst.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  inst.geometry.instances.data.deviceAddress = out.instances.address;
  build(d, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, inst, static_cast<uint32_t>(instances.size()), out.tlas);
}

void destroySceneAccel(VulkanDevice& d, SceneAccel& a) {
  destroyAs(d, a.tlas);
  destroyAs(d, a.blas);
  destroyAs(d, a.blasNonOpaque);
  destroyBuffer(d, a.instances);
  destroyBuffer(d, a.positions);
  destroyBuffer(d, a.indices);
}

}  // namespace probecast::renderer
