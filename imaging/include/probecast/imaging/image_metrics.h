// Image quality metrics for renders against the reference: PSNR and SSIM (Wang, Bovik, Sheikh,
// Simoncelli 2004) after the same plain gamma 2.2 on both images, without clamping first.
#pragma once

#include <string>
#include <vector>

namespace probecast::imaging {

struct ImageMetrics {
  double psnrDb = 0;  // over RGB, peak 1 after gamma; +inf for identical images
  double ssim = 0;    // mean SSIM of the luminance (Rec. 709), 11×11 Gaussian window σ 1.5, K1 0.01, K2 0.03, L 1
  double mse = 0;
};

// Both images: width × height × 3 linear floats. Non-finite values count as 0 here, so callers
// that judge images check findNonFinitePixels first (`probecast compare` refuses such images).
ImageMetrics compareImages(const std::vector<float>& a, const std::vector<float>& b, int width, int height);

struct NonFinitePixels {
  size_t count = 0;  // pixels with a NaN or infinite channel
  size_t first = 0;  // index (y × width + x) of the first one, when count > 0
};
NonFinitePixels findNonFinitePixels(const std::vector<float>& rgb);

// Per-pixel absolute luminance difference after gamma, as a false-colour PNG (black → blue →
// green → yellow → red at `scale`).
bool writeDifferencePng(const std::string& path, const std::vector<float>& a, const std::vector<float>& b, int width,
                        int height, double scale, std::string& error);

}  // namespace probecast::imaging
