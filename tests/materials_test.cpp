// Materials in all three renderers (reference camera, probe updater, raster client): alphaMode
// Mask cut-outs, transmissive (Blend, KHR_materials_transmission) coloured panes, daylight through
// a window, KHR_texture_transform with a TEXCOORD_1 override, and the shading-normal rule.
#include <gtest/gtest.h>

#include <cmath>

#include "gltf_test_files.h"
#include "probecast/renderer/environment.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/reference_camera.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

using scene::Material;
using scene::Scene;

class Materials : public ::testing::Test {
 protected:
  void SetUp() override { context_ = std::make_unique<VulkanContext>(test::validatedContext()); }
  void TearDown() override { EXPECT_EQ(context_->validationMessages(), 0u) << "Vulkan validation messages"; }
  std::unique_ptr<VulkanContext> context_;
};

uint32_t addMaterial(Scene& s, const Material& m) {
  s.materials.push_back(m);
  return static_cast<uint32_t>(s.materials.size() - 1);
}

Material emitter(float radiance) {
  Material m;
  m.baseColor = glm::vec3(0.0f);
  m.emission = glm::vec3(radiance);
  return m;
}

// A square of half-size h at z facing +Z (towards a camera or probe at the origin).
void addFacingSquare(Scene& s, float z, float h, uint32_t material) {
  scene::addQuad(s, {-h, -h, z}, {h, -h, z}, {h, h, z}, {-h, h, z}, material);
}

// An 8 × 8 checker: alpha 255 where (x + y) is even, 0 elsewhere (white RGB).
scene::Texture checkerAlpha() {
  scene::Texture t;
  t.width = t.height = 8;
  t.rgba.assign(8 * 8 * 4, 255);
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) t.rgba[(y * 8 + x) * 4 + 3] = (x + y) % 2 == 0 ? 255 : 0;
  return t;
}

// A black Mask material cut by the checker (cutoff 0.5: holes are exactly half the area; bilinear
// alpha crosses 0.5 on the texel edges).
Material checkerMask() {
  Material m;
  m.baseColor = glm::vec3(0.0f);
  m.baseColorTexture = 0;
  m.alphaMode = scene::AlphaMode::Mask;
  return m;
}

double channelMean(const Image& img, int c) {
  double sum = 0;
  for (size_t i = static_cast<size_t>(c); i < img.rgb.size(); i += 3) sum += img.rgb[i];
  return sum / static_cast<double>(img.rgb.size() / 3);
}

using test::frontCamera;

Image referenceImage(VulkanContext& context, const Scene& s, const CameraView& cam, uint32_t size, uint32_t spp) {
  ReferenceOptions o;
  o.width = o.height = size;
  o.samplesPerPixel = spp;
  o.maxBounces = 1;
  return renderReference(context, s, cam, o);
}

Image rasterImage(VulkanContext& context, const Scene& s, const CameraView& cam, uint32_t size) {
  RasterRenderer raster(context, s, size, size);
  return raster.render(raster.viewProjection(cam), cam.position);
}

// c00 (R, G, B) of a probe at `p` after a few updates (no reflections: one interaction).
glm::vec3 probeDc(VulkanContext& context, const Scene& s, glm::vec3 p, std::shared_ptr<const Environment> sky = {}) {
  UpdaterOptions o;
  o.samplesPerProbe = 2048;
  o.maxBounces = 1;
  o.classify = false;
  o.environment = std::move(sky);
  ProbeUpdater updater(context, s, ProbeGrid{{1, 1, 1}, {{p.x, p.y, p.z}, {p.x, p.y, p.z}}}, o);
  for (int u = 0; u < 4; ++u) updater.update();
  const float* c = updater.volume().probes.data();
  return {c[0], c[1], c[2]};
}

