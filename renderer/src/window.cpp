#include "probecast/renderer/window.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "vk_device.h"
#include "vk_resources.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

namespace probecast::renderer {
namespace {

std::mutex gGlfwMutex;
std::string gGlfwError;  // the last error GLFW reported, for the exceptions below

void onGlfwError(int, const char* message) { gGlfwError = message ? message : "unknown error"; }

// glfwInit once per process; GLFW is left running until exit (windows come and go).
void startGlfw() {
  std::lock_guard<std::mutex> lock(gGlfwMutex);
  static bool started = false;
  if (started) return;
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit()) {
    const char* display = std::getenv("DISPLAY");
    throw std::runtime_error("cannot open a window: " + gGlfwError +
                             (display && *display ? std::string(" (DISPLAY=") + display + ")"
                                                  : std::string(" (DISPLAY is not set; without a screen, run it under "
                                                                "Xvfb: xvfb-run -a probecast …)")));
  }
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    throw std::runtime_error("cannot open a window: the window system offers no Vulkan surface (" + gGlfwError + ")");
  }
  started = true;
}

}  // namespace

struct Window::Impl {
  VulkanDevice* d = nullptr;
  GLFWwindow* window = nullptr;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  bool bgra = true;           // swapchain channel order
  bool canReadBack = false;   // swapchain images allow transfer reads
  VkPresentModeKHR mode = VK_PRESENT_MODE_FIFO_KHR;
  VkExtent2D extent{};
  std::vector<VkImage> images;
  std::vector<VkSemaphore> rendered;  // one per swapchain image: signalled when its copy is done
  VkSemaphore acquired = VK_NULL_HANDLE;
  VkFence done = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  Buffer staging, readback;
  uint64_t frames = 0;
  uint32_t width = 0, height = 0;
  // Input state between polls.
  double lastX = 0.0, lastY = 0.0;
  bool haveCursor = false;
  bool screenshotPressed = false, resetPressed = false;

  void createSwapchain() {
    VkSurfaceCapabilitiesKHR caps;
    VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(d->physical, surface, &caps));
    uint32_t n = 0;
    VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(d->physical, surface, &n, nullptr));
    std::vector<VkSurfaceFormatKHR> formats(n);
    VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(d->physical, surface, &n, formats.data()));
    // The frames arrive sRGB-encoded already: a UNORM format shows the bytes as they are.
    VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
    for (VkFormat want : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
      for (const VkSurfaceFormatKHR& f : formats)
        if (chosen.format == VK_FORMAT_UNDEFINED && f.format == want &&
            f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR)
          chosen = f;
    if (chosen.format == VK_FORMAT_UNDEFINED)
      throw std::runtime_error("the window's surface offers no 8-bit RGBA or BGRA format");
    format = chosen.format;
    bgra = format == VK_FORMAT_B8G8R8A8_UNORM;

    VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(d->physical, surface, &n, nullptr));
    std::vector<VkPresentModeKHR> modes(n);
    VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(d->physical, surface, &n, modes.data()));
    // Frames are paced by rendering, not by the display: never block on a refresh when another
    // mode exists (FIFO is the one every device has).
    mode = VK_PRESENT_MODE_FIFO_KHR;
    for (VkPresentModeKHR want : {VK_PRESENT_MODE_IMMEDIATE_KHR, VK_PRESENT_MODE_MAILBOX_KHR})
      if (std::find(modes.begin(), modes.end(), want) != modes.end()) mode = want;

    if (caps.currentExtent.width != UINT32_MAX) {
      extent = caps.currentExtent;
    } else {
      int w = 0, h = 0;
      glfwGetFramebufferSize(window, &w, &h);
      extent = {std::clamp(static_cast<uint32_t>(w), caps.minImageExtent.width, caps.maxImageExtent.width),
                std::clamp(static_cast<uint32_t>(h), caps.minImageExtent.height, caps.maxImageExtent.height)};
    }
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
      throw std::runtime_error("the window's swapchain images cannot be written by transfers");
    canReadBack = (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != 0;
    uint32_t count = caps.minImageCount + 1;
    if (caps.maxImageCount > 0) count = std::min(count, caps.maxImageCount);

    VkSwapchainCreateInfoKHR sci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    sci.surface = surface;
    sci.minImageCount = count;
    sci.imageFormat = chosen.format;
    sci.imageColorSpace = chosen.colorSpace;
    sci.imageExtent = extent;
    sci.imageArrayLayers = 1;
    sci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | (canReadBack ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
    sci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    sci.preTransform = caps.currentTransform;
    sci.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                             ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                             : static_cast<VkCompositeAlphaFlagBitsKHR>(caps.supportedCompositeAlpha &
                                                                        -caps.supportedCompositeAlpha);
    sci.presentMode = mode;
    sci.clipped = VK_TRUE;
    VkSwapchainKHR old = swapchain;
    sci.oldSwapchain = old;
    VK_CHECK(vkCreateSwapchainKHR(d->device, &sci, nullptr, &swapchain));
    if (old) vkDestroySwapchainKHR(d->device, old, nullptr);
    VK_CHECK(vkGetSwapchainImagesKHR(d->device, swapchain, &n, nullptr));
    images.resize(n);
    VK_CHECK(vkGetSwapchainImagesKHR(d->device, swapchain, &n, images.data()));
    for (VkSemaphore s : rendered) vkDestroySemaphore(d->device, s, nullptr);
    rendered.assign(n, VK_NULL_HANDLE);
    VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    for (VkSemaphore& s : rendered) VK_CHECK(vkCreateSemaphore(d->device, &si, nullptr, &s));
  }

  // Everything goes with the Impl, also when the constructor stopped half-way.
  ~Impl() {
    if (d && d->device) vkDeviceWaitIdle(d->device);
    if (cmd) vkFreeCommandBuffers(d->device, d->commandPool, 1, &cmd);
    if (done) vkDestroyFence(d->device, done, nullptr);
    if (acquired) vkDestroySemaphore(d->device, acquired, nullptr);
    for (VkSemaphore s : rendered) vkDestroySemaphore(d->device, s, nullptr);
    if (d) {
      destroyBuffer(*d, staging);
      destroyBuffer(*d, readback);
    }
    if (swapchain) vkDestroySwapchainKHR(d->device, swapchain, nullptr);
    if (surface) vkDestroySurfaceKHR(d->instance, surface, nullptr);
    if (window) glfwDestroyWindow(window);
  }

  void recreateSwapchain() {
    VK_CHECK(vkDeviceWaitIdle(d->device));
    createSwapchain();
  }
};

