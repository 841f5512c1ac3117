// A headless Vulkan device with ray tracing: lavapipe by default, a GPU when asked for.
#pragma once

#include <memory>
#include <string>

namespace probecast::renderer {

struct ContextOptions {
  bool validation = false;  // VK_LAYER_KHRONOS_validation; messages are counted and logged
  bool preferGpu = false;   // pick a discrete/integrated GPU over lavapipe when both exist
};

struct VulkanDevice;  // defined in renderer/src/vk_device.h

class VulkanContext {
 public:
  explicit VulkanContext(const ContextOptions& options = {});
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  const std::string& deviceName() const;
  // Warnings and errors reported by the validation layer so far.
  uint32_t validationMessages() const;
  VulkanDevice& device();

 private:
  std::unique_ptr<VulkanDevice> device_;
};

}  // namespace probecast::renderer
