// Raster shadow maps of directional lights: cascades fitted to the view set, and shadows cast by
// transmissive surfaces.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "probecast/renderer/raster_client.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

using scene::Material;
using scene::Scene;

// Appends material m to s and returns its index.
uint32_t withMaterial(Scene& s, const Material& m) {
  s.materials.push_back(m);
  return static_cast<uint32_t>(s.materials.size()) - 1u;
}

// The red channel of the pixel that world point p falls on (NAN off the image).
float pixelAt(const Image& img, const glm::mat4& viewProj, glm::vec3 p, glm::ivec2* pixel = nullptr) {
  const glm::vec4 clip = viewProj * glm::vec4(p, 1.0f);
  const glm::vec2 ndc = glm::vec2(clip) / clip.w;
  const int x = static_cast<int>(std::floor((ndc.x * 0.5f + 0.5f) * static_cast<float>(img.width)));
  const int y = static_cast<int>(std::floor((ndc.y * 0.5f + 0.5f) * static_cast<float>(img.height)));
  if (clip.w <= 0.0f || x < 0 || y < 0 || x >= static_cast<int>(img.width) || y >= static_cast<int>(img.height))
    return NAN;
  if (pixel) *pixel = {x, y};
  return img.rgb[(static_cast<size_t>(y) * img.width + static_cast<size_t>(x)) * 3];
}

// A 64 m white floor and two 3 m posts, 8 m and 42 m ahead of a camera 8 m up, under a sun 45°
// from the zenith that throws their shadows 3 m sideways (+x). Shadow map of 256 texels: one layer
// over the scene has texels of ~25 cm, so its near shadow edge is a wide ramp.
struct PostScene {
  Scene scene;
  CameraView camera;
  PostScene() {
    Material white;
    white.baseColor = glm::vec3(1.0f);
    const uint32_t m = withMaterial(scene, white);
    scene::addQuad(scene, {-8, 0, 4}, {8, 0, 4}, {8, 0, -60}, {-8, 0, -60}, m);
    scene::addBox(scene, {0, 1.5f, -6}, {0.1f, 1.5f, 0.5f}, 0.0f, m);
    scene::addBox(scene, {0, 1.5f, -40}, {0.1f, 1.5f, 10.0f}, 0.0f, m);
    scene.lights.push_back(
        {.type = scene::LightType::Directional, .direction = glm::normalize(glm::vec3(1, -1, 0)), .intensity = 3.0f});
    scene::finalizeScene(scene);
    camera.position = {1, 8, 2};
    camera.forward = glm::normalize(glm::vec3(0, -1, -3));
    camera.yfov = 1.2f;
  }
};

struct PostShadow {
  float lit = 0, nearShadow = 0, farShadow = 0, farLit = 0;
  size_t nearRampPixels = 0;  // pixels on the near shadow's outer edge between 10 % and 90 % lit
};

PostShadow measurePosts(RasterRenderer& raster, const CameraView& camera) {
  const glm::mat4 vp = raster.viewProjection(camera);
  const Image img = raster.render(vp, camera.position);
  PostShadow r;
  r.lit = pixelAt(img, vp, {4.0f, 0.0f, -8.0f});
  r.nearShadow = pixelAt(img, vp, {1.6f, 0.0f, -6.0f});
  r.farShadow = pixelAt(img, vp, {1.6f, 0.0f, -40.0f});
  r.farLit = pixelAt(img, vp, {5.5f, 0.0f, -40.0f});
  // The shadow's edge at x = 3.1 (the posts' tops), crossed along x at the near post's middle.
  std::set<std::pair<int, int>> ramp;
  for (float x = 2.1f; x <= 4.1f; x += 0.005f) {
    glm::ivec2 px;
    const float v = pixelAt(img, vp, {x, 0.0f, -6.0f}, &px);
    if (v > 0.1f * r.lit && v < 0.9f * r.lit) ramp.insert({px.x, px.y});
  }
  r.nearRampPixels = ramp.size();
  return r;
}

RasterOptions postOptions(uint32_t cascades) {
  RasterOptions o;
  o.shadowMapSize = 256;
  o.shadowCascades = cascades;
  return o;
}

// Both posts' shadows show with one layer and with four cascades; the cascades' near edge is
// sharper (the finest cascade has texels of a few cm next to the camera).
TEST(ShadowMaps, CascadesSharpenTheNearShadowAndKeepTheFarOne) {
  VulkanContext context(test::validatedContext());
  const PostScene ps;
  RasterRenderer layer(context, ps.scene, 192, 128, postOptions(1)), cascaded(context, ps.scene, 192, 128, postOptions(4));
  const PostShadow one = measurePosts(layer, ps.camera), four = measurePosts(cascaded, ps.camera);
  for (const PostShadow* r : {&one, &four}) {
    ASSERT_GT(r->lit, 0.3f);
    EXPECT_LT(r->nearShadow, 0.05f * r->lit);
    EXPECT_LT(r->farShadow, 0.1f * r->lit);
    EXPECT_GT(r->farLit, 0.8f * r->lit);
  }
  EXPECT_GE(one.nearRampPixels, 4u);
  EXPECT_LT(four.nearRampPixels * 2, one.nearRampPixels) << "4 cascades: " << four.nearRampPixels
                                                         << " ramp pixels, 1: " << one.nearRampPixels;
  EXPECT_EQ(context.validationMessages(), 0u);
}

