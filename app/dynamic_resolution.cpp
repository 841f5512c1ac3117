#include "dynamic_resolution.h"

#include <algorithm>
#include <cmath>

namespace probecast::app {

DynamicResolution::DynamicResolution(double targetFps) : budgetMs_(targetFps > 0.0 ? 1e3 / targetFps : 0.0) {}

bool DynamicResolution::update(double frameMs) {
  if (budgetMs_ <= 0.0 || !(frameMs > 0.0) || !std::isfinite(frameMs)) return false;
  recent_.push_back(frameMs);
  if (recent_.size() > 3) recent_.erase(recent_.begin());
  if (recent_.size() < 3) return false;
  std::vector<double> sorted = recent_;
  std::sort(sorted.begin(), sorted.end());
  const double ms = sorted[1];
  // Aimed at 90 % of the budget, so that frames around the aim still keep the rate.
  double wanted = scale_;
  if (ms > budgetMs_)
    wanted = scale_ * std::sqrt(0.9 * budgetMs_ / ms);
  else if (ms < 0.7 * budgetMs_)
    wanted = scale_ * std::min(1.15, std::sqrt(0.9 * budgetMs_ / ms));
  const float next = std::clamp(static_cast<float>(std::round(wanted * 32.0) / 32.0), 0.25f, 1.0f);
  if (next == scale_) return false;
  scale_ = next;
  recent_.clear();  // judge the new scale on frames drawn at it
  return true;
}

renderer::Image upscale(const renderer::Image& image, uint32_t width, uint32_t height) {
  if ((image.width == width && image.height == height) || image.width == 0 || image.height == 0) return image;
  renderer::Image out;
  out.width = width;
  out.height = height;
  out.rgb.resize(static_cast<size_t>(width) * height * 3);
  const float sx = static_cast<float>(image.width) / static_cast<float>(width);
  const float sy = static_cast<float>(image.height) / static_cast<float>(height);
  for (uint32_t y = 0; y < height; ++y) {
    const float fy = std::clamp((static_cast<float>(y) + 0.5f) * sy - 0.5f, 0.0f, static_cast<float>(image.height - 1));
    const auto y0 = static_cast<uint32_t>(fy);
    const uint32_t y1 = std::min(y0 + 1, image.height - 1);
    const float ty = fy - static_cast<float>(y0);
    for (uint32_t x = 0; x < width; ++x) {
      const float fx = std::clamp((static_cast<float>(x) + 0.5f) * sx - 0.5f, 0.0f, static_cast<float>(image.width - 1));
      const auto x0 = static_cast<uint32_t>(fx);
      const uint32_t x1 = std::min(x0 + 1, image.width - 1);
      const float tx = fx - static_cast<float>(x0);
      const auto at = [&](uint32_t px, uint32_t py, uint32_t c) {
        return image.rgb[(static_cast<size_t>(py) * image.width + px) * 3 + c];
      };
      for (uint32_t c = 0; c < 3; ++c) {
        const float top = at(x0, y0, c) + (at(x1, y0, c) - at(x0, y0, c)) * tx;
        const float bottom = at(x0, y1, c) + (at(x1, y1, c) - at(x0, y1, c)) * tx;
        out.rgb[(static_cast<size_t>(y) * width + x) * 3 + c] = top + (bottom - top) * ty;
      }
    }
  }
  return out;
}

}  // namespace probecast::app
