#include "probecast/imaging/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <stb_image_write.h>

namespace probecast::imaging {
namespace {

double gammaOf(float v) { return std::isfinite(v) && v > 0 ? std::pow(static_cast<double>(v), 1.0 / 2.2) : 0.0; }

std::vector<double> gammaLuma(const std::vector<float>& rgb) {
  std::vector<double> y(rgb.size() / 3);
  for (size_t i = 0; i < y.size(); ++i)
    y[i] = 0.2126 * gammaOf(rgb[i * 3]) + 0.7152 * gammaOf(rgb[i * 3 + 1]) + 0.0722 * gammaOf(rgb[i * 3 + 2]);
  return y;
}

// Separable Gaussian blur, window 11, σ 1.5, edges clamped to the image (renormalised weights).
std::vector<double> blur(const std::vector<double>& in, int w, int h) {
  double k[11];
  double sum = 0;
  for (int i = 0; i < 11; ++i) sum += k[i] = std::exp(-0.5 * (i - 5) * (i - 5) / (1.5 * 1.5));
  for (double& v : k) v /= sum;
  std::vector<double> tmp(in.size()), out(in.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double acc = 0, wsum = 0;
      for (int i = -5; i <= 5; ++i) {
        const int xx = x + i;
        if (xx < 0 || xx >= w) continue;
        acc += k[i + 5] * in[static_cast<size_t>(y) * w + xx];
        wsum += k[i + 5];
      }
      tmp[static_cast<size_t>(y) * w + x] = acc / wsum;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double acc = 0, wsum = 0;
      for (int i = -5; i <= 5; ++i) {
        const int yy = y + i;
        if (yy < 0 || yy >= h) continue;
        acc += k[i + 5] * tmp[static_cast<size_t>(yy) * w + x];
        wsum += k[i + 5];
      }
      out[static_cast<size_t>(y) * w + x] = acc / wsum;
    }
  return out;
}

}  // namespace

NonFinitePixels findNonFinitePixels(const std::vector<float>& rgb) {
  NonFinitePixels r;
  for (size_t i = 0; i < rgb.size() / 3; ++i)
    if (!std::isfinite(rgb[i * 3]) || !std::isfinite(rgb[i * 3 + 1]) || !std::isfinite(rgb[i * 3 + 2])) {
      if (r.count++ == 0) r.first = i;
    }
  return r;
}

ImageMetrics compareImages(const std::vector<float>& a, const std::vector<float>& b, int width, int height) {
  ImageMetrics m;
  const size_t n = static_cast<size_t>(width) * height;
  if (a.size() != n * 3 || b.size() != n * 3 || n == 0) return m;
  double se = 0;
  for (size_t i = 0; i < n * 3; ++i) {
    const double d = gammaOf(a[i]) - gammaOf(b[i]);
    se += d * d;
  }
  m.mse = se / static_cast<double>(n * 3);
  m.psnrDb = m.mse > 0 ? 10.0 * std::log10(1.0 / m.mse) : std::numeric_limits<double>::infinity();
  const std::vector<double> x = gammaLuma(a), y = gammaLuma(b);
  std::vector<double> xx(n), yy(n), xy(n);
  for (size_t i = 0; i < n; ++i) {
    xx[i] = x[i] * x[i];
    yy[i] = y[i] * y[i];
    xy[i] = x[i] * y[i];
  }
  const auto mx = blur(x, width, height), my = blur(y, width, height);
  const auto sxx = blur(xx, width, height), syy = blur(yy, width, height), sxy = blur(xy, width, height);
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  double total = 0;
  for (size_t i = 0; i < n; ++i) {
    const double vx = sxx[i] - mx[i] * mx[i], vy = syy[i] - my[i] * my[i], cxy = sxy[i] - mx[i] * my[i];
    total += ((2 * mx[i] * my[i] + c1) * (2 * cxy + c2)) / ((mx[i] * mx[i] + my[i] * my[i] + c1) * (vx + vy + c2));
  }
  m.ssim = total / static_cast<double>(n);
  return m;
}

bool writeDifferencePng(const std::string& path, const std::vector<float>& a, const std::vector<float>& b, int width,
                        int height, double scale, std::string& error) {
  const size_t n = static_cast<size_t>(width) * height;
  if (a.size() != n * 3 || b.size() != n * 3) return error = "images differ in size", false;
  const std::vector<double> x = gammaLuma(a), y = gammaLuma(b);
  std::vector<uint8_t> out(n * 3);
  for (size_t i = 0; i < n; ++i) {
    const double t = std::clamp(std::fabs(x[i] - y[i]) / scale, 0.0, 1.0);
    // black → blue → green → yellow → red
    const double stops[5][3] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}};
    const double f = t * 4.0;
    const int k = std::min(3, static_cast<int>(f));
    const double u = f - k;
    for (int c = 0; c < 3; ++c)
      out[i * 3 + c] = static_cast<uint8_t>(std::lround(255.0 * (stops[k][c] * (1 - u) + stops[k + 1][c] * u)));
  }
  if (!stbi_write_png(path.c_str(), width, height, 3, out.data(), width * 3)) return error = path + ": cannot write PNG", false;
  return true;
}

}  // namespace probecast::imaging
