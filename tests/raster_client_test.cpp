// The raster client: analytic diffuse indirect light, inactive-probe filling, a Cornell render.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "probecast/renderer/glossy_sh.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

TEST(RasterClient, ConstantProbeVolumeLightsWhitePlaneToTheAnalyticValue) {
  // Radiance L from every direction: E = π L (docs/CODEC.md §8.1), so a white Lambertian plane
  // reflects albedo/π · E = L; the glossy split sum adds L · (F0·A + B) (the prefiltered constant
  // radiance is L whatever the lobe), F0 = 0.04, (A, B) from the environment-BRDF table at
  // roughness 1 and n·v ≈ 1 (its last texel; the sampler clamps there). No lights, no emission.
  VulkanContext context(test::validatedContext());
  scene::Scene s;
  scene::Material white;
  white.baseColor = glm::vec3(1.0f);
  s.materials.push_back(white);
  scene::addQuad(s, {-5, 0, 5}, {5, 0, 5}, {5, 0, -5}, {-5, 0, -5}, 0);
  scene::finalizeScene(s);
  RasterRenderer raster(context, s, 32, 24);
  const glm::vec3 L(0.5f, 0.25f, 0.125f);
  ProbeVolume v = makeProbeVolume(ProbeGrid{{3, 2, 3}, {{-4, -1, -4}, {4, 1, 4}}});
  for (int p = 0; p < 18; ++p)
    for (int c = 0; c < 3; ++c) v.probes[p * 27 + c] = 3.5449077f * L[c];  // c00 = 2√π L
  raster.setProbes(v);
  CameraView cam;
  cam.position = {0, 3, 0.01f};
  cam.forward = glm::normalize(glm::vec3(0, -1, -0.01f));
  cam.up = {0, 0, -1};
  cam.yfov = 0.5f;
  const Image img = raster.render(raster.viewProjection(cam), cam.position);
  const std::vector<float> table = envBrdfTable(32, 256);
  const float a = table[(31 * 32 + 31) * 2], b = table[(31 * 32 + 31) * 2 + 1];
  const float gain = 1.0f + 0.04f * a + b;
  EXPECT_GT(gain - 1.0f, 0.005f);  // the glossy term is there
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.rgb[(12 * 32 + 16) * 3 + c], L[c] * gain, 2e-4f * L[c]);
  // Off centre n·v drops a little (≥ 0.94 here), and with it the glossy share.
  for (uint32_t y = 4; y < 20; y += 5)
    for (uint32_t x = 4; x < 28; x += 7)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.rgb[(y * 32 + x) * 3 + c], L[c] * gain, 0.01f * L[c]) << x << "," << y;
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(RasterClient, InactiveProbesAreFilledFromActiveNeighbours) {
  ProbeVolume v = makeProbeVolume(ProbeGrid{{3, 1, 1}, {{0, 0, 0}, {2, 0, 0}}});
  v.probes[0] = 2.0f;   // probe 0 active, c00 R = 2
  v.probes[54] = 4.0f;  // probe 2 active, c00 R = 4
  v.active = {1, 0, 1};
  fillInactiveProbes(v);
  EXPECT_FLOAT_EQ(v.probes[27], 3.0f);  // the inactive middle probe takes the mean, not black
  v.active = {0, 0, 1};
  v.probes.assign(3 * 27, 0.0f);
  v.probes[54] = 4.0f;
  fillInactiveProbes(v);
  EXPECT_FLOAT_EQ(v.probes[0], 4.0f);  // filled across two steps
}

// n³ probes over the inner three quarters of the scene's bounds after one update of `spp` samples.
ProbeVolume onceUpdatedProbes(VulkanContext& context, const scene::Scene& s, uint32_t n, uint32_t spp) {
  const glm::vec3 lo = s.boundsMin + 0.125f * (s.boundsMax - s.boundsMin);
  const glm::vec3 hi = s.boundsMax - 0.125f * (s.boundsMax - s.boundsMin);
  UpdaterOptions uo;
  uo.samplesPerProbe = spp;
  ProbeUpdater updater(context, s, ProbeGrid{{n, n, n}, {{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}}}, uo);
  updater.update();
  return updater.volume();
}

