#include "vk_device.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <cstring>
#include <vector>

#include "probecast/renderer/vulkan_context.h"

namespace probecast::renderer {
namespace {

const char* kRayTracingExtensions[] = {
    VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
    VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME,
    VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME,
};

// PROBECAST_VK_HIDE_RAY_TRACING=1: every device looks as if it had no ray tracing.
bool rayTracingHidden() {
  const char* v = std::getenv("PROBECAST_VK_HIDE_RAY_TRACING");
  return v && std::strcmp(v, "") != 0 && std::strcmp(v, "0") != 0;
}

VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    static_cast<VulkanDevice*>(user)->validationMessages++;
    std::fprintf(stderr, "vulkan validation: %s\n", data->pMessage);
  }
  return VK_FALSE;
}

bool hasExtensions(VkPhysicalDevice physical, const std::vector<const char*>& wanted) {
  uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> props(count);
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, props.data());
  for (const char* want : wanted) {
    bool found = false;
    for (const auto& p : props) found = found || std::strcmp(p.extensionName, want) == 0;
    if (!found) return false;
  }
  return true;
}

template <typename T>
void load(VkDevice device, T& fn, const char* name) {
  fn = reinterpret_cast<T>(vkGetDeviceProcAddr(device, name));
  if (!fn) throw std::runtime_error(std::string("Vulkan entry point missing: ") + name);
}

}  // namespace

void vkFail(VkResult result, const char* call, const char* file, int line) {
  throw std::runtime_error("Vulkan call failed (VkResult " + std::to_string(static_cast<int>(result)) + "): " + call +
                           " at " + file + ":" + std::to_string(line));
}

void requireRayTracing(const VulkanDevice& d, const char* what) {
  if (!d.rayTracing)
    throw std::runtime_error(std::string(what) + " needs ray tracing, and this Vulkan device (" + d.name +
                             ") was opened without it (a raster-only viewer's device" +
                             (rayTracingHidden() ? ", PROBECAST_VK_HIDE_RAY_TRACING is set" : "") + ")");
}