std::vector<std::string> Window::instanceExtensions() {
  startGlfw();
  uint32_t n = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&n);
  if (!names) throw std::runtime_error("cannot open a window: " + gGlfwError);
  return std::vector<std::string>(names, names + n);
}

glm::uvec2 Window::screenWorkArea() {
  startGlfw();
  GLFWmonitor* monitor = glfwGetPrimaryMonitor();
  if (!monitor) return {0, 0};
  int x = 0, y = 0, w = 0, h = 0;
  glfwGetMonitorWorkarea(monitor, &x, &y, &w, &h);
  if (w <= 0 || h <= 0) {  // some window systems report no work area: the mode, then
    const GLFWvidmode* mode = glfwGetVideoMode(monitor);
    if (!mode) return {0, 0};
    w = mode->width;
    h = mode->height;
  }
  return {static_cast<uint32_t>(w), static_cast<uint32_t>(h)};
}

Window::Window(VulkanContext& context, const WindowOptions& options) : impl_(std::make_unique<Impl>()) {
  startGlfw();
  Impl& w = *impl_;
  w.d = &context.device();
  if (!w.d->swapchain)
    throw std::runtime_error("this Vulkan context was not opened for presenting (ContextOptions::swapchain)");
  if (options.width == 0 || options.height == 0 || options.width > 16384 || options.height > 16384)
    throw std::invalid_argument("a window needs 1..16384 pixels a side");
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  GLFWmonitor* monitor = nullptr;
  if (options.fullscreen) {
    monitor = glfwGetPrimaryMonitor();
    int count = 0;
    GLFWmonitor** monitors = glfwGetMonitors(&count);
    for (int i = 0; i < count; ++i) {
      const GLFWvidmode* mode = glfwGetVideoMode(monitors[i]);
      if (mode && static_cast<uint32_t>(mode->width) == options.width &&
          static_cast<uint32_t>(mode->height) == options.height) {
        monitor = monitors[i];
        break;
      }
    }
    if (!monitor) throw std::runtime_error("--fullscreen: the window system reports no monitor");
  }
  w.window = glfwCreateWindow(static_cast<int>(options.width), static_cast<int>(options.height), options.title.c_str(),
                              monitor, nullptr);
  if (!w.window) throw std::runtime_error("cannot open a window: " + gGlfwError);
  try {
    if (glfwCreateWindowSurface(w.d->instance, w.window, nullptr, &w.surface) != VK_SUCCESS)
      throw std::runtime_error("cannot make a Vulkan surface for the window: " + gGlfwError);
    VkBool32 supported = VK_FALSE;
    VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(w.d->physical, w.d->queueFamily, w.surface, &supported));
    if (!supported)
      throw std::runtime_error("the Vulkan device " + w.d->name + " cannot present to this window from its queue");
    w.createSwapchain();
    VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VK_CHECK(vkCreateSemaphore(w.d->device, &si, nullptr, &w.acquired));
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    VK_CHECK(vkCreateFence(w.d->device, &fi, nullptr, &w.done));
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = w.d->commandPool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(w.d->device, &ai, &w.cmd));
  } catch (...) {
    impl_.reset();  // the destructor below does not run for a constructor that throws
    throw;
  }
  glfwGetCursorPos(w.window, &w.lastX, &w.lastY);
  glfwSetWindowUserPointer(w.window, &w);
  glfwSetKeyCallback(w.window, [](GLFWwindow* win, int key, int, int action, int) {
    auto* self = static_cast<Impl*>(glfwGetWindowUserPointer(win));
    if (action != GLFW_PRESS) return;
    if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(win, GLFW_TRUE);
    if (key == GLFW_KEY_F12 || key == GLFW_KEY_P) self->screenshotPressed = true;
    if (key == GLFW_KEY_R) self->resetPressed = true;
  });
}