// An emitter of radiance 1 at z = −2 behind a checker cut-out at z = −1: the camera sees the
// emitter through the holes, half the image; a probe at the origin gets half the light it gets
// without the cut-out (the cut-out covers exactly the emitter's cone; mirroring x swaps holes and
// solid cells, so the holes hold half the solid angle).
TEST_F(Materials, MaskCutOutLetsLightThroughItsHolesInEveryRenderer) {
  Scene s;
  s.textures.push_back(checkerAlpha());
  addFacingSquare(s, -2.0f, 2.0f, addMaterial(s, emitter(1.0f)));
  Scene bare = s;
  scene::finalizeScene(bare);
  addFacingSquare(s, -1.0f, 1.0f, addMaterial(s, checkerMask()));
  scene::finalizeScene(s);

  const Image ref = referenceImage(*context_, s, frontCamera(), 32, 4);
  EXPECT_NEAR(channelMean(ref, 0), 0.5, 0.02);
  // Cell (0, 0) (pixels 0..3) is solid, cell (1, 0) a hole.
  EXPECT_NEAR(ref.rgb[(1 * 32 + 1) * 3], 0.0f, 0.02f);
  EXPECT_NEAR(ref.rgb[(1 * 32 + 5) * 3], 1.0f, 0.02f);
  const Image raster = rasterImage(*context_, s, frontCamera(), 32);
  EXPECT_NEAR(channelMean(raster, 0), 0.5, 0.01);
  EXPECT_NEAR(raster.rgb[(1 * 32 + 1) * 3], 0.0f, 1e-3f);
  EXPECT_NEAR(raster.rgb[(1 * 32 + 5) * 3], 1.0f, 1e-3f);

  const float through = probeDc(*context_, s, glm::vec3(0.0f)).r, open = probeDc(*context_, bare, glm::vec3(0.0f)).r;
  ASSERT_GT(open, 0.1f);
  EXPECT_NEAR(through / open, 0.5f, 0.05f);
}

// A white floor under a checker cut-out 1 m up, lit by a sun straight down: the floor under the
// cut-out is lit on half its area — visibility rays pass the holes (tracer), the shadow map has
// them too (raster). The camera sits between the cut-out and the floor, looking down.
TEST_F(Materials, MaskCutOutCastsAHalfShadowInTracerAndRaster) {
  Scene s;
  s.textures.push_back(checkerAlpha());
  Material white;
  white.baseColor = glm::vec3(1.0f);
  scene::addQuad(s, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4}, addMaterial(s, white));
  scene::Light sun;
  sun.type = scene::LightType::Directional;
  sun.direction = {0, -1, 0};
  sun.intensity = 3.0f;
  s.lights.push_back(sun);
  Scene lit = s;
  scene::finalizeScene(lit);
  scene::addQuad(s, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}, {-1, 1, -1}, addMaterial(s, checkerMask()));
  scene::finalizeScene(s);
  CameraView down;
  down.position = {0, 0.5f, 0};
  down.forward = {0, -1, 0};
  down.up = {0, 0, -1};
  down.yfov = 1.5707963f;  // sees the floor under the middle 4 × 4 cells
  const double refLit = channelMean(referenceImage(*context_, lit, down, 32, 4), 1);
  const double refMasked = channelMean(referenceImage(*context_, s, down, 32, 4), 1);
  ASSERT_GT(refLit, 0.5);
  EXPECT_NEAR(refMasked / refLit, 0.5, 0.03);
  const double rasterLit = channelMean(rasterImage(*context_, lit, down, 32), 1);
  const double rasterMasked = channelMean(rasterImage(*context_, s, down, 32), 1);
  EXPECT_NEAR(rasterLit, refLit, 0.02 * refLit);
  EXPECT_NEAR(rasterMasked / rasterLit, 0.5, 0.05);
}

// Red glass (Blend, alpha 0.5, base (1, 0, 0)) in front of a white emitter: T = (1 − 0.5)·base, so
// the camera and a probe behind the glass see (0.5, 0, 0) of the emitter; the glass itself is lit
// by nothing on their side. A thin KHR_materials_transmission pane (t = 0.8, base (0, 0, 1),
// alphaMode Opaque) passes (0, 0, 0.8).
TEST_F(Materials, ColouredPaneTintsTheLightThroughItInEveryRenderer) {
  Scene s;
  addFacingSquare(s, -2.0f, 2.0f, addMaterial(s, emitter(1.0f)));
  Scene bare = s;
  scene::finalizeScene(bare);
  Material red;
  red.baseColor = {1, 0, 0};
  red.alphaMode = scene::AlphaMode::Blend;
  red.alpha = 0.5f;
  Scene glass = s;
  addFacingSquare(glass, -1.0f, 1.0f, addMaterial(glass, red));
  scene::finalizeScene(glass);
  Material blue;
  blue.baseColor = {0, 0, 1};
  blue.transmission = 0.8f;
  Scene thin = s;
  addFacingSquare(thin, -1.0f, 1.0f, addMaterial(thin, blue));
  scene::finalizeScene(thin);

  const Image ref = referenceImage(*context_, glass, frontCamera(), 16, 64);
  EXPECT_NEAR(channelMean(ref, 0), 0.5, 0.03);
  EXPECT_LT(channelMean(ref, 1), 1e-3);
  const Image raster = rasterImage(*context_, glass, frontCamera(), 16);
  EXPECT_NEAR(channelMean(raster, 0), 0.5, 1e-3);
  EXPECT_LT(channelMean(raster, 1), 1e-3);
  const Image rasterThin = rasterImage(*context_, thin, frontCamera(), 16);
  EXPECT_NEAR(channelMean(rasterThin, 2), 0.8, 1e-3);
  EXPECT_LT(channelMean(rasterThin, 0), 1e-3);

  const glm::vec3 open = probeDc(*context_, bare, glm::vec3(0.0f));
  const glm::vec3 red0 = probeDc(*context_, glass, glm::vec3(0.0f));
  const glm::vec3 blue0 = probeDc(*context_, thin, glm::vec3(0.0f));
  ASSERT_GT(open.r, 0.1f);
  EXPECT_NEAR(red0.r / open.r, 0.5f, 0.05f);
  EXPECT_LT(red0.g, 0.01f * open.g);
  EXPECT_NEAR(blue0.b / open.b, 0.8f, 0.05f);
  EXPECT_LT(blue0.r, 0.01f * open.r);
}

