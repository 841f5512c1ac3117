// A headless Vulkan device with ray tracing: a GPU when one is present, lavapipe otherwise.
#pragma once

#include <memory>
#include <string>

namespace probecast::renderer {

// Which kind of Vulkan device to run on. Only devices with ray tracing count.
enum class DeviceChoice {
  Auto,  // a GPU (discrete, integrated or virtual) when one is present, a CPU implementation otherwise
  Gpu,   // a GPU, or an error naming the devices found
  Cpu,   // a CPU implementation (lavapipe), or an error naming the devices found
};

// "auto", "gpu" or "cpu"; false for anything else.
bool parseDeviceChoice(const std::string& text, DeviceChoice& out);
const char* deviceChoiceName(DeviceChoice choice);

struct ContextOptions {
  bool validation = false;  // VK_LAYER_KHRONOS_validation; messages are counted and logged
  DeviceChoice device = DeviceChoice::Auto;
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