Window::~Window() = default;

uint32_t Window::width() const { return impl_->extent.width; }
uint32_t Window::height() const { return impl_->extent.height; }
uint64_t Window::framesPresented() const { return impl_->frames; }
const char* Window::presentMode() const {
  switch (impl_->mode) {
    case VK_PRESENT_MODE_IMMEDIATE_KHR:
      return "immediate";
    case VK_PRESENT_MODE_MAILBOX_KHR:
      return "mailbox";
    default:
      return "fifo";
  }
}

bool Window::isOpen() const { return !glfwWindowShouldClose(impl_->window); }

void Window::setTitle(const std::string& title) { glfwSetWindowTitle(impl_->window, title.c_str()); }

WindowInput Window::poll() {
  Impl& w = *impl_;
  glfwPollEvents();
  WindowInput in;
  double x = 0.0, y = 0.0;
  glfwGetCursorPos(w.window, &x, &y);
  if (glfwGetMouseButton(w.window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS && w.haveCursor)
    in.look = glm::vec2(static_cast<float>(x - w.lastX), static_cast<float>(y - w.lastY));
  w.lastX = x;
  w.lastY = y;
  w.haveCursor = true;
  auto held = [&](int key) { return glfwGetKey(w.window, key) == GLFW_PRESS ? 1.0f : 0.0f; };
  in.move = glm::vec3(held(GLFW_KEY_D) - held(GLFW_KEY_A), held(GLFW_KEY_E) - held(GLFW_KEY_Q),
                      held(GLFW_KEY_W) - held(GLFW_KEY_S));
  in.fast = held(GLFW_KEY_LEFT_SHIFT) + held(GLFW_KEY_RIGHT_SHIFT) > 0.0f;
  in.screenshot = w.screenshotPressed;
  in.reset = w.resetPressed;
  w.screenshotPressed = w.resetPressed = false;
  return in;
}

void Window::present(const uint8_t* rgba, uint32_t width, uint32_t height, std::vector<uint8_t>* readback) {
  Impl& w = *impl_;
  VulkanDevice& d = *w.d;
  VK_CHECK(vkWaitForFences(d.device, 1, &w.done, VK_TRUE, UINT64_MAX));
  uint32_t index = 0;
  for (int attempt = 0;; ++attempt) {
    const VkResult r = vkAcquireNextImageKHR(d.device, w.swapchain, UINT64_MAX, w.acquired, VK_NULL_HANDLE, &index);
    if (r == VK_SUCCESS || r == VK_SUBOPTIMAL_KHR) break;
    if (r != VK_ERROR_OUT_OF_DATE_KHR || attempt > 2) VK_CHECK(r);
    w.recreateSwapchain();
  }
  VK_CHECK(vkResetFences(d.device, 1, &w.done));
  const VkExtent2D e = w.extent;
  const uint32_t cw = std::min(width, e.width), ch = std::min(height, e.height);
  const VkDeviceSize bytes = VkDeviceSize{e.width} * e.height * 4;
  if (w.staging.size < bytes) {
    destroyBuffer(d, w.staging);
    w.staging = createBuffer(d, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  }
  // Rows of the frame into the swapchain's channel order (the copy region is the part that fits).
  auto* dst = static_cast<uint8_t*>(w.staging.mapped);
  for (uint32_t y = 0; y < ch; ++y) {
    const uint8_t* src = rgba + (size_t{y} * width) * 4;
    uint8_t* out = dst + (size_t{y} * cw) * 4;
    for (uint32_t x = 0; x < cw; ++x, src += 4, out += 4) {
      out[0] = w.bgra ? src[2] : src[0];
      out[1] = src[1];
      out[2] = w.bgra ? src[0] : src[2];
      out[3] = 255;
    }
  }
  const bool wantBack = readback && w.canReadBack;
  if (wantBack && w.readback.size < bytes) {
    destroyBuffer(d, w.readback);
    w.readback = createBuffer(d, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  }

  VK_CHECK(vkResetCommandBuffer(w.cmd, 0));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(w.cmd, &bi));
  auto barrier = [&](VkImageLayout from, VkImageLayout to, VkAccessFlags src, VkAccessFlags dstAccess,
                     VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = src;
    b.dstAccessMask = dstAccess;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = w.images[index];
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(w.cmd, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
  };
  barrier(VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
  if (cw < e.width || ch < e.height) {  // a frame smaller than the window: the rest is black
    const VkClearColorValue black{{0.0f, 0.0f, 0.0f, 1.0f}};
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(w.cmd, w.images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &black, 1, &range);
    barrier(VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
            VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
  }
  if (cw > 0 && ch > 0) {
    VkBufferImageCopy region{};
    region.bufferRowLength = cw;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {cw, ch, 1};
    vkCmdCopyBufferToImage(w.cmd, w.staging.buffer, w.images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  }
  VkImageLayout last = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  VkAccessFlags lastAccess = VK_ACCESS_TRANSFER_WRITE_BIT;
  if (wantBack) {
    barrier(last, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, lastAccess, VK_ACCESS_TRANSFER_READ_BIT,
            VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {e.width, e.height, 1};
    vkCmdCopyImageToBuffer(w.cmd, w.images[index], VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, w.readback.buffer, 1, &region);
    last = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    lastAccess = VK_ACCESS_TRANSFER_READ_BIT;
  }
  barrier(last, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, lastAccess, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  VK_CHECK(vkEndCommandBuffer(w.cmd));

  const VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &w.acquired;
  si.pWaitDstStageMask = &waitStage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &w.cmd;
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &w.rendered[index];
  VK_CHECK(vkQueueSubmit(d.queue, 1, &si, w.done));
  VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  pi.waitSemaphoreCount = 1;
  pi.pWaitSemaphores = &w.rendered[index];
  pi.swapchainCount = 1;
  pi.pSwapchains = &w.swapchain;
  pi.pImageIndices = &index;
  const VkResult presented = vkQueuePresentKHR(d.queue, &pi);
  if (presented == VK_ERROR_OUT_OF_DATE_KHR || presented == VK_SUBOPTIMAL_KHR)
    w.recreateSwapchain();
  else
    VK_CHECK(presented);
  ++w.frames;
  if (readback) {
    readback->assign(bytes, 0);
    if (!wantBack) throw std::runtime_error("this window's swapchain images cannot be read back");
    VK_CHECK(vkWaitForFences(d.device, 1, &w.done, VK_TRUE, UINT64_MAX));
    const auto* src = static_cast<const uint8_t*>(w.readback.mapped);
    for (size_t p = 0; p < bytes; p += 4) {
      (*readback)[p + 0] = w.bgra ? src[p + 2] : src[p + 0];
      (*readback)[p + 1] = src[p + 1];
      (*readback)[p + 2] = w.bgra ? src[p + 0] : src[p + 2];
      (*readback)[p + 3] = 255;
    }
  }
}

}  // namespace probecast::renderer