// A closed black room whose +Z wall is red glass, under a uniform white sky: the probe in the
// middle sees the sky through the window only, tinted: c00 = Y00 · ∫window T dω =
// 0.2820948 · 0.5 · 4π/6 for R, 0 for G and B. An opaque window would leave it black.
TEST_F(Materials, DaylightComesInThroughAColouredWindow) {
  Scene s;
  Material black;
  black.baseColor = glm::vec3(0.0f);
  const uint32_t wall = addMaterial(s, black);
  Material red;
  red.baseColor = {1, 0, 0};
  red.alphaMode = scene::AlphaMode::Blend;
  red.alpha = 0.5f;
  const uint32_t window = addMaterial(s, red);
  const float a = -1, b = 1;
  scene::addQuad(s, {a, a, a}, {b, a, a}, {b, b, a}, {a, b, a}, wall);
  scene::addQuad(s, {b, a, b}, {a, a, b}, {a, b, b}, {b, b, b}, window);
  scene::addQuad(s, {a, a, b}, {b, a, b}, {b, a, a}, {a, a, a}, wall);
  scene::addQuad(s, {a, b, a}, {b, b, a}, {b, b, b}, {a, b, b}, wall);
  scene::addQuad(s, {a, a, b}, {a, a, a}, {a, b, a}, {a, b, b}, wall);
  scene::addQuad(s, {b, a, a}, {b, a, b}, {b, b, b}, {b, b, a}, wall);
  scene::finalizeScene(s);
  auto sky = std::make_shared<Environment>();
  std::string error;
  ASSERT_TRUE(makeUniformSky(glm::vec3(1.0f), *sky, error)) << error;
  const glm::vec3 c = probeDc(*context_, s, glm::vec3(0.0f), sky);
  const float expected = 0.2820948f * 0.5f * 4.0f * 3.14159265f / 6.0f;
  EXPECT_NEAR(c.r, expected, 0.05f * expected);
  EXPECT_LT(c.g, 1e-3f);
  EXPECT_LT(c.b, 1e-3f);
}

// Centre of the pixels brighter than half the image's maximum (channel 0), in pixel units with
// pixel (x, y) at (x + ½, y + ½).
glm::vec2 brightCentroid(const Image& img) {
  float peak = 0;
  for (size_t i = 0; i < img.rgb.size(); i += 3) peak = std::max(peak, img.rgb[i]);
  glm::dvec2 sum(0.0);
  double weight = 0;
  for (uint32_t y = 0; y < img.height; ++y)
    for (uint32_t x = 0; x < img.width; ++x) {
      const float v = img.rgb[(static_cast<size_t>(y) * img.width + x) * 3];
      if (v < 0.5f * peak) continue;
      sum += glm::dvec2(x + 0.5, y + 0.5) * static_cast<double>(v);
      weight += v;
    }
  return weight > 0 ? glm::vec2(sum / weight) : glm::vec2(-1.0f);
}

