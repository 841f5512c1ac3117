// The image harness: the reference cache (hits render nothing, any change of the key renders anew,
// damaged entries are rendered again) and the two-seed noise floor, on lavapipe at tiny sizes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "harness.h"
#include "scene_bench.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/imaging/image_io.h"
#include "vulkan_test_support.h"

namespace probecast::bench {
namespace {

namespace fs = std::filesystem;

class ReferenceCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(PROBECAST_TEST_TMP) / ("reference_cache_" + std::string(
        ::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    scene_ = test::builtinScene("cornell");
    request_.camera = renderer::CameraView::fromScene(scene_);
    request_.options.width = 12;
    request_.options.height = 8;
    request_.options.samplesPerPixel = 8;
    request_.options.maxBounces = 3;
  }
  void TearDown() override { fs::remove_all(dir_); }

  renderer::VulkanContext context_{test::validatedContext()};
  fs::path dir_;
  scene::Scene scene_;
  ReferenceRequest request_;
};

TEST_F(ReferenceCacheTest, SecondRequestRendersNothingAndReturnsTheSamePixels) {
  ReferenceCache cache(context_, dir_.string());
  const Reference first = cache.get(scene_, request_);
  EXPECT_EQ(cache.renders(), 2u);  // two half-references
  EXPECT_FALSE(first.fromCache);
  for (const char* f : {".json", ".a.json", ".a.exr", ".b.json", ".b.exr"})
    EXPECT_TRUE(fs::exists(dir_ / (first.key + f))) << f;

  ReferenceCache again(context_, dir_.string());  // a later run: nothing shared but the folder
  const Reference second = again.get(scene_, request_);
  EXPECT_EQ(again.renders(), 0u);
  EXPECT_TRUE(second.fromCache);
  EXPECT_EQ(second.key, first.key);
  EXPECT_EQ(second.halfA.rgb, first.halfA.rgb);
  EXPECT_EQ(second.halfB.rgb, first.halfB.rgb);
  EXPECT_EQ(second.mean.rgb, first.mean.rgb);
  EXPECT_EQ(second.floor.psnrDb, first.floor.psnrDb);
}

TEST_F(ReferenceCacheTest, ChangedKeyRendersAnew) {
  ReferenceCache cache(context_, dir_.string());
  const Reference base = cache.get(scene_, request_);
  uint32_t expected = 2;
  const auto rendersAnew = [&](const ReferenceRequest& changed, const char* what) {
    const Reference r = cache.get(scene_, changed);
    expected += 2;
    EXPECT_EQ(cache.renders(), expected) << what;
    EXPECT_FALSE(r.fromCache) << what;
    EXPECT_NE(r.key, base.key) << what;
  };
  ReferenceRequest spp = request_;
  spp.options.samplesPerPixel = 10;
  rendersAnew(spp, "spp");
  ReferenceRequest camera = request_;
  camera.camera.position.x += 0.01f;
  rendersAnew(camera, "camera");
  ReferenceRequest sky = request_;
  auto env = std::make_shared<renderer::Environment>();
  std::string error;
  ASSERT_TRUE(renderer::makeUniformSky({0.2f, 0.3f, 0.4f}, *env, error)) << error;
  sky.options.environment = env;
  rendersAnew(sky, "environment");
  auto brighter = std::make_shared<renderer::Environment>(*env);
  for (float& c : brighter->rgb) c *= 2.0f;  // the same sky at another intensity
  sky.options.environment = brighter;
  rendersAnew(sky, "environment intensity");
  ReferenceRequest seed = request_;
  seed.options.seed = 7;
  rendersAnew(seed, "seed");
  scene::Scene moved = test::builtinScene("cornell", 0.5f);  // the light elsewhere
  const Reference r = cache.get(moved, request_);
  EXPECT_EQ(cache.renders(), expected + 2) << "scene content";
  EXPECT_NE(r.key, base.key);
  // And the first request is still a hit.
  cache.get(scene_, request_);
  EXPECT_EQ(cache.renders(), expected + 2);
}

TEST_F(ReferenceCacheTest, DamagedHalvesAreRenderedAgain) {
  ReferenceCache cache(context_, dir_.string());
  const Reference good = cache.get(scene_, request_);
  const fs::path exr = dir_ / (good.key + ".a.exr"), json = dir_ / (good.key + ".a.json");

  // A truncated image: that half alone is traced again.
  fs::resize_file(exr, fs::file_size(exr) / 2);
  Reference r = cache.get(scene_, request_);
  EXPECT_EQ(cache.renders(), 3u);
  EXPECT_FALSE(r.fromCache);
  EXPECT_EQ(r.halfA.rgb, good.halfA.rgb);  // the same seed renders the same pixels

  // A valid image of other pixels (a file swapped in from another entry).
  std::vector<float> other(good.halfA.rgb.size(), 0.25f);
  std::string error;
  ASSERT_TRUE(imaging::writeExr(exr.string(), other, 12, 8, error)) << error;
  r = cache.get(scene_, request_);
  EXPECT_EQ(cache.renders(), 4u);
  EXPECT_EQ(r.halfA.rgb, good.halfA.rgb);

  // A JSON that holds another key (written for other settings), then one that is not JSON.
  std::ifstream in(json);
  nlohmann::json entry = nlohmann::json::parse(in);
  in.close();
  entry["key"]["spp"] = 4096;
  std::ofstream(json) << entry.dump();
  r = cache.get(scene_, request_);
  EXPECT_EQ(cache.renders(), 5u);
  std::ofstream(json) << "{ not json";
  r = cache.get(scene_, request_);
  EXPECT_EQ(cache.renders(), 6u);
  EXPECT_EQ(r.mean.rgb, good.mean.rgb);
  cache.get(scene_, request_);
  EXPECT_EQ(cache.renders(), 6u);  // repaired: a hit again
}

TEST_F(ReferenceCacheTest, InterruptedRenderKeepsItsFinishedHalf) {
  ReferenceCache cache(context_, dir_.string());
  const Reference whole = cache.get(scene_, request_);
  // As if the run had stopped while tracing the second half: its files and the summary missing.
  for (const char* f : {".b.exr", ".b.json", ".json"}) fs::remove(dir_ / (whole.key + f));
  ReferenceCache later(context_, dir_.string());
  const Reference resumed = later.get(scene_, request_);
  EXPECT_EQ(later.renders(), 1u);
  EXPECT_EQ(resumed.mean.rgb, whole.mean.rgb);
  EXPECT_TRUE(fs::exists(dir_ / (whole.key + ".json")));
}

TEST_F(ReferenceCacheTest, NoiseFloorFromTwoSeeds) {
  ReferenceCache cache(context_, dir_.string());
  const Reference r = cache.get(scene_, request_);
  EXPECT_NE(r.halfA.rgb, r.halfB.rgb);
  EXPECT_TRUE(std::isfinite(r.floor.psnrDb));
  EXPECT_GT(r.floor.psnrDb, 5.0);
  EXPECT_NEAR(r.accuracyDb - r.floor.psnrDb, 6.0206, 1e-3);
  // More samples, a higher floor: the two halves agree better.
  ReferenceRequest more = request_;
  more.options.samplesPerPixel = 128;
  EXPECT_GT(cache.get(scene_, more).floor.psnrDb, r.floor.psnrDb + 3.0);

  // The same seed twice (two caches, nothing shared) gives identical images.
  ReferenceCache other(context_, (dir_ / "other").string());
  const Reference same = other.get(scene_, request_);
  EXPECT_EQ(other.renders(), 2u);
  EXPECT_EQ(same.halfA.rgb, r.halfA.rgb);
  EXPECT_EQ(same.halfB.rgb, r.halfB.rgb);
}

TEST_F(ReferenceCacheTest, RefusesWhatCannotBeTwoHalves) {
  ReferenceCache cache(context_, dir_.string());
  ReferenceRequest one = request_;
  one.options.samplesPerPixel = 1;
  EXPECT_THROW(cache.get(scene_, one), std::runtime_error);
  EXPECT_EQ(cache.renders(), 0u);
}

TEST(ImageHarness, ComparisonRefusesNonFinitePixelsAndSizeMismatch) {
  renderer::Image a{2, 1, {0.5f, 0.5f, 0.5f, 0.1f, 0.2f, 0.3f}}, b = a;
  EXPECT_TRUE(std::isinf(compareChecked(a, b, "same").psnrDb));
  b.rgb[4] = std::nanf("");
  try {
    compareChecked(a, b, "zh3 view 0");
    FAIL() << "a NaN reference pixel was scored";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("1 non-finite pixels in the reference"), std::string::npos) << e.what();
  }
  renderer::Image c{1, 2, a.rgb};
  EXPECT_THROW(compareChecked(a, c, "size"), std::invalid_argument);
}

// At a small size the raster client's one sample per pixel aliases every edge, while the
// reference averages each pixel's area: supersampling the raster (the same footprint) or MSAA
// (the default) must score clearly closer to the reference than one sample per pixel.
TEST(SceneBench, SupersamplingMatchesThePixelFootprintOfTheReference) {
  const std::filesystem::path dir = std::filesystem::path(PROBECAST_TEST_TMP) / "scene_bench_supersample";
  std::filesystem::remove_all(dir);
  SceneBenchOptions o;
  o.scene = test::builtinScene("cornell");
  o.grid = renderer::sceneGrid(o.scene, {4, 4, 4});
  o.updater.samplesPerProbe = 64;
  o.updates = 2;
  o.width = 32;
  o.height = 20;
  o.repeats = 1;
  o.referenceSpp = 64;
  o.referenceBounces = 4;
  o.referenceCache = dir.string();
  o.context = test::validatedContext();
  const auto floatPsnr = [](const SceneBenchResult& r) { return r.json["representations"][0]["psnr_db"].get<double>(); };
  EXPECT_EQ(o.raster.samplesPerSide, 1u) << "the library's default anti-aliases by MSAA";
  EXPECT_EQ(o.raster.msaaSamples, 4u);
  const SceneBenchResult msaa = runSceneBench(o);
  o.raster.msaaSamples = 1;
  const SceneBenchResult one = runSceneBench(o);  // the cached reference, the same probes
  o.raster.samplesPerSide = 4;
  const SceneBenchResult four = runSceneBench(o);
  EXPECT_EQ(four.json["supersample"].get<uint32_t>(), 4u);
  EXPECT_EQ(one.json["supersample"].get<uint32_t>(), 1u);
  EXPECT_EQ(msaa.json["msaa_samples"].get<uint32_t>(), 4u);
  EXPECT_GT(floatPsnr(four), floatPsnr(one) + 2.0) << "1 sample per pixel " << floatPsnr(one) << " dB, 16: "
                                                   << floatPsnr(four) << " dB";
  EXPECT_GT(floatPsnr(msaa), floatPsnr(one) + 2.0) << "1 sample per pixel " << floatPsnr(one) << " dB, MSAA 4: "
                                                   << floatPsnr(msaa) << " dB";
  std::filesystem::remove_all(dir);
  o.raster.samplesPerSide = 0;
  EXPECT_THROW(checkSceneBenchOptions(o), std::invalid_argument);
}

}  // namespace
}  // namespace probecast::bench
