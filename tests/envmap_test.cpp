// Environment-map conventions, projection and brute-force irradiance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <ImfCompression.h>

#include "envmap.h"
#include "exr_test_files.h"

namespace probecast::bench {
namespace {

EnvMap constantMap(int w, int h, float value) {
  return EnvMap{"constant", w, h, std::vector<float>(static_cast<size_t>(w) * h * 3, value)};
}

// The L1 direction (c3, c1, c2) of channel 0, normalised.
std::array<float, 3> l1Direction(const float* p) {
  const float d[3] = {p[9], p[3], p[6]};
  const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return {d[0] / len, d[1] / len, d[2] / len};
}

TEST(EnvMap, TopRowIsUpAndCentreIsMinusZ) {
  // The loader's convention (envmap.h): top row +Y, map centre −Z, u = 0.75 is +X.
  float d[3];
  EnvMap m = constantMap(64, 32, 0.0f);
  envMapDirection(m, 32, 0, d);
  EXPECT_GT(d[1], 0.99f);
  envMapDirection(m, 31, 15, d);
  EXPECT_LT(d[2], -0.99f);
  envMapDirection(m, 47, 15, d);
  EXPECT_GT(d[0], 0.99f);

  // A map bright only in its top rows has its L1 pointing up.
  for (int x = 0; x < 64; ++x)
    for (int y = 0; y < 4; ++y)
      for (int c = 0; c < 3; ++c) m.rgb[(static_cast<size_t>(y) * 64 + x) * 3 + c] = 1.0f;
  float p[kProbeFloats];
  projectToSh(m, p);
  EXPECT_GT(l1Direction(p)[1], 0.99f);
}

TEST(EnvMap, ConstantMapProjectsAndConvolvesToKnownAnswers) {
  // docs/CODEC.md §8.1: L = 1 → c00 = 2√π, E = π.
  const EnvMap m = constantMap(128, 64, 1.0f);
  float p[kProbeFloats];
  projectToSh(m, p);
  EXPECT_NEAR(p[0], 3.5449077f, 1e-4f);
  // Y20 is sampled at row centres: O(1/H²) quadrature error, ≈ 7e-4 at 64 rows.
  for (int i = 3; i < kProbeFloats; ++i) EXPECT_NEAR(p[i], 0.0f, 2e-3f);
  std::vector<float> e;
  bruteForceIrradiance(m, fibonacciSphere(64), e);
  for (float v : e) EXPECT_NEAR(v, kPi, 2e-3f);
}

TEST(EnvMap, RotationMovesTheLightAboutY) {
  // A bright spot at −Z rotated by +90° about +Y: its L1 turns toward −X (x' = cos·x + sin·z).
  EnvMap m = constantMap(64, 32, 0.0f);
  for (int c = 0; c < 3; ++c) m.rgb[(static_cast<size_t>(15) * 64 + 31) * 3 + c] = 100.0f;
  float p[kProbeFloats];
  projectToSh(m, p, kPi / 2);
  const auto d = l1Direction(p);
  EXPECT_LT(d[0], -0.99f);
}

TEST(EnvMap, DownsampleKeepsTheIntegral) {
  std::vector<EnvMap> maps = builtinEnvMaps();
  for (const EnvMap& m : maps) {
    float a[kProbeFloats], b[kProbeFloats];
    projectToSh(m, a);
    projectToSh(downsample(m, 4), b);
    EXPECT_NEAR(b[0], a[0], 1e-3f * a[0]) << m.name;
  }
}

TEST(EnvMap, BadFilesFailWithAMessage) {
  EnvMap m;
  std::string error;
  EXPECT_FALSE(loadEnvMap("/nonexistent/x.hdr", m, error));
  EXPECT_NE(error.find("/nonexistent/x.hdr"), std::string::npos);
  EXPECT_FALSE(loadEnvMap(std::string(PROBECAST_TEST_DATA) + "/CREDITS.md", m, error));
  EXPECT_NE(error.find("not an environment map"), std::string::npos);
  EXPECT_FALSE(loadEnvMap(std::string(PROBECAST_TEST_DATA) + "/scenes/cornell-box/CornellBox-Original.bin.hdr", m, error));
}

TEST(EnvMap, LoadsExrInEveryCompression) {
  // The same files as ImageIo.EveryCompressionReadsBack, through the loader `bench codec --envmaps` uses.
  using namespace probecast::testing;
  const int w = 64, h = 32;
  const std::vector<float> image = exrTestImage(w, h);
  for (const ExrCompressionCase& c : exrCompressionCases()) {
    SCOPED_TRACE(c.name);
    const std::string path =
        (std::filesystem::temp_directory_path() / (std::string("probecast_envmap_") + c.name + ".exr")).string();
    writeTestExr(path, image, w, h, c.compression, c.half);
    EnvMap map;
    std::string error;
    ASSERT_TRUE(loadEnvMap(path, map, error)) << error;
    ASSERT_EQ(map.width, w);
    ASSERT_EQ(map.height, h);
    EXPECT_EQ(map.name, std::string("probecast_envmap_") + c.name + ".exr");
    const std::vector<float> stored = c.half ? roundToHalf(image) : image;
    float worst = 0.0f;
    for (size_t i = 0; i < stored.size(); ++i)
      worst = std::max(worst, std::fabs(map.rgb[i] - stored[i]) / std::max(1.0f, std::fabs(stored[i])));
    EXPECT_LE(worst, c.tolerance);
    std::filesystem::remove(path);
  }
}

TEST(EnvMap, TruncatedExrFailsNamingTheFile) {
  using namespace probecast::testing;
  const std::string path = (std::filesystem::temp_directory_path() / "probecast_envmap_truncated.exr").string();
  writeTestExr(path, exrTestImage(64, 32), 64, 32, Imf::ZIP_COMPRESSION, false);
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
  EnvMap map;
  std::string error;
  EXPECT_FALSE(loadEnvMap(path, map, error));
  EXPECT_NE(error.find("probecast_envmap_truncated.exr: cannot read EXR"), std::string::npos) << error;
  std::filesystem::remove(path);
}

TEST(EnvMap, LoadsProjectRadianceMap) {
  EnvMap m;
  std::string error;
  ASSERT_TRUE(loadEnvMap(std::string(PROBECAST_TEST_DATA) + "/envmaps/venice_sunset_1k.hdr", m, error)) << error;
  EXPECT_EQ(m.width, 1024);
  EXPECT_EQ(m.height, 512);
  float p[kProbeFloats];
  projectToSh(m, p);
  EXPECT_GT(p[0], 0.0f);
}

// Opt-in: the research-only light probes stay outside the project (tests/data/CREDITS.md).
TEST(EnvMap, LoadsSharedRadianceMap) {
  const std::string path = std::string(PROBECAST_SHARED_DATA) + "/envmaps/grace.hdr";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared test data absent: " << path;
  EnvMap m;
  std::string error;
  ASSERT_TRUE(loadEnvMap(path, m, error)) << error;
  EXPECT_EQ(m.width, 256);
  EXPECT_EQ(m.height, 128);
  float p[kProbeFloats];
  projectToSh(m, p);
  EXPECT_GT(p[0], 0.0f);
}

}  // namespace
}  // namespace probecast::bench
