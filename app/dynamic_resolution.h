// Dynamic resolution for the live window: a device too slow to draw the window's views at full
// size in the frame budget draws them smaller (RasterRenderer::setRenderScale), and the window
// shows them scaled back up, so the frame rate holds and the picture softens instead.
#pragma once

#include <cstdint>
#include <vector>

#include "probecast/renderer/raster_client.h"

namespace probecast::app {

// After each frame the render scale (each side; pixels go as its square) moves toward the one that
// would have drawn the frame in 90 % of the budget, judged on the median of the last three frames:
// down at once when they run over the budget, back up (at most 15 % a step) when they take under
// 70 % of it. Steps of 1/32, between 1/4 and 1.
class DynamicResolution {
 public:
  explicit DynamicResolution(double targetFps);  // 0: always full size
  float scale() const { return scale_; }
  // The last frame's time, milliseconds; true when the scale changed.
  bool update(double frameMs);

 private:
  double budgetMs_ = 0.0;
  float scale_ = 1.0f;
  std::vector<double> recent_;
};

// `image` resampled bilinearly to width × height (pixel centres aligned); the same image when it
// already has that size.
renderer::Image upscale(const renderer::Image& image, uint32_t width, uint32_t height);

}  // namespace probecast::app