// The cascades follow the view set: after a view 20 m further on (whose cascades leave the near
// post to the coarsest one), the first view gets its sharp near shadow back.
TEST(ShadowMaps, CascadesAreRefittedWhenTheViewsChange) {
  VulkanContext context(test::validatedContext());
  const PostScene ps;
  RasterRenderer first(context, ps.scene, 192, 128, postOptions(4)), moved(context, ps.scene, 192, 128, postOptions(4));
  const PostShadow fresh = measurePosts(first, ps.camera);
  CameraView ahead = ps.camera;
  ahead.position.z -= 20.0f;
  moved.render(moved.viewProjection(ahead), ahead.position);
  const PostShadow back = measurePosts(moved, ps.camera);
  EXPECT_EQ(back.nearRampPixels, fresh.nearRampPixels);
  EXPECT_LT(back.nearShadow, 0.05f * back.lit);
  EXPECT_LT(back.farShadow, 0.1f * back.lit);
  EXPECT_EQ(context.validationMessages(), 0u);
}

// A white floor lit from 3 m above (a sun straight down, then a point light) through a 2 × 2 m pane
// 1 m up, seen from below the pane: clear glass (transmission 1, white) leaves the floor as lit as
// without it; red glass (Blend, alpha 0.5: T = (0.5, 0, 0), the tracers' thin rule) tints it red.
TEST(ShadowMaps, TransmissivePanesCastColouredShadows) {
  VulkanContext context(test::validatedContext());
  for (scene::LightType type : {scene::LightType::Directional, scene::LightType::Point}) {
    Scene s;
    Material white;
    white.baseColor = glm::vec3(1.0f);
    scene::addQuad(s, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4}, withMaterial(s, white));
    scene::Light light;
    light.type = type;
    light.position = {0, 3, 0};
    light.direction = {0, -1, 0};
    light.intensity = 3.0f;
    s.lights.push_back(light);
    Scene bare = s;
    scene::finalizeScene(bare);
    Material clear;
    clear.baseColor = glm::vec3(1.0f);
    clear.transmission = 1.0f;
    Material red;
    red.baseColor = {1, 0, 0};
    red.alphaMode = scene::AlphaMode::Blend;
    red.alpha = 0.5f;
    Scene clearPane = s, redPane = s;
    scene::addQuad(clearPane, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}, {-1, 1, -1}, withMaterial(clearPane, clear));
    scene::addQuad(redPane, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}, {-1, 1, -1}, withMaterial(redPane, red));
    scene::finalizeScene(clearPane);
    scene::finalizeScene(redPane);
    CameraView down;
    down.position = {0, 0.5f, 0};
    down.forward = {0, -1, 0};
    down.up = {0, 0, -1};
    down.yfov = 1.5707963f;
    const auto mean = [&](const Scene& scene, int c) {
      RasterRenderer raster(context, scene, 32, 32);
      const Image img = raster.render(raster.viewProjection(down), down.position);
      double sum = 0;
      for (size_t i = static_cast<size_t>(c); i < img.rgb.size(); i += 3) sum += img.rgb[i];
      return sum / static_cast<double>(img.rgb.size() / 3);
    };
    const double lit[3] = {mean(bare, 0), mean(bare, 1), mean(bare, 2)};
    ASSERT_GT(lit[0], 0.1) << static_cast<int>(type);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean(clearPane, c) / lit[c], 1.0, 0.03) << "clear, channel " << c;
    EXPECT_NEAR(mean(redPane, 0) / lit[0], 0.5, 0.03) << "red pane, light type " << static_cast<int>(type);
    EXPECT_LT(mean(redPane, 1) / lit[1], 0.01) << "red pane, light type " << static_cast<int>(type);
    EXPECT_LT(mean(redPane, 2) / lit[2], 0.01) << "red pane, light type " << static_cast<int>(type);
  }
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(ShadowMaps, CascadeCountOutsideOneToFourIsRefused) {
  VulkanContext context(test::validatedContext());
  const PostScene ps;
  for (uint32_t n : {0u, 5u, 0xffffffffu}) {
    RasterOptions o;
    o.shadowCascades = n;
    EXPECT_THROW(RasterRenderer(context, ps.scene, 8, 8, o), std::invalid_argument) << n;
  }
  EXPECT_EQ(context.validationMessages(), 0u);
}

}  // namespace
}  // namespace probecast::renderer
