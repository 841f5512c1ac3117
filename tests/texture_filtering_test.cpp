// Texture filtering: the mip chain (texture_mips.h) and the raster client reading textures over
// each pixel's footprint, against the path tracer, which averages the footprint by sampling it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/reference_camera.h"
#include "texture_mips.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

using scene::Material;
using scene::Scene;

uint8_t channel(const std::vector<uint32_t>& texels, size_t i, int c) {
  return static_cast<uint8_t>((texels[i] >> (8 * c)) & 255u);
}

// w × h, each texel black or white by `white(x, y)`; alpha 255.
scene::Texture pattern(uint32_t w, uint32_t h, const std::function<bool(uint32_t, uint32_t)>& white) {
  scene::Texture t;
  t.width = w;
  t.height = h;
  t.rgba.assign(static_cast<size_t>(w) * h * 4, 255);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x)
      if (!white(x, y))
        for (int c = 0; c < 3; ++c) t.rgba[(static_cast<size_t>(y) * w + x) * 4 + c] = 0;
  return t;
}

TEST(TextureMips, LevelsHalveEachSideDownToOneTexel) {
  EXPECT_EQ(mipLevelCount(1, 1), 1u);
  EXPECT_EQ(mipLevelCount(256, 256), 9u);
  EXPECT_EQ(mipLevelCount(5, 3), 3u);  // 5×3, 2×1, 1×1
  EXPECT_EQ(mipLevelCount(1, 1024), 11u);
  std::vector<uint32_t> texels{7u};  // what was there before stays
  const scene::Texture t = pattern(5, 3, [](uint32_t x, uint32_t y) { return (x + y) % 2 == 0; });
  EXPECT_EQ(appendMipChain(t, true, texels), 3u);
  EXPECT_EQ(texels.size(), 1u + 15u + 2u + 1u);
  EXPECT_EQ(texels[0], 7u);
}

TEST(TextureMips, ColourAveragesLinearLightDataAveragesStoredValues) {
  // A one-texel checker: every texel below the first level is half white. As light that is 0.5,
  // sRGB-encoded 188; as stored values 127.5.
  const scene::Texture t = pattern(8, 8, [](uint32_t x, uint32_t y) { return (x + y) % 2 == 0; });
  std::vector<uint32_t> colour, data;
  ASSERT_EQ(appendMipChain(t, true, colour), 4u);
  ASSERT_EQ(appendMipChain(t, false, data), 4u);
  ASSERT_EQ(colour.size(), 64u + 16u + 4u + 1u);
  for (size_t i = 64; i < colour.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(channel(colour, i, c), 188, 1) << "texel " << i;
      EXPECT_NEAR(channel(data, i, c), 127.5, 1) << "texel " << i;
      EXPECT_EQ(channel(colour, i, 3), 255);
    }
}

TEST(TextureMips, ColourTexturesAreThoseAMaterialReadsAsColour) {
  Scene s;
  s.textures.resize(4);
  Material m;
  m.baseColorTexture = 2;
  m.metallicRoughnessTexture = 0;
  m.occlusionTexture = 1;
  s.materials.push_back(m);
  m = Material{};
  m.emissiveTexture = 3;
  m.baseColorTexture = 7;  // out of range: ignored
  s.materials.push_back(m);
  EXPECT_EQ(colourTextures(s), (std::vector<bool>{false, false, true, true}));
}

class TextureFiltering : public ::testing::Test {
 protected:
  void SetUp() override { context_ = std::make_unique<VulkanContext>(test::validatedContext()); }
  void TearDown() override { EXPECT_EQ(context_->validationMessages(), 0u) << "Vulkan validation messages"; }
  std::unique_ptr<VulkanContext> context_;
};

