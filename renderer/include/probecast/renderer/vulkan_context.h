// A Vulkan device: a GPU when one is present, lavapipe otherwise. With ray tracing (the probe
// updater and the reference renderer need it) or raster-only (viewers: any Vulkan 1.3 device with
// geometry shaders, as headset and mobile GPUs without ray tracing are), headless or presenting to
// a window.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace probecast::renderer {

// Which kind of Vulkan device to run on. Only devices with what the context asks for count.
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
  // Off: no ray-tracing extension is asked for, so devices without them qualify (what a viewer
  // needs); a ProbeUpdater or reference render on such a context throws std::runtime_error.
  // The environment variable PROBECAST_VK_HIDE_RAY_TRACING=1 makes every device look as if it had
  // none (to try a raster-only device on a machine whose devices all trace).
  bool rayTracing = true;
  // Instance extensions a window system needs (Window::instanceExtensions()), and VK_KHR_swapchain
  // on the device: to present to a window.
  std::vector<std::string> instanceExtensions;
  bool swapchain = false;
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
  // Whether ray tracing was asked for and enabled (ContextOptions::rayTracing).
  bool rayTracing() const;
  VulkanDevice& device();

 private:
  std::unique_ptr<VulkanDevice> device_;
};

}  // namespace probecast::renderer
