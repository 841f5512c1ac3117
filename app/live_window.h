// A live window for `view`: every display frame renders the view set of a camera the user moves,
// from whatever lighting the viewer holds at that moment, tone-maps it, writes a status line over
// it and presents it. The stream (or a local tracer) only ever changes what is held; a stall or a
// reconnect never stops the frames.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "probecast/imaging/image_io.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/renderer/vulkan_context.h"

namespace probecast::app {

struct LiveWindowOptions {
  bool enabled = false;           // --window
  bool fullscreen = false;        // --fullscreen
  double seconds = 0.0;           // --window-seconds: close after this long (0: when the user closes it)
  double screenshotAfter = -1.0;  // --screenshot-after: one screenshot this many seconds in (< 0: none)
  bool overlay = true;            // the status line
  std::string headTrace;          // --head-trace: the camera turns as this recorded head turned (looping)
  double fps = 10.0;              // --window-fps: the rate dynamic resolution holds (0: always full size)
  void add(CLI::App* cmd);
  // The context a window presents from: the given options plus what presenting needs.
  static renderer::ContextOptions presenting(renderer::ContextOptions options);
};

// What a frame shows: `render` draws `views` into `images` (false while there is nothing to
// draw yet); `status` is the right part of the status line (probe age, rate, connection).
struct FrameSource {
  std::function<bool(const std::vector<renderer::ViewInfo>& views, bool cameraMoved,
                     std::vector<renderer::Image>& images)>
      render;
  std::function<std::string()> status;
  // Optional: the displayed image from the rendered views (a quilt by default; an interleaved
  // Looking Glass image, say), and the window's size for it.
  std::function<renderer::Image(const std::vector<renderer::Image>& images, const std::vector<renderer::ViewInfo>& views)>
      compose;
  uint32_t displayWidth = 0, displayHeight = 0;  // 0: the quilt's size
  // Optional: draw the next views at this scale of their size (dynamic resolution; none: full size).
  std::function<void(float scale)> setRenderScale;
};

struct LiveWindowResult {
  uint64_t frames = 0;
  double seconds = 0.0;
  double medianFrameMs = 0.0;
  std::vector<std::string> screenshots;
};

// Runs the window until it is closed (or `seconds` pass). Screenshots (F12 or P, or
// --screenshot-after) go to `outDir`: screenshot_NNN.png, the presented pixels read back from the
// swapchain, status line included, and screenshot_NNN.exr, the linear frame without it.
LiveWindowResult runLiveWindow(const LiveWindowOptions& options, renderer::VulkanContext& context,
                               const renderer::CameraView& start, const renderer::ViewSetSpec& spec,
                               const renderer::ViewSetOptions& viewSetOptions, uint32_t viewWidth,
                               uint32_t viewHeight, float sceneSize, FrameSource& source, const std::string& outDir,
                               float exposure, imaging::ToneMap toneMap);

}  // namespace probecast::app
