// Normal textures in the tracers and the raster client: glTF's convention (+X along +u, +Y up the
// image) and the two agreeing, on a synthetic square and on the brick wall of tests/data.
#include <gtest/gtest.h>

#include <cmath>

#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/reference_camera.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

using scene::Material;
using scene::Scene;

class NormalMaps : public ::testing::Test {
 protected:
  void SetUp() override { context_ = std::make_unique<VulkanContext>(test::validatedContext()); }
  void TearDown() override { EXPECT_EQ(context_->validationMessages(), 0u) << "Vulkan validation messages"; }
  std::unique_ptr<VulkanContext> context_;
};

Image traced(VulkanContext& context, const Scene& s, const CameraView& cam, uint32_t w, uint32_t h, uint32_t spp) {
  ReferenceOptions o;
  o.width = w;
  o.height = h;
  o.samplesPerPixel = spp;
  o.maxBounces = 1;  // direct light only, as the raster client without probes
  return renderReference(context, s, cam, o);
}

Image rastered(VulkanContext& context, const Scene& s, const CameraView& cam, uint32_t w, uint32_t h) {
  RasterRenderer r(context, s, w, h);
  return r.render(r.viewProjection(cam), cam.position);
}

// Mean red over the w/2 × h/2 quadrant (qx, qy) of an image, leaving a margin of `m` pixels.
double quadrantMean(const Image& img, int qx, int qy, uint32_t m) {
  const uint32_t hw = img.width / 2, hh = img.height / 2;
  double sum = 0.0;
  int n = 0;
  for (uint32_t y = qy * hh + m; y < (qy + 1) * hh - m; ++y)
    for (uint32_t x = qx * hw + m; x < (qx + 1) * hw - m; ++x, ++n) sum += img.rgb[(y * img.width + x) * 3];
  return sum / n;
}

double psnr(const Image& a, const Image& b, double peak) {
  double se = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) se += (a.rgb[i] - b.rgb[i]) * (a.rgb[i] - b.rgb[i]);
  return 10.0 * std::log10(peak * peak / std::max(se / static_cast<double>(a.rgb.size()), 1e-20));
}

// A white square facing the camera, its normal texture tilted 37° in each quadrant: up the image
// (top left), down (top right), toward +u (bottom left), toward −u (bottom right). A sun from the
// upper right in front lights the up and +u quadrants more than their opposites, by the same ratio
// in the path tracer and the raster client.
TEST_F(NormalMaps, TiltsFollowGltfsConventionInTracerAndRaster) {
  Scene s;
  scene::Texture t;
  t.width = t.height = 2;
  const uint8_t up[4] = {128, 205, 230, 255}, down[4] = {128, 51, 230, 255}, plusU[4] = {205, 128, 230, 255},
                minusU[4] = {51, 128, 230, 255};
  for (const uint8_t* texel : {up, down, plusU, minusU}) t.rgba.insert(t.rgba.end(), texel, texel + 4);
  s.textures.push_back(t);
  Material m;
  m.baseColor = glm::vec3(0.8f);
  m.normalTexture = 0;
  s.materials.push_back(m);
  scene::addQuad(s, {-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, 0);
  scene::Light sun;
  sun.type = scene::LightType::Directional;
  sun.direction = glm::normalize(glm::vec3(-1.0f, -1.0f, -1.5f));
  sun.color = glm::vec3(1.0f);
  sun.intensity = 1.0f;
  s.lights.push_back(sun);
  scene::finalizeScene(s);
  // Texels are 16 pixels wide: the quadrants' inner pixels see one texel each (nearest would be
  // the same; bilinear blends only at the borders the margin leaves out).
  const CameraView cam = test::frontCamera();
  const Image ref = traced(*context_, s, cam, 32, 32, 16), img = rastered(*context_, s, cam, 32, 32);
  for (const Image* i : {&ref, &img}) {
    const double a = quadrantMean(*i, 0, 0, 5), b = quadrantMean(*i, 1, 0, 5), c = quadrantMean(*i, 0, 1, 5),
                 d = quadrantMean(*i, 1, 1, 5);
    EXPECT_GT(a, 1.3 * b) << (i == &ref ? "tracer" : "raster") << ": tilted up the image against down";
    EXPECT_GT(c, 1.3 * d) << (i == &ref ? "tracer" : "raster") << ": tilted toward +u against −u";
  }
  for (int q = 0; q < 4; ++q)
    EXPECT_NEAR(quadrantMean(img, q % 2, q / 2, 5) / quadrantMean(ref, q % 2, q / 2, 5), 1.0, 0.02) << "quadrant " << q;
}

// The brick wall of tests/data (relief from a normal texture only): the raster client's picture
// against the path tracer's, both with the sun alone; without the texture the raster picture is
// far from the traced one.
TEST_F(NormalMaps, BrickWallRastersAsTraced) {
  Scene s;
  std::string error;
  ASSERT_TRUE(scene::loadGltf(std::string(PROBECAST_TEST_DATA) + "/scenes/normal-wall/normal-wall.gltf", s, error)) << error;
  ASSERT_GE(s.materials.front().normalTexture, 0);
  const CameraView cam = CameraView::fromScene(s);
  const Image ref = traced(*context_, s, cam, 160, 100, 64), img = rastered(*context_, s, cam, 160, 100);
  double peak = 0.0;
  for (float v : ref.rgb) peak = std::max(peak, static_cast<double>(v));
  Scene flat = s;
  for (Material& m : flat.materials) m.normalTexture = -1;
  const double with = psnr(img, ref, peak), without = psnr(rastered(*context_, flat, cam, 160, 100), ref, peak);
  EXPECT_GT(with, 30.0) << "raster against traced, with the normal texture";
  EXPECT_GT(with, without + 6.0) << "without the texture: " << without << " dB";
}

}  // namespace
}  // namespace probecast::renderer
