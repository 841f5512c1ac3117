#include "vk_acceleration.h"

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

  VkAccelerationStructureGeometryKHR tri{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  tri.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  tri.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  auto& t = tri.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexData.deviceAddress = out.positions.address;
  t.vertexStride = sizeof(glm::vec3);
  t.maxVertex = static_cast<uint32_t>(scene.positions.size()) - 1;
  t.indexType = VK_INDEX_TYPE_UINT32;
  t.indexData.deviceAddress = out.indices.address;
  build(d, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, tri, scene.triangleCount(), out.blas);

  VkAccelerationStructureInstanceKHR instance{};
  instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
  instance.mask = 0xFF;
  instance.flags = 0;  // back faces are reported, not culled: classification needs them
  instance.accelerationStructureReference = out.blas.address;
  out.instances = createBufferWithData(d, &instance, sizeof instance,
                                       VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                           VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  VkAccelerationStructureGeometryKHR inst{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  inst.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  inst.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  inst.geometry.instances.data.deviceAddress = out.instances.address;
  build(d, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, inst, 1, out.tlas);
}

void destroySceneAccel(VulkanDevice& d, SceneAccel& a) {
  destroyAs(d, a.tlas);
  destroyAs(d, a.blas);
  destroyBuffer(d, a.instances);
  destroyBuffer(d, a.positions);
  destroyBuffer(d, a.indices);
}

}  // namespace probecast::renderer