// An emissive square whose 8 × 8 emission texture is black but for texel (6, 0), read through
// KHR_texture_transform (offset (0.5, 0.25), rotation π/2, scale (0.5, 0.5)) of TEXCOORD_1, which
// is TEXCOORD_0 mirrored in u. uv' = (0.5 v1 + 0.5, −0.5 u1 + 0.25) reaches the texel centre
// (0.8125, 0.0625) at u1 = 0.375, v1 = 0.625, i.e. u0 = 0.625: pixel (40, 40) of a 64 × 64 view.
// Without the transform the texel shows at (52, 4); through TEXCOORD_0, at (24, 40).
TEST_F(Materials, TextureTransformMovesATexelToTheSameScreenPositionInTracerAndRaster) {
  const std::string dir = PROBECAST_TEST_TMP;
  std::vector<uint16_t> texels(8 * 8 * 3, 0);
  for (int c = 0; c < 3; ++c) texels[(0 * 8 + 6) * 3 + c] = 255;
  test::writeFile(dir + "/one_texel.png", test::pngFile(8, 8, 3, 8, texels));
  std::vector<test::GltfQuad> quads(1);
  test::GltfQuad& q = quads[0];
  q.corners[0] = {-1, -1, -1}, q.corners[1] = {1, -1, -1}, q.corners[2] = {1, 1, -1}, q.corners[3] = {-1, 1, -1};
  for (int k = 0; k < 4; ++k) q.uv1[k] = {1.0f - q.uv0[k].x, q.uv0[k].y};
  const std::string path = test::writeQuadGltf(
      dir, "texture_transform", quads,
      R"({"pbrMetallicRoughness":{"baseColorFactor":[0,0,0,1]},"emissiveFactor":[1,1,1],)"
      R"("emissiveTexture":{"index":0,"extensions":{"KHR_texture_transform":)"
      R"({"offset":[0.5,0.25],"rotation":1.5707963268,"scale":[0.5,0.5],"texCoord":1}}}})",
      R"({"source":0})", R"({"uri":"one_texel.png"})",
      R"("extensionsUsed":["KHR_texture_transform"],"extensionsRequired":["KHR_texture_transform"],)");
  Scene s;
  std::string error;
  ASSERT_TRUE(scene::loadGltf(path, s, error)) << error;
  const glm::vec2 expected(40.0f, 40.0f);
  const glm::vec2 ref = brightCentroid(referenceImage(*context_, s, frontCamera(), 64, 4));
  EXPECT_NEAR(ref.x, expected.x, 1.0f);
  EXPECT_NEAR(ref.y, expected.y, 1.0f);
  const glm::vec2 raster = brightCentroid(rasterImage(*context_, s, frontCamera(), 64));
  EXPECT_NEAR(raster.x, expected.x, 1.0f);
  EXPECT_NEAR(raster.y, expected.y, 1.0f);
}

// A floor (geometric normal +Y) whose shading normals lean 60° toward +X, seen from the −X side
// at a low angle: every view ray falls below the shading normal. The rule (material.glsl) bends
// the normal toward the viewer in the tracer and the raster client alike, so with one direct
// light and nothing else both give the same picture — no bright floor in one and dark in the other.
TEST_F(Materials, ShadingNormalBelowTheViewIsBentTheSameWayInTracerAndRaster) {
  Scene s;
  Material white;
  white.baseColor = glm::vec3(0.8f);
  white.roughness = 0.7f;
  scene::addQuad(s, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, {-10, 0, -10}, addMaterial(s, white));
  for (glm::vec3& n : s.normals) n = glm::normalize(glm::vec3(0.866f, 0.5f, 0.0f));
  scene::Light sun;
  sun.type = scene::LightType::Directional;
  sun.direction = glm::normalize(glm::vec3(0.2f, -1.0f, 0.1f));
  sun.intensity = 3.0f;
  s.lights.push_back(sun);
  scene::finalizeScene(s);
  CameraView cam;
  cam.position = {-2, 1, 0};
  cam.forward = glm::normalize(glm::vec3(2, -1, 0));
  cam.up = {0, 1, 0};
  cam.yfov = 0.6f;
  const uint32_t size = 32;
  const Image ref = referenceImage(*context_, s, cam, size, 16);
  const Image raster = rasterImage(*context_, s, cam, size);
  const double refMean = channelMean(ref, 1), rasterMean = channelMean(raster, 1);
  ASSERT_GT(rasterMean, 0.05);
  EXPECT_NEAR(refMean, rasterMean, 0.03 * rasterMean);
  // Pixel by pixel (rows away from the far edge of the floor, where jitter mixes in black).
  for (uint32_t y = 2; y < size; y += 3)
    for (uint32_t x = 1; x < size; x += 3) {
      const size_t i = (static_cast<size_t>(y) * size + x) * 3 + 1;
      EXPECT_NEAR(ref.rgb[i], raster.rgb[i], 0.05f * raster.rgb[i] + 1e-3f) << x << "," << y;
    }
}

// One texel of linear data: the channels as stored (a metallic-roughness or occlusion texture).
scene::Texture dataTexel(uint8_t r, uint8_t g, uint8_t b) {
  scene::Texture t;
  t.width = t.height = 1;
  t.rgba = {r, g, b, 255};
  return t;
}