TEST(RasterClient, CornellWithUpdatedProbesRendersLitAndDeterministic) {
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("cornell", 0.0f);
  const ProbeVolume v = onceUpdatedProbes(context, s, 4, 64);
  RasterRenderer raster(context, s, 48, 36);
  raster.setProbes(v);
  const CameraView cam = CameraView::fromScene(s);
  const Image a = raster.render(raster.viewProjection(cam), cam.position);
  const Image b = raster.render(raster.viewProjection(cam), cam.position);
  EXPECT_EQ(a.rgb, b.rgb);
  double mean = 0;
  for (float x : a.rgb) {
    ASSERT_TRUE(std::isfinite(x));
    mean += x;
  }
  EXPECT_GT(mean / static_cast<double>(a.rgb.size()), 0.05);
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(RasterClient, RasterOnlyDeviceDrawsWhatARayTracingOneDraws) {
  // A viewer's device asks for no ray-tracing extension (headset and mobile GPUs have none): the
  // picture is the same bit for bit, and tracing on such a device is refused by name.
  const scene::Scene s = test::builtinScene("cornell", 0.0f);
  Image traced;
  ProbeVolume v;
  {
    VulkanContext context(test::validatedContext());
    ASSERT_TRUE(context.rayTracing());
    v = onceUpdatedProbes(context, s, 4, 32);
    RasterRenderer raster(context, s, 40, 30);
    raster.setProbes(v);
    const CameraView cam = CameraView::fromScene(s);
    traced = raster.render(raster.viewProjection(cam), cam.position);
  }
  ContextOptions options = test::validatedContext();
  options.rayTracing = false;
  VulkanContext rasterOnly(options);
  EXPECT_FALSE(rasterOnly.rayTracing());
  RasterRenderer raster(rasterOnly, s, 40, 30);
  raster.setProbes(v);
  scene::Scene moved = s;  // a move too: shading and visibility redraws need no acceleration structure
  raster.setShading(moved);
  const CameraView cam = CameraView::fromScene(s);
  const Image img = raster.render(raster.viewProjection(cam), cam.position);
  EXPECT_EQ(img.rgb, traced.rgb);
  EXPECT_EQ(rasterOnly.validationMessages(), 0u);
  try {
    ProbeUpdater updater(rasterOnly, s, ProbeGrid{{2, 2, 2}, {{0, 0, 0}, {1, 1, 1}}});
    FAIL() << "an updater on a raster-only device";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the probe updater needs ray tracing"), std::string::npos) << e.what();
  }
}

TEST(RasterClient, MsaaSmoothsEdgesTowardTheSupersampledPictureOverTheEnvironment) {
  // A floating quad against a bright uniform sky: with MSAA the edge pixels blend quad and sky as
  // the 4×4-supersampled picture does (the sky goes behind what the samples left uncovered);
  // inside the quad and in open sky nothing changes.
  VulkanContext context(test::validatedContext());
  scene::Scene s;
  scene::Material grey;
  grey.baseColor = glm::vec3(0.5f);
  grey.emission = glm::vec3(0.2f);
  s.materials.push_back(grey);
  scene::addQuad(s, {-0.7f, -0.45f, 0}, {0.6f, -0.55f, 0}, {0.55f, 0.5f, 0}, {-0.65f, 0.4f, 0}, 0);
  scene::finalizeScene(s);
  auto sky = std::make_shared<Environment>();
  std::string error;
  ASSERT_TRUE(makeUniformSky(glm::vec3(2.0f, 1.5f, 1.0f), *sky, error)) << error;
  CameraView cam;
  cam.position = {0, 0, 2.5f};
  cam.forward = {0, 0, -1};
  cam.up = {0, 1, 0};
  cam.yfov = 0.7f;
  auto draw = [&](uint32_t perSide, uint32_t msaa) {
    RasterOptions o;
    o.samplesPerSide = perSide;
    o.msaaSamples = msaa;
    o.environment = sky;
    RasterRenderer raster(context, s, 48, 32, o);
    raster.setProbes(makeProbeVolume(ProbeGrid{{2, 2, 2}, {{-1, -1, -1}, {1, 1, 1}}}));
    return raster.render(raster.viewProjection(cam), cam.position);
  };
  const Image one = draw(1, 1), msaa = draw(1, 4), super = draw(4, 1);
  double errOne = 0.0, errMsaa = 0.0;
  size_t edges = 0, changed = 0;
  for (size_t p = 0; p < one.rgb.size() / 3; ++p) {
    double dOne = 0.0, dMsaa = 0.0, dEach = 0.0;
    for (size_t c = 0; c < 3; ++c) {
      dOne += std::abs(one.rgb[p * 3 + c] - super.rgb[p * 3 + c]);
      dMsaa += std::abs(msaa.rgb[p * 3 + c] - super.rgb[p * 3 + c]);
      dEach += std::abs(msaa.rgb[p * 3 + c] - one.rgb[p * 3 + c]);
    }
    errOne += dOne;
    errMsaa += dMsaa;
    edges += dOne > 0.05 ? 1 : 0;
    changed += dEach > 1e-4 ? 1 : 0;
  }
  EXPECT_GT(edges, 20u);                   // the quad has edges to smooth
  EXPECT_LT(errMsaa, 0.35 * errOne);       // and MSAA smooths them most of the way
  EXPECT_LT(changed, one.rgb.size() / 6);  // only edge pixels change (well under half of them)
  EXPECT_GT(changed, 10u);
  EXPECT_EQ(context.validationMessages(), 0u);
  try {
    RasterOptions bad;
    bad.msaaSamples = 3;
    RasterRenderer raster(context, s, 8, 8, bad);
    FAIL() << "3 MSAA samples taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "MSAA samples must be 1, 2, 4 or 8");
  }
}

TEST(RasterClient, MovedGeometryIsDrawnWhereItIsNow) {
  // The animated Cornell box posed at 1.9 s, then at 2 s, given through setShading draws exactly
  // what a renderer made at 2 s draws (vertices, shadow maps and the probes' visibility all moved
  // with it), and differs from the picture at 0 s. The second, small move draws again only the
  // depth cubes of the probes within reach of what moved.
  VulkanContext context(test::validatedContext());
  const std::string path = std::string(PROBECAST_TEST_DATA) + "/scenes/cornell-animated/cornell-animated.gltf";
  scene::Scene at0, at19, at2;
  std::string error;
  ASSERT_TRUE(scene::loadScene(path, 0.0, at0, error)) << error;
  ASSERT_TRUE(scene::loadScene(path, 1.9, at19, error)) << error;
  ASSERT_TRUE(scene::loadScene(path, 2.0, at2, error)) << error;
  for (scene::Scene* s : {&at0, &at19, &at2}) {  // a point light under the ceiling: six shadow layers
    scene::Light bulb;
    bulb.position = {0.0f, 1.8f, 0.0f};
    bulb.intensity = 2.0f;
    s->lights.push_back(bulb);
  }
  const ProbeVolume v = onceUpdatedProbes(context, at2, 8, 32);
  const CameraView cam = CameraView::fromScene(at0);
  RasterOptions ro;
  ro.areaLights.enabled = true;  // the ceiling panel, with a shadow layer of its own
  RasterRenderer moving(context, at0, 64, 48, ro);
  moving.setProbes(v);
  const Image before = moving.render(moving.viewProjection(cam), cam.position);
  EXPECT_EQ(moving.timings().geometryMoves, 0u);
  moving.setShading(at19);
  (void)moving.render(moving.viewProjection(cam), cam.position);
  moving.setShading(at2);
  EXPECT_EQ(moving.timings().geometryMoves, 2u);
  EXPECT_GT(moving.timings().visibilityProbesRedrawn, 0u);
  EXPECT_LT(moving.timings().visibilityProbesRedrawn, 512u * 3 / 4);  // 271 here: the movers fill much of the room
  const Image after = moving.render(moving.viewProjection(cam), cam.position);
  // Of the bulb's six layers, those that see neither the cube nor the arm kept their depth.
  EXPECT_GT(moving.timings().shadowLayersDrawn, 0u);
  EXPECT_LT(moving.timings().shadowLayersDrawn, 6u);
  RasterRenderer direct(context, at2, 64, 48, ro);
  direct.setProbes(v);
  const Image want = direct.render(direct.viewProjection(cam), cam.position);
  EXPECT_EQ(after.rgb, want.rgb);
  size_t differing = 0;
  for (size_t i = 0; i < before.rgb.size(); i += 3)
    differing += std::fabs(before.rgb[i] - after.rgb[i]) + std::fabs(before.rgb[i + 1] - after.rgb[i + 1]) > 0.02f;
  EXPECT_GT(differing, before.rgb.size() / 3 / 50);  // the cube and the arm moved: > 2 % of the pixels
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(RasterClient, ShadingWithOtherTexturesDrawsThem) {
  // The box's materials take their base colour from one 1×1 texture, white; setShading with it dark
  // grey (same geometry and probes) must darken the directly lit picture: the raster draws the
  // texture it was given last, as a fresh renderer of the dark box does, bit for bit. The same
  // texture again changes nothing; other geometry is refused.
  VulkanContext context(test::validatedContext());
  scene::Scene white = test::builtinScene("cornell", 0.0f);
  white.textures = {scene::Texture{1, 1, {255, 255, 255, 255}}};
  for (scene::Material& m : white.materials) m.baseColorTexture = 0;
  scene::Scene dark = white;
  dark.textures[0].rgba = {40, 40, 40, 255};
  const ProbeVolume v = onceUpdatedProbes(context, white, 4, 32);
  const CameraView cam = CameraView::fromScene(white);
  const auto meanOf = [](const Image& i) {
    double sum = 0;
    for (float x : i.rgb) sum += x;
    return sum / static_cast<double>(i.rgb.size());
  };
  RasterRenderer raster(context, white, 32, 24), fresh(context, dark, 32, 24);
  raster.setProbes(v);
  fresh.setProbes(v);
  const Image before = raster.render(raster.viewProjection(cam), cam.position);
  raster.setShading(dark);
  const Image after = raster.render(raster.viewProjection(cam), cam.position);
  EXPECT_EQ(after.rgb, fresh.render(fresh.viewProjection(cam), cam.position).rgb);
  EXPECT_LT(meanOf(after), 0.5 * meanOf(before));
  raster.setShading(dark);
  EXPECT_EQ(raster.render(raster.viewProjection(cam), cam.position).rgb, after.rgb);
  scene::Scene moved = dark;
  moved.positions.push_back(glm::vec3(0.0f));
  EXPECT_THROW(raster.setShading(moved), std::invalid_argument);
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(RasterClient, LightFieldQuiltTileEqualsMonoRenderOfThatView) {
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("cornell", 0.0f);
  std::string error;
  RasterRenderer raster(context, s, 20, 16);
  ViewSetSpec spec;
  ASSERT_TRUE(parseViewSet("lf:3x2", spec, error));
  ViewSetOptions vo;
  vo.aspect = 20.0f / 16.0f;
  const CameraView cam = CameraView::fromScene(s);
  const auto views = makeViewSet(cam, spec, vo);
  ASSERT_EQ(views.size(), 6u);
  std::vector<Image> images;
  for (const auto& v : views) images.push_back(raster.render(v.viewProj, v.eye));
  const Image quilt = composeQuilt(images, views, 3, 2);
  ASSERT_EQ(quilt.width, 60u);
  ASSERT_EQ(quilt.height, 32u);
  // View 4 is column 1 of row 1 (the top row): quilt tile x = 1, y = 0. Render it alone, as mono.
  const Image mono = raster.render(views[4].viewProj, views[4].eye);
  for (uint32_t y = 0; y < 16; ++y)
    for (uint32_t x = 0; x < 20; ++x)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(quilt.rgb[((y + 0) * 60 + 20 + x) * 3 + c], mono.rgb[(y * 20 + x) * 3 + c]) << x << "," << y;
  // Neighbouring views differ (parallax), and the centre view of an odd array is the mono camera.
  EXPECT_NE(images[3].rgb, images[4].rgb);
  ViewSetSpec odd;
  ASSERT_TRUE(parseViewSet("lf:3x3", odd, error));
  const auto oddViews = makeViewSet(cam, odd, vo);
  ViewSetSpec monoSpec;
  ASSERT_TRUE(parseViewSet("mono", monoSpec, error));
  const auto monoViews = makeViewSet(cam, monoSpec, vo);
  EXPECT_EQ(raster.render(oddViews[4].viewProj, oddViews[4].eye).rgb,
            raster.render(monoViews[0].viewProj, monoViews[0].eye).rgb);
  EXPECT_FALSE(parseViewSet("lf:0x3", spec, error));
  EXPECT_FALSE(parseViewSet("quad", spec, error));
  EXPECT_EQ(context.validationMessages(), 0u);
}

// A render scale draws the views smaller in the same targets: the images are those of a renderer
// made at that size (the same pixel grid and projection), and back at 1 the full size again.
TEST(RasterClient, ARenderScaleDrawsWhatASmallerRendererDraws) {
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("cornell", 0.0f);
  RasterRenderer big(context, s, 40, 30), small(context, s, 20, 15);
  const ProbeVolume v = onceUpdatedProbes(context, s, 4, 32);
  big.setProbes(v);
  small.setProbes(v);
  const glm::mat4 viewProj = big.viewProjection(CameraView::fromScene(s));
  const glm::vec3 eye = CameraView::fromScene(s).position;
  const Image full = big.render(viewProj, eye);
  big.setRenderScale(0.5f);
  EXPECT_EQ(big.renderScale(), 0.5f);
  const Image half = big.render(viewProj, eye);
  const Image reference = small.render(viewProj, eye);
  ASSERT_EQ(half.width, 20u);
  ASSERT_EQ(half.height, 15u);
  EXPECT_EQ(half.rgb, reference.rgb);
  big.setRenderScale(1.0f);
  EXPECT_EQ(big.render(viewProj, eye).rgb, full.rgb);
  big.setRenderScale(0.001f);  // at least a pixel a side
  const Image tiny = big.render(viewProj, eye);
  EXPECT_EQ(tiny.width, 1u);
  EXPECT_EQ(tiny.height, 1u);
  for (float bad : {0.0f, -1.0f, 1.5f, std::numeric_limits<float>::quiet_NaN()})
    EXPECT_THROW(big.setRenderScale(bad), std::invalid_argument) << bad;
  EXPECT_EQ(context.validationMessages(), 0u);
}

// N × N samples per pixel: each pixel of a W × H image is the mean of its N × N block of the same
// view drawn at one sample per pixel and N × the size (same aspect, so the same projection and the
// same sample positions). Differs from the one-sample W × H image at the box's edges.
TEST(RasterClient, SupersampledPixelsAreTheMeanOfTheirBlockAtNTimesTheSize) {
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("cornell", 0.0f);
  const ProbeVolume probes = onceUpdatedProbes(context, s, 3, 16);
  constexpr uint32_t kW = 20, kH = 16, kN = 3;
  RasterOptions one, three;
  one.samplesPerSide = 1;
  three.samplesPerSide = kN;
  RasterRenderer small(context, s, kW, kH, one), large(context, s, kW * kN, kH * kN, one),
      supersampled(context, s, kW, kH, three);
  const CameraView cam = CameraView::fromScene(s);
  const auto draw = [&](RasterRenderer& r) {
    r.setProbes(probes);
    return r.render(r.viewProjection(cam), cam.position);
  };
  const Image a = draw(small), big = draw(large), ss = draw(supersampled);
  ASSERT_EQ(ss.width, kW);
  ASSERT_EQ(ss.height, kH);
  ASSERT_EQ(ss.rgb.size(), a.rgb.size());
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x)
      for (uint32_t c = 0; c < 3; ++c) {
        float mean = 0.0f;
        for (uint32_t j = 0; j < kN; ++j)
          for (uint32_t i = 0; i < kN; ++i) mean += big.rgb[((y * kN + j) * kW * kN + x * kN + i) * 3 + c];
        mean /= static_cast<float>(kN * kN);
        ASSERT_NEAR(ss.rgb[(y * kW + x) * 3 + c], mean, 1e-5f * (1.0f + mean)) << x << "," << y << "," << c;
      }
  EXPECT_NE(ss.rgb, a.rgb);  // the edges are averaged now
  RasterOptions bad;
  bad.samplesPerSide = 0;
  EXPECT_THROW(RasterRenderer(context, s, kW, kH, bad), std::invalid_argument);
  bad.samplesPerSide = 17;
  EXPECT_THROW(RasterRenderer(context, s, kW, kH, bad), std::invalid_argument);
  bad.samplesPerSide = 4;
  EXPECT_THROW(RasterRenderer(context, s, 4097, kH, bad), std::invalid_argument);  // 16388 pixels a side
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(RasterClient, BadProbeVolumesAreRefusedAndTheLastGoodOneKept) {
  VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("cornell", 0.0f);
  RasterRenderer raster(context, s, 24, 16);
  const glm::vec3 lo = s.boundsMin, hi = s.boundsMax;
  ProbeVolume good = makeProbeVolume(ProbeGrid{{2, 2, 2}, {{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}}});
  for (int p = 0; p < 8; ++p) good.probes[p * 27] = 1.0f;
  raster.setProbes(good);
  const CameraView cam = CameraView::fromScene(s);
  const Image before = raster.render(raster.viewProjection(cam), cam.position);
  ProbeVolume nan = good;
  nan.probes[5 * 27 + 4] = std::nanf("");
  EXPECT_THROW(raster.setProbes(nan), std::invalid_argument);
  ProbeVolume inf = good;
  inf.probes[3] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(raster.setProbes(inf), std::invalid_argument);
  ProbeVolume flat = good;
  flat.grid.bounds.max[0] = flat.grid.bounds.min[0];
  EXPECT_THROW(raster.setProbes(flat), std::invalid_argument);
  ProbeVolume mask = good;
  mask.active.assign(7, 1);
  EXPECT_THROW(raster.setProbes(mask), std::invalid_argument);
  ProbeVolume small = good;
  small.probes.pop_back();
  EXPECT_THROW(raster.setProbes(small), std::invalid_argument);
  EXPECT_EQ(raster.render(raster.viewProjection(cam), cam.position).rgb, before.rgb);  // nothing lost
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(ViewSets, HorizontalLightFieldPutsEveryViewOnOneLineInQuiltOrder) {
  // lfh:4x2: 8 eyes on one horizontal line across the cone, view 0 leftmost, equally spaced,
  // tiles in quilt order (column k mod 4, row k div 4); the two middle eyes straddle the camera.
  ViewSetSpec spec;
  std::string error;
  ASSERT_TRUE(parseViewSet("lfh:4x2", spec, error));
  EXPECT_EQ(spec.kind, ViewSetSpec::Kind::HorizontalLightField);
  CameraView cam;
  cam.position = {0, 1, 4};
  cam.forward = {0, 0, -1};
  cam.up = {0, 1, 0};
  ViewSetOptions vo;
  vo.displayDistance = 4.0f;
  vo.lfConeDeg = 40.0f;
  const auto views = makeViewSet(cam, spec, vo);
  ASSERT_EQ(views.size(), 8u);
  const float span = 2.0f * 4.0f * std::tan(glm::radians(20.0f)), step = span / 7.0f;
  for (size_t k = 0; k < views.size(); ++k) {
    EXPECT_NEAR(views[k].eye.x, -0.5f * span + step * static_cast<float>(k), 1e-5f) << k;
    EXPECT_FLOAT_EQ(views[k].eye.y, 1.0f);  // no vertical parallax
    EXPECT_FLOAT_EQ(views[k].eye.z, 4.0f);
    EXPECT_EQ(views[k].column, static_cast<int>(k % 4));
    EXPECT_EQ(views[k].row, static_cast<int>(k / 4));
    // Every view sees the display centre (the scene point 4 m ahead) at the image centre.
    const glm::vec4 c = views[k].viewProj * glm::vec4(0, 1, 0, 1);
    EXPECT_NEAR(c.x / c.w, 0.0f, 1e-5f);
    EXPECT_NEAR(c.y / c.w, 0.0f, 1e-5f);
  }
  EXPECT_FALSE(parseViewSet("lfh:2x", spec, error));
  EXPECT_FALSE(parseViewSet("lfh:17x1", spec, error));
}

}  // namespace
}  // namespace probecast::renderer