void createDevice(VulkanDevice& d, const ContextOptions& options) {
  const bool validation = options.validation;
  const DeviceChoice choice = options.device;
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "probecast";
  app.apiVersion = VK_API_VERSION_1_3;
  std::vector<const char*> layers, extensions;
  for (const std::string& e : options.instanceExtensions) extensions.push_back(e.c_str());
  if (validation) {
    layers.push_back("VK_LAYER_KHRONOS_validation");
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = static_cast<uint32_t>(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  const VkResult created = vkCreateInstance(&ici, nullptr, &d.instance);
  if (created == VK_ERROR_LAYER_NOT_PRESENT)
    throw std::runtime_error("Vulkan validation layer not installed (package vulkan-validationlayers)");
  if (created == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw std::runtime_error("no Vulkan driver (install mesa-vulkan-drivers >= 24 for lavapipe; see README)");
  VK_CHECK(created);

  if (validation) {
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mci.pfnUserCallback = onValidationMessage;
    mci.pUserData = &d;
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(d.instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create) VK_CHECK(create(d.instance, &mci, nullptr, &d.messenger));
  }

  uint32_t count = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(d.instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  VK_CHECK(vkEnumeratePhysicalDevices(d.instance, &count, devices.data()));
  std::vector<const char*> wanted;
  if (options.rayTracing) wanted.assign(std::begin(kRayTracingExtensions), std::end(kRayTracingExtensions));
  if (options.swapchain) wanted.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  const bool hidden = rayTracingHidden();
  int best = -1;
  bool bestIsCpu = false;
  std::string seen;  // every device, for the error when none fits
  for (uint32_t i = 0; i < count; ++i) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(devices[i], &p);
    const bool rayTracing =
        !hidden && hasExtensions(devices[i], {std::begin(kRayTracingExtensions), std::end(kRayTracingExtensions)});
    const bool fits = (rayTracing || !options.rayTracing) && hasExtensions(devices[i], wanted) &&
                      p.apiVersion >= VK_API_VERSION_1_3;
    const bool isCpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    seen += std::string(seen.empty() ? "" : ", ") + p.deviceName + (isCpu ? " (CPU" : " (GPU") +
            (rayTracing ? "" : ", no ray tracing") + (p.apiVersion >= VK_API_VERSION_1_3 ? "" : ", Vulkan < 1.3") + ")";
    if (!fits || (choice == DeviceChoice::Gpu && isCpu) || (choice == DeviceChoice::Cpu && !isCpu)) continue;
    if (best < 0 || (bestIsCpu && !isCpu)) {  // auto: the first GPU, else the first CPU
      best = static_cast<int>(i);
      bestIsCpu = isCpu;
    }
  }
  const std::string need = std::string(options.rayTracing ? "ray tracing" : "Vulkan 1.3") +
                           (options.swapchain ? " and a swapchain" : "");
  if (best < 0 && choice == DeviceChoice::Auto)
    throw std::runtime_error(
        "no Vulkan device with " + need +
        (options.rayTracing ? std::string(" (VK_KHR_ray_tracing_pipeline); lavapipe needs Mesa >= 24 from "
                                          "bookworm-backports (scripts/setup.sh installs it)")
                            : std::string()) +
        "; devices found: " + (seen.empty() ? std::string("none") : seen));
  if (best < 0)
    throw std::runtime_error(std::string("--device ") + deviceChoiceName(choice) + ": no " +
                             (choice == DeviceChoice::Gpu ? "GPU" : "CPU") + " Vulkan device with " + need +
                             "; devices found: " + (seen.empty() ? std::string("none") : seen) +
                             " (--device auto takes whichever there is)");
  d.physical = devices[best];
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  d.rtProperties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR;
  VkPhysicalDeviceMultiviewProperties multiview{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MULTIVIEW_PROPERTIES};
  d.rtProperties.pNext = &multiview;
  props.pNext = &d.rtProperties;
  vkGetPhysicalDeviceProperties2(d.physical, &props);
  d.rtProperties.pNext = nullptr;
  d.maxMultiviewViewCount = std::max(1u, multiview.maxMultiviewViewCount);
  d.name = props.properties.deviceName;
  vkGetPhysicalDeviceMemoryProperties(d.physical, &d.memory);

  uint32_t families = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(d.physical, &families, nullptr);
  std::vector<VkQueueFamilyProperties> qf(families);
  vkGetPhysicalDeviceQueueFamilyProperties(d.physical, &families, qf.data());
  d.queueFamily = UINT32_MAX;
  for (uint32_t i = 0; i < families; ++i)
    if ((qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) && (qf[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) &&
        d.queueFamily == UINT32_MAX)
      d.queueFamily = i;
  if (d.queueFamily == UINT32_MAX) throw std::runtime_error("no Vulkan queue that does both graphics and compute");

  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rt{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  rt.rayTracingPipeline = VK_TRUE;
  VkPhysicalDeviceAccelerationStructureFeaturesKHR as{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  as.accelerationStructure = VK_TRUE;
  as.pNext = &rt;
  VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  v12.bufferDeviceAddress = options.rayTracing ? VK_TRUE : VK_FALSE;  // device addresses serve the tracer only
  v12.pNext = options.rayTracing ? static_cast<void*>(&as) : nullptr;
  VkPhysicalDeviceVulkan11Features v11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  v11.multiview = VK_TRUE;  // core since 1.1 and mandatory
  v11.pNext = &v12;
  VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  v13.synchronization2 = VK_TRUE;
  v13.dynamicRendering = VK_TRUE;
  v13.pNext = &v11;
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  features.pNext = &v13;
  VkPhysicalDeviceFeatures available{};
  vkGetPhysicalDeviceFeatures(d.physical, &available);
  if (!available.geometryShader)
    throw std::runtime_error("the Vulkan device lacks geometryShader (gl_PrimitiveID in the raster client)");
  features.features.geometryShader = VK_TRUE;

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = d.queueFamily;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.pNext = &features;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = static_cast<uint32_t>(wanted.size());
  dci.ppEnabledExtensionNames = wanted.data();
  VK_CHECK(vkCreateDevice(d.physical, &dci, nullptr, &d.device));
  d.rayTracing = options.rayTracing;
  d.swapchain = options.swapchain;
  vkGetDeviceQueue(d.device, d.queueFamily, 0, &d.queue);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = d.queueFamily;
  VK_CHECK(vkCreateCommandPool(d.device, &pci, nullptr, &d.commandPool));

  if (!d.rayTracing) return;
  load(d.device, d.vkCreateAccelerationStructureKHR, "vkCreateAccelerationStructureKHR");
  load(d.device, d.vkDestroyAccelerationStructureKHR, "vkDestroyAccelerationStructureKHR");
  load(d.device, d.vkGetAccelerationStructureBuildSizesKHR, "vkGetAccelerationStructureBuildSizesKHR");
  load(d.device, d.vkCmdBuildAccelerationStructuresKHR, "vkCmdBuildAccelerationStructuresKHR");
  load(d.device, d.vkGetAccelerationStructureDeviceAddressKHR, "vkGetAccelerationStructureDeviceAddressKHR");
  load(d.device, d.vkCreateRayTracingPipelinesKHR, "vkCreateRayTracingPipelinesKHR");
  load(d.device, d.vkGetRayTracingShaderGroupHandlesKHR, "vkGetRayTracingShaderGroupHandlesKHR");
  load(d.device, d.vkCmdTraceRaysKHR, "vkCmdTraceRaysKHR");
}

void destroyDevice(VulkanDevice& d) {
  if (d.device) {
    vkDeviceWaitIdle(d.device);
    vkDestroyCommandPool(d.device, d.commandPool, nullptr);
    vkDestroyDevice(d.device, nullptr);
  }
  if (d.messenger) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(d.instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(d.instance, d.messenger, nullptr);
  }
  if (d.instance) vkDestroyInstance(d.instance, nullptr);
  d.device = VK_NULL_HANDLE;
  d.messenger = VK_NULL_HANDLE;
  d.instance = VK_NULL_HANDLE;
}

VulkanContext::VulkanContext(const ContextOptions& options) : device_(std::make_unique<VulkanDevice>()) {
  try {
    createDevice(*device_, options);
  } catch (...) {
    destroyDevice(*device_);
    throw;
  }
}

VulkanContext::~VulkanContext() { destroyDevice(*device_); }

bool parseDeviceChoice(const std::string& text, DeviceChoice& out) {
  for (DeviceChoice c : {DeviceChoice::Auto, DeviceChoice::Gpu, DeviceChoice::Cpu})
    if (text == deviceChoiceName(c)) {
      out = c;
      return true;
    }
  return false;
}

const char* deviceChoiceName(DeviceChoice choice) {
  switch (choice) {
    case DeviceChoice::Gpu:
      return "gpu";
    case DeviceChoice::Cpu:
      return "cpu";
    default:
      return "auto";
  }
}
const std::string& VulkanContext::deviceName() const { return device_->name; }
uint32_t VulkanContext::validationMessages() const { return device_->validationMessages.load(); }
bool VulkanContext::rayTracing() const { return device_->rayTracing; }
VulkanDevice& VulkanContext::device() { return *device_; }

}  // namespace probecast::renderer
