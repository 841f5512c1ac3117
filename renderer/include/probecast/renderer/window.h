// A desktop window the raster client's frames are shown in: GLFW for the window and its input, a
// Vulkan swapchain on the viewer's device for the pixels. A frame arrives as 8-bit sRGB RGBA (tone
// mapped, overlay drawn) and is copied into the next swapchain image and presented; the window
// keeps the size it was opened with (a frame of another size is drawn at the top left, the rest
// cleared).
//
// Start the window system first (Window::instanceExtensions), open the VulkanContext with those
// instance extensions and ContextOptions::swapchain, then open windows on it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "probecast/renderer/vulkan_context.h"

namespace probecast::renderer {

struct WindowOptions {
  uint32_t width = 960, height = 600;  // of the drawable area, pixels
  std::string title = "probecast";
  // Full screen at the monitor's current mode: the monitor whose mode is width × height when one
  // is (a Looking Glass beside a desktop monitor), else the primary one.
  bool fullscreen = false;
};

// What the user did since the last poll.
struct WindowInput {
  glm::vec2 look{0.0f};   // mouse movement while the left button is held, pixels (x right, y down)
  glm::vec3 move{0.0f};   // held keys: x = D − A, y = E − Q, z = W − S (each −1, 0 or 1)
  bool fast = false;      // Shift held
  bool screenshot = false;  // F12 or P pressed
  bool reset = false;       // R pressed: back to the starting camera
};

class Window {
 public:
  // Starts the window system (once per process) and returns the Vulkan instance extensions that
  // presenting needs. Throws std::runtime_error naming the reason when no window can be opened
  // (no display: DISPLAY unset or unreachable; no Vulkan loader support).
  static std::vector<std::string> instanceExtensions();
  // The primary monitor's work area (the screen less task bars), pixels; {0, 0} when the window
  // system reports none. Throws as instanceExtensions() does when there is no window system.
  static glm::uvec2 screenWorkArea();

  // Opens the window and its swapchain. Throws std::runtime_error when the context was not made
  // for presenting, or its queue cannot present to this window.
  Window(VulkanContext& context, const WindowOptions& options);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  // False once the user closed it (the close button or Escape).
  bool isOpen() const;
  // Handles pending window-system events and returns the input since the last call.
  WindowInput poll();
  // Shows `rgba` (width × height, 4 bytes a pixel, rows from the top, sRGB-encoded). With
  // `readback`, the pixels of the swapchain image as presented are copied back into it (RGBA, the
  // window's size): what a screenshot of the window holds.
  void present(const uint8_t* rgba, uint32_t width, uint32_t height, std::vector<uint8_t>* readback = nullptr);
  void setTitle(const std::string& title);

  uint32_t width() const;
  uint32_t height() const;
  uint64_t framesPresented() const;
  // The swapchain's present mode, for the log ("mailbox", "immediate" or "fifo").
  const char* presentMode() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace probecast::renderer
