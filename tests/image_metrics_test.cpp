// PSNR/SSIM against answers from their definitions (Wang et al. 2004, eq. 13 for SSIM).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "probecast/imaging/image_metrics.h"

namespace probecast::imaging {
namespace {

std::vector<float> constant(int w, int h, float v) { return std::vector<float>(static_cast<size_t>(w) * h * 3, v); }

TEST(ImageMetrics, NonFinitePixelsAreFoundAndCounted) {
  // compareImages scores NaN as 0; callers judge images only after this finds none.
  std::vector<float> img(6 * 4 * 3, 0.5f);
  EXPECT_EQ(findNonFinitePixels(img).count, 0u);
  img[(2 * 6 + 3) * 3 + 1] = std::nanf("");
  img[(3 * 6 + 0) * 3 + 2] = -std::numeric_limits<float>::infinity();
  img[(3 * 6 + 0) * 3] = std::nanf("");  // the same pixel again: still one pixel
  const NonFinitePixels nf = findNonFinitePixels(img);
  EXPECT_EQ(nf.count, 2u);
  EXPECT_EQ(nf.first, 2u * 6 + 3);
}

TEST(ImageMetrics, IdenticalImagesArePerfect) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.0f, 4.0f);
  std::vector<float> a(32 * 24 * 3);
  for (float& v : a) v = u(rng);
  const ImageMetrics m = compareImages(a, a, 32, 24);
  EXPECT_TRUE(std::isinf(m.psnrDb));
  EXPECT_NEAR(m.ssim, 1.0, 1e-12);
}

TEST(ImageMetrics, ConstantImagesMatchTheDefinitions) {
  // After gamma 2.2: 0.5 → 0.72974, 0.6 → 0.79281. PSNR = −20 log10 |Δ| (peak 1).
  // SSIM of two flat images: variances and covariance vanish, leaving the luminance term
  // (2 μx μy + C1) / (μx² + μy² + C1), C1 = 0.01².
  const double gx = std::pow(0.5, 1 / 2.2), gy = std::pow(static_cast<double>(0.6f), 1 / 2.2);
  const ImageMetrics m = compareImages(constant(20, 20, 0.5f), constant(20, 20, 0.6f), 20, 20);
  EXPECT_NEAR(m.psnrDb, -20.0 * std::log10(gy - gx), 1e-6);
  const double c1 = 1e-4;
  EXPECT_NEAR(m.ssim, (2 * gx * gy + c1) / (gx * gx + gy * gy + c1), 1e-9);
}

TEST(ImageMetrics, NoClampingBeforeTheMetric) {
  // Values above 1 are compared as they are: 4 and 9 differ even though both clip to white.
  const ImageMetrics m = compareImages(constant(8, 8, 4.0f), constant(8, 8, 9.0f), 8, 8);
  EXPECT_NEAR(m.psnrDb, -20.0 * std::log10(std::pow(9.0, 1 / 2.2) - std::pow(4.0, 1 / 2.2)), 1e-6);
}

TEST(ImageMetrics, MoreNoiseScoresWorse) {
  std::mt19937 rng(3);
  std::normal_distribution<float> n(0.0f, 1.0f);
  const int w = 64, h = 48;
  std::vector<float> ref(static_cast<size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) ref[(static_cast<size_t>(y) * w + x) * 3 + c] = 0.2f + 0.6f * static_cast<float>(x) / w;
  std::vector<float> a = ref, b = ref;
  for (size_t i = 0; i < ref.size(); ++i) {
    a[i] = std::max(0.0f, ref[i] + 0.02f * n(rng));
    b[i] = std::max(0.0f, ref[i] + 0.08f * n(rng));
  }
  const ImageMetrics ma = compareImages(a, ref, w, h), mb = compareImages(b, ref, w, h);
  EXPECT_GT(ma.psnrDb, mb.psnrDb);
  EXPECT_GT(ma.ssim, mb.ssim);
  EXPECT_LT(mb.ssim, 0.9);
}

}  // namespace
}  // namespace probecast::imaging