// An emitter of radiance 1 × the texture (nothing else lights anything): every renderer shows the
// texture as it reads it.
Material texturedEmitter(glm::vec2 scale) {
  Material m;
  m.baseColor = glm::vec3(0.0f);
  m.emission = glm::vec3(1.0f);
  m.emissiveTexture = 0;
  m.emissiveTransform.row0 = {scale.x, 0.0f, 0.0f};
  m.emissiveTransform.row1 = {0.0f, scale.y, 0.0f};
  return m;
}

Image reference(VulkanContext& context, const Scene& s, uint32_t size, uint32_t spp) {
  ReferenceOptions o;
  o.width = o.height = size;
  o.samplesPerPixel = spp;
  o.maxBounces = 1;
  return renderReference(context, s, test::frontCamera(), o);
}

Image raster(VulkanContext& context, const Scene& s, uint32_t size, uint32_t anisotropy) {
  RasterOptions o;
  o.msaaSamples = 1;  // one shading sample per pixel: the filtering alone
  o.anisotropy = anisotropy;
  RasterRenderer r(context, s, size, size, o);
  const CameraView cam = test::frontCamera();
  return r.render(r.viewProjection(cam), cam.position);
}

double rmsRed(const Image& a, const Image& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.rgb.size(); i += 3) sum += (a.rgb[i] - b.rgb[i]) * (a.rgb[i] - b.rgb[i]);
  return std::sqrt(sum / static_cast<double>(a.rgb.size() / 3));
}

// A 256 × 256 one-texel checker filling a 28 × 28 image: about 9 texels a pixel. The path tracer
// finds the mean, half the light, in every pixel; so must the raster client at one sample a pixel
// (one bilinear read at the pixel's centre lands anywhere between black and white).
TEST_F(TextureFiltering, MinifiedCheckerRastersToTheMeanTheTracerFinds) {
  Scene s;
  s.textures.push_back(pattern(256, 256, [](uint32_t x, uint32_t y) { return (x + y) % 2 == 0; }));
  s.materials.push_back(texturedEmitter({1.0f, 1.0f}));
  scene::addQuad(s, {-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, 0);
  scene::finalizeScene(s);
  const Image ref = reference(*context_, s, 28, 256), img = raster(*context_, s, 28, 8);
  double refMean = 0.0, worst = 0.0;
  for (size_t i = 0; i < img.rgb.size(); i += 3) {
    refMean += ref.rgb[i] / static_cast<double>(img.rgb.size() / 3);
    worst = std::max(worst, std::fabs(img.rgb[i] - 0.5));
  }
  EXPECT_NEAR(refMean, 0.5, 0.01);
  EXPECT_LT(worst, 0.02) << "a pixel that should hold the checker's mean";
}

// A floor seen at a grazing angle, striped across (along X) 4 texels a period, about a texel a
// pixel across the middle distance, while each pixel covers many texels along the view: the
// footprint is long and thin. One isotropic read at the level of its long side blurs the stripes
// the path tracer resolves; taps along the long side keep them.
TEST_F(TextureFiltering, GrazingStripesStayResolvedWithAnisotropicTaps) {
  Scene s;
  s.textures.push_back(pattern(64, 4, [](uint32_t x, uint32_t) { return (x / 2) % 2 == 0; }));
  s.materials.push_back(texturedEmitter({2.0f, 80.0f}));
  scene::addQuad(s, {-4, -0.25f, -0.25f}, {4, -0.25f, -0.25f}, {4, -0.25f, -20.25f}, {-4, -0.25f, -20.25f}, 0);
  scene::finalizeScene(s);
  const Image ref = reference(*context_, s, 64, 256);
  const double isotropic = rmsRed(raster(*context_, s, 64, 1), ref);
  const double anisotropic = rmsRed(raster(*context_, s, 64, 16), ref);
  EXPECT_LT(anisotropic, 0.6 * isotropic) << "isotropic " << isotropic << ", anisotropic " << anisotropic;
  EXPECT_LT(anisotropic, 0.08);
}

}  // namespace
}  // namespace probecast::renderer