// A square of `m` filling the front camera, lit (`bulb`) by a point light beside the camera: its
// highlight depends on metallic and roughness.
Scene squareScene(const Material& m, const std::vector<scene::Texture>& textures, bool bulb = true) {
  Scene s;
  s.textures = textures;
  addFacingSquare(s, -1.0f, 1.0f, addMaterial(s, m));
  if (bulb) {
    scene::Light l;
    l.position = {0.3f, 0.3f, -0.2f};
    l.intensity = 0.5f;
    s.lights.push_back(l);
  }
  scene::finalizeScene(s);
  return s;
}

double maxRelativeDifference(const Image& a, const Image& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    worst = std::max(worst, std::fabs(static_cast<double>(a.rgb[i]) - b.rgb[i]) / std::max(1e-3, std::fabs(static_cast<double>(b.rgb[i]))));
  return worst;
}

TEST_F(Materials, MetallicRoughnessTextureScalesTheFactorsByItsBlueAndGreenAsStored) {
  // glTF: metallic = metallicFactor × B, roughness = roughnessFactor × G, the texture's values as
  // stored (linear, not sRGB). Factors 1 and 1 with a texel (255, 128, 0) must shade exactly as
  // metallic 0, roughness 128/255 without a texture, in the raster client and the path tracer;
  // reading G as sRGB (roughness 0.216) or B as metallic 1 shades otherwise.
  Material grey;
  grey.baseColor = glm::vec3(0.5f);
  Material textured = grey;
  textured.metallic = 1.0f;
  textured.roughness = 1.0f;
  textured.metallicRoughnessTexture = 0;
  Material plain = grey;
  plain.metallic = 0.0f;
  plain.roughness = 128.0f / 255.0f;
  Material asSrgb = plain;
  asSrgb.roughness = 0.2158605f;  // the sRGB decoding of 128/255
  Material metal = plain;
  metal.metallic = 1.0f;
  const Scene a = squareScene(textured, {dataTexel(255, 128, 0)}), b = squareScene(plain, {}),
              c = squareScene(asSrgb, {}), d = squareScene(metal, {});
  const CameraView cam = frontCamera();
  const Image ra = rasterImage(*context_, a, cam, 32), rb = rasterImage(*context_, b, cam, 32);
  EXPECT_LT(maxRelativeDifference(ra, rb), 1e-4);
  EXPECT_GT(maxRelativeDifference(rasterImage(*context_, c, cam, 32), rb), 0.05);
  EXPECT_GT(maxRelativeDifference(rasterImage(*context_, d, cam, 32), rb), 0.05);
  const Image ta = referenceImage(*context_, a, cam, 16, 16), tb = referenceImage(*context_, b, cam, 16, 16);
  EXPECT_LT(maxRelativeDifference(ta, tb), 1e-3);
  EXPECT_GT(maxRelativeDifference(referenceImage(*context_, d, cam, 16, 16), tb), 0.05);
}

TEST_F(Materials, OcclusionTextureDimsOnlyTheRasterClientsProbeLightByItsStrength) {
  // occlusion = 1 + strength × (R − 1): R = 0 at strength 0.5 halves the probe light the raster
  // client shades with (no lights, no emission here); the path tracer ignores the texture.
  Material white;
  white.baseColor = glm::vec3(1.0f);
  Material occluded = white;
  occluded.occlusionTexture = 0;
  occluded.occlusionStrength = 0.5f;
  const Scene open = squareScene(white, {dataTexel(0, 255, 255)}, false),
              dim = squareScene(occluded, {dataTexel(0, 255, 255)}, false);
  ProbeVolume v = makeProbeVolume(ProbeGrid{{2, 2, 2}, {{-1, -1, -1.5f}, {1, 1, 0}}});
  for (int p = 0; p < 8; ++p)
    for (int c = 0; c < 3; ++c) v.probes[p * 27 + c] = 1.0f;
  const CameraView cam = frontCamera();
  const auto render = [&](const Scene& s) {
    RasterOptions ro;
    ro.visibility = false;
    RasterRenderer raster(*context_, s, 16, 16, ro);
    raster.setProbes(v);
    return raster.render(raster.viewProjection(cam), cam.position);
  };
  const Image full = render(open), half = render(dim);
  ASSERT_GT(channelMean(full, 0), 0.01);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(channelMean(half, c) / channelMean(full, c), 0.5, 1e-4);
}

}  // namespace
}  // namespace probecast::renderer
