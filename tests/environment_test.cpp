// Environment light: the map convention (known answers with one bright texel), loading checks,
// the sampling distribution, furnace tests of both tracers, importance sampling against BSDF-only
// sampling, and the raster background.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "brdf_quadrature.h"
#include "probecast/codec/equirect.h"
#include "probecast/codec/sh.h"
#include "probecast/imaging/image_io.h"
#include "probecast/renderer/environment.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/reference_camera.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

constexpr int kW = 64, kH = 32;

// A black kW × kH map with texel (x, y) at radiance `value` (grey).
std::shared_ptr<Environment> oneTexelMap(int x, int y, float value, float rotation = 0.0f) {
  auto env = std::make_shared<Environment>();
  env->name = "one-texel";
  env->width = kW;
  env->height = kH;
  env->rgb.assign(static_cast<size_t>(kW) * kH * 3, 0.0f);
  for (int c = 0; c < 3; ++c) env->rgb[(static_cast<size_t>(y) * kW + x) * 3 + c] = value;
  env->rotation = rotation;
  return env;
}

glm::vec3 texelCentre(int x, int y) {
  float d[3];
  equirectDirection(kW, kH, x, y, d);
  return {d[0], d[1], d[2]};
}

// Open space: one black 1 mm triangle 1 km away (the tracers need a triangle; nothing sees it).
scene::Scene openSpace() {
  scene::Scene s;
  scene::Material black;
  black.baseColor = glm::vec3(0.0f);
  s.materials.push_back(black);
  s.positions = {{0, -1000, 0}, {0.001f, -1000, 0}, {0, -1000, 0.001f}};
  s.normals = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
  s.texcoords.assign(3, glm::vec2(0.0f));
  s.indices = {0, 1, 2};
  s.triangleMaterial = {0};
  scene::finalizeScene(s);
  return s;
}

// A white (base colour 1) dielectric square at y = 0, half-size `half`.
scene::Scene whitePlane(float half, float roughness) {
  scene::Scene s;
  scene::Material white;
  white.baseColor = glm::vec3(1.0f);
  white.roughness = roughness;
  s.materials.push_back(white);
  scene::addQuad(s, {-half, 0, half}, {half, 0, half}, {half, 0, -half}, {-half, 0, -half}, 0);
  scene::finalizeScene(s);
  return s;
}

std::shared_ptr<Environment> uniformSky(const glm::vec3& radiance) {
  auto sky = std::make_shared<Environment>();
  std::string error;
  if (!makeUniformSky(radiance, *sky, error)) throw std::invalid_argument(error);
  return sky;
}

CameraView lookAlong(const glm::vec3& dir, float yfov, const glm::vec3& from = glm::vec3(0.0f)) {
  CameraView c;
  c.position = from;
  c.forward = glm::normalize(dir);
  c.up = std::fabs(c.forward.y) > 0.9f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  c.yfov = yfov;
  return c;
}

double meanRed(const Image& img) {
  double sum = 0;
  for (size_t i = 0; i < img.rgb.size(); i += 3) sum += img.rgb[i];
  return sum / static_cast<double>(img.rgb.size() / 3);
}

TEST(Environment, ConventionTopRowUpCentreMinusZRightPlusX) {
  // environment.h: top row +Y, image centre −Z, u = 0.75 +X, u = 0.25 −X, the edges +Z.
  const struct {
    glm::vec3 dir;
    int x, y;
  } cases[] = {{{0, 1, 0}, -1, 0}, {{0, -1, 0}, -1, kH - 1}, {{0, 0, -1}, kW / 2, kH / 2},
               {{1, 0, 0}, 3 * kW / 4, kH / 2}, {{-1, 0, 0}, kW / 4, kH / 2}, {{0, 0, 1}, -1, kH / 2}};
  for (const auto& c : cases) {
    const float d[3] = {c.dir.x, c.dir.y, c.dir.z};
    int x = -1, y = -1;
    equirectPixel(kW, kH, d, x, y);
    EXPECT_EQ(y, c.y) << c.dir.x << "," << c.dir.y << "," << c.dir.z;
    if (c.x >= 0) {
      EXPECT_EQ(x, c.x) << c.dir.x << "," << c.dir.y << "," << c.dir.z;
    }
  }
  const float plusZ[3] = {0.0f, 0.0f, 1.0f}, nearLeft[3] = {-0.01f, 0.0f, 1.0f}, nearRight[3] = {0.01f, 0.0f, 1.0f};
  int ex = -1, ey = -1;
  equirectPixel(kW, kH, plusZ, ex, ey);
  EXPECT_TRUE(ex == 0 || ex == kW - 1);  // +Z is the seam between the left and right edges
  equirectPixel(kW, kH, nearRight, ex, ey);
  EXPECT_EQ(ex, kW - 1);  // a little toward +X from +Z: the last column
  equirectPixel(kW, kH, nearLeft, ex, ey);
  EXPECT_EQ(ex, 0);
  // equirectPixel inverts equirectDirection at every texel centre.
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      float d[3];
      equirectDirection(kW, kH, x, y, d);
      int px = -1, py = -1;
      equirectPixel(kW, kH, d, px, py);
      ASSERT_EQ(px, x);
      ASSERT_EQ(py, y);
    }
  const float nan[3] = {std::nanf(""), 0.0f, 1.0f};
  int px = -1, py = -1;
  equirectPixel(kW, kH, nan, px, py);  // not a direction: a valid pixel all the same
  EXPECT_TRUE(px >= 0 && px < kW && py >= 0 && py < kH);
}

TEST(Environment, RotationTurnsTheMapCounterClockwiseSeenFromAbove) {
  // The texel at the map's centre faces −Z; rotated by +90° about +Y it faces −X.
  const auto env = oneTexelMap(kW / 2, kH / 2, 5.0f, glm::radians(90.0f));
  const glm::vec3 centre = texelCentre(kW / 2, kH / 2);
  const glm::vec3 turned = environmentToWorld(*env, centre);
  EXPECT_NEAR(turned.x, -1.0f, 0.01f);
  EXPECT_NEAR(turned.z, 0.0f, 0.06f);  // the texel's centre lies half a texel (2.8°) past −Z
  EXPECT_FLOAT_EQ(environmentRadiance(*env, turned).r, 5.0f);
  EXPECT_FLOAT_EQ(environmentRadiance(*env, centre).r, 0.0f);
  const glm::vec3 back = environmentToMap(*env, turned);
  EXPECT_NEAR(glm::length(back - centre), 0.0f, 1e-5f);
}

TEST(Environment, LoadChecksItsInput) {
  Environment env;
  std::string error;
  const std::string kiara = std::string(PROBECAST_TEST_DATA) + "/envmaps/kiara_1_dawn_1k.hdr";
  ASSERT_TRUE(loadEnvironment(kiara, 2.0f, 45.0f, env, error)) << error;
  EXPECT_EQ(env.width, 1024);
  EXPECT_EQ(env.height, 512);
  EXPECT_NEAR(env.rotation, glm::radians(45.0f), 1e-6f);
  Environment plain;
  ASSERT_TRUE(loadEnvironment(kiara, 1.0f, 0.0f, plain, error));
  EXPECT_FLOAT_EQ(env.rgb[1000], 2.0f * plain.rgb[1000]);  // the intensity scales radiance

  EXPECT_FALSE(loadEnvironment("/nonexistent/sky.hdr", 1.0f, 0.0f, env, error));
  EXPECT_NE(error.find("sky.hdr: no such file"), std::string::npos) << error;
  EXPECT_FALSE(loadEnvironment(kiara, -1.0f, 0.0f, env, error));
  EXPECT_NE(error.find("intensity"), std::string::npos) << error;
  EXPECT_FALSE(loadEnvironment(kiara, std::nanf(""), 0.0f, env, error));
  EXPECT_FALSE(loadEnvironment(kiara, std::numeric_limits<float>::infinity(), 0.0f, env, error));
  EXPECT_FALSE(loadEnvironment(kiara, 1.0f, std::nanf(""), env, error));
  EXPECT_FALSE(loadEnvironment(std::string(PROBECAST_TEST_DATA) + "/CREDITS.md", 1.0f, 0.0f, env, error));
  EXPECT_NE(error.find("expected .hdr or .exr"), std::string::npos) << error;

  // An EXR with a NaN and an infinity is refused, naming the first bad pixel.
  const std::string bad = std::string(PROBECAST_TEST_TMP) + "/nan_env.exr";
  std::vector<float> rgb(8 * 4 * 3, 1.0f);
  rgb[(2 * 8 + 5) * 3 + 1] = std::nanf("");
  rgb[(3 * 8 + 1) * 3] = std::numeric_limits<float>::infinity();
  ASSERT_TRUE(imaging::writeExr(bad, rgb, 8, 4, error)) << error;
  EXPECT_FALSE(loadEnvironment(bad, 1.0f, 0.0f, env, error));
  EXPECT_NE(error.find("2 pixel values are not finite"), std::string::npos) << error;
  EXPECT_NE(error.find("x 5, y 2"), std::string::npos) << error;

  EXPECT_FALSE(makeUniformSky({1.0f, -0.5f, 1.0f}, env, error));
  EXPECT_FALSE(makeUniformSky({1.0f, std::nanf(""), 1.0f}, env, error));
  ASSERT_TRUE(makeUniformSky({0.5f, 0.25f, 1.0f}, env, error));
  EXPECT_FLOAT_EQ(environmentRadiance(env, glm::normalize(glm::vec3(0.3f, -0.8f, 0.1f))).g, 0.25f);
}

TEST(Environment, DistributionPicksTexelsByLuminanceTimesSolidAngle) {
  // Two lit texels of equal radiance, one on the equator, one near the pole: probabilities in
  // the ratio of their solid angles (the sin θ factor), pdf = luminance / total everywhere.
  auto env = oneTexelMap(10, kH / 2, 1.0f);
  for (int c = 0; c < 3; ++c) env->rgb[(static_cast<size_t>(1) * kW + 40) * 3 + c] = 1.0f;
  const EnvironmentDistribution d = buildEnvironmentDistribution(*env);
  ASSERT_EQ(d.rows.size(), static_cast<size_t>(kH));
  ASSERT_EQ(d.columns.size(), static_cast<size_t>(kW * kH));
  EXPECT_FLOAT_EQ(d.rows.back(), 1.0f);
  const double polar = equirectPixelSolidAngle(kW, kH, 1), equator = equirectPixelSolidAngle(kW, kH, kH / 2);
  EXPECT_NEAR(d.total, polar + equator, 1e-6);
  const double pPolar = d.rows[1] - d.rows[0];
  EXPECT_NEAR(pPolar, polar / (polar + equator), 1e-6);
  EXPECT_NEAR(d.rows[kH / 2] - d.rows[kH / 2 - 1], equator / (polar + equator), 1e-6);
  EXPECT_FLOAT_EQ(d.columns[1 * kW + 39], 0.0f);
  EXPECT_FLOAT_EQ(d.columns[1 * kW + 40], 1.0f);
  for (int y = 0; y < kH; ++y) EXPECT_FLOAT_EQ(d.columns[static_cast<size_t>(y) * kW + kW - 1], 1.0f);
}

TEST(Environment, ReferenceCameraSeesTheTexelWhereTheConventionPutsIt) {
  // One bright texel near +X (u = 0.75, just above the horizon): a narrow camera aimed at its
  // centre sees exactly its radiance, one aimed the other way sees black; rotated by +90° the
  // texel moves to R_y(90°)·d ≈ −Z.
  VulkanContext context(test::validatedContext());
  const scene::Scene s = openSpace();
  const int tx = 3 * kW / 4, ty = kH / 2 - 1;
  const glm::vec3 d = texelCentre(tx, ty);
  ReferenceOptions o;
  o.width = 4;
  o.height = 4;
  o.samplesPerPixel = 2;
  o.environment = oneTexelMap(tx, ty, 7.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(meanRed(renderReference(context, s, lookAlong(d, 0.01f), o))), 7.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(meanRed(renderReference(context, s, lookAlong(-d, 0.01f), o))), 0.0f);
  o.environment = oneTexelMap(tx, ty, 7.0f, glm::radians(90.0f));
  const glm::vec3 turned(d.z, d.y, -d.x);  // R_y(90°)
  EXPECT_LT(turned.z, -0.99f);
  EXPECT_FLOAT_EQ(static_cast<float>(meanRed(renderReference(context, s, lookAlong(turned, 0.01f), o))), 7.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(meanRed(renderReference(context, s, lookAlong(d, 0.01f), o))), 0.0f);
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(Environment, ProbeL1PointsAtTheBrightTexel) {
  // A probe in open space under one bright texel: c = L Ω Y(d), so its L1 direction is the
  // texel's direction (up to where the probe's rays cross the texel).
  VulkanContext context(test::validatedContext());
  const scene::Scene s = openSpace();
  const int tx = 3 * kW / 4, ty = kH / 4;
  UpdaterOptions o;
  o.samplesPerProbe = 32768;
  o.classify = false;
  o.minBlendWeight = 0.0f;
  o.environment = oneTexelMap(tx, ty, 100.0f);
  ProbeUpdater u(context, s, ProbeGrid{{1, 1, 1}, {{0, 0, 0}, {0, 0, 0}}}, o);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(u.update().droppedSamples, 0u);
  const float* c = u.volume().probes.data();
  const glm::vec3 l1 = glm::normalize(glm::vec3(c[9], c[3], c[6]));  // (c3, c1, c2) = (x, y, z)
  const glm::vec3 d = texelCentre(tx, ty);
  EXPECT_GT(glm::dot(l1, d), 0.99f) << l1.x << "," << l1.y << "," << l1.z;
  // c00 = Y00 L Ω of the texel, within the noise of ~S Ω / 4π = 18 rays per update through it.
  const double expected = 0.282094792 * 100.0 * equirectPixelSolidAngle(kW, kH, ty);
  EXPECT_NEAR(c[0], expected, 0.1 * expected);
  EXPECT_EQ(context.validationMessages(), 0u);
}

// Furnace: a white plane under a uniform sky L reflects L A(θo), A the directional albedo of the
// material (1 for its Lambert part plus the F0 = 0.04 GGX layer's share, which the model adds
// without energy compensation).
// With one interaction per path (--bounces 1) the plane still gets the sky: environment
// next-event estimation runs at the last interaction too, with map sampling on and off.
TEST(Environment, FurnaceReferenceCameraReturnsSkyTimesAlbedo) {
  VulkanContext context(test::validatedContext());
  const float roughness = 0.7f;
  const scene::Scene s = whitePlane(10.0f, roughness);
  const double expected = 0.5 * test::directionalAlbedo(1.0, roughness, 1.0);
  for (uint32_t bounces : {1u, 2u})
    for (bool sampling : {true, false}) {
      if (!sampling && bounces != 1u) continue;
      ReferenceOptions o;
      o.width = 8;
      o.height = 8;
      o.samplesPerPixel = bounces == 1u && sampling ? 4096 : 2048;  // half the sphere's samples miss the plane
      o.maxBounces = bounces;
      o.environment = uniformSky(glm::vec3(0.5f));
      o.environmentSampling = sampling;
      ReferenceStats stats;
      const Image img = renderReference(context, s, lookAlong({0, -1, 0}, 0.02f, {0, 1, 0}), o, &stats);
      EXPECT_NEAR(meanRed(img), expected, 0.005 * expected) << "A = " << expected / 0.5 << ", bounces " << bounces
                                                            << ", sampling " << sampling;
      std::printf("reference furnace (%u bounces, sampling %d): %.5f, expected %.5f (A = %.5f)\n", bounces, sampling,
                  meanRed(img), expected, expected / 0.5);
      EXPECT_EQ(stats.droppedSamples, 0u);
    }
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(Environment, FurnaceProbeAbovePlaneSeesSkyAndAlbedo) {
  // Upper hemisphere: the sky L. Lower: the plane (1 km wide, 1 m below: all but 0.0006 sr),
  // L A(μ) at μ = cos θo. c00 = Y00 (2π L + 2π L ∫₀¹ A(μ) dμ); with A = 1 this is L √(4π).
  // The same with one interaction per path (--bounces 1): the plane is lit by the sky all the same.
  VulkanContext context(test::validatedContext());
  const float roughness = 0.7f;
  const scene::Scene s = whitePlane(1000.0f, roughness);
  for (uint32_t bounces : {1u, 2u}) {
  UpdaterOptions o;
  o.samplesPerProbe = 32768;
  o.maxBounces = bounces;
  o.indirectClamp = 0.0f;
  o.classify = false;
  o.minBlendWeight = 0.0f;  // a plain mean over the updates
  o.rejectSigmas = 0.0f;
  o.environment = uniformSky(glm::vec3(2.0f));
  ProbeUpdater u(context, s, ProbeGrid{{1, 1, 1}, {{0, 1, 0}, {0, 1, 0}}}, o);
  for (int k = 0; k < 8; ++k) EXPECT_EQ(u.update().droppedSamples, 0u);
  double meanAlbedo = 0;
  const int nm = 32;
  for (int i = 0; i < nm; ++i) meanAlbedo += test::directionalAlbedo(1.0, roughness, (i + 0.5) / nm, 96) / nm;
  const double expected = 0.282094792 * 2.0 * (2 * M_PI + 2 * M_PI * meanAlbedo);
  const float* c = u.volume().probes.data();
  EXPECT_NEAR(c[0], expected, 0.005 * expected) << "mean A = " << meanAlbedo;
  std::printf("probe furnace: c00 %.5f, expected %.5f (mean A = %.5f)\n", c[0], expected, meanAlbedo);
  EXPECT_NEAR(c[0] / (2.0 * std::sqrt(4 * M_PI)), 0.5 * (1 + meanAlbedo), 0.005) << "bounces " << bounces;
  }
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(Environment, ImportanceAndBsdfSamplingAgreeUnderASunMap) {
  // A dim sky with a bright 'sun' of 3 × 2 texels: environment sampling with MIS and BSDF-only
  // sampling estimate the same radiance off a white plane, and the plane's radiance matches a
  // quadrature of f · cos · L over the map's texels.
  VulkanContext context(test::validatedContext());
  const float roughness = 0.8f;
  const scene::Scene s = whitePlane(10.0f, roughness);
  auto env = std::make_shared<Environment>();
  env->width = kW;
  env->height = kH;
  env->rgb.assign(static_cast<size_t>(kW) * kH * 3, 0.2f);
  for (int y = 6; y < 8; ++y)
    for (int x = 40; x < 43; ++x)
      for (int c = 0; c < 3; ++c) env->rgb[(static_cast<size_t>(y) * kW + x) * 3 + c] = 50.0f;
  env->rotation = glm::radians(30.0f);
  double expected = 0;  // ∫ f(n, n, ω) cos L(ω) dω over the upper hemisphere, 8 × 8 points per texel
  const glm::dvec3 n(0, 1, 0);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          const double theta = M_PI * (y + (j + 0.5) / 8) / kH, phi = 2 * M_PI * ((x + (i + 0.5) / 8) / kW - 0.5);
          const glm::vec3 world = environmentToWorld(
              *env, glm::vec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)));
          const glm::dvec3 w(world);
          const double dOmega = std::sin(theta) * (M_PI / kH / 8) * (2 * M_PI / kW / 8);
          expected += test::dielectricBrdf(1.0, roughness, n, n, w) * std::max(0.0, w.y) *
                      env->rgb[(static_cast<size_t>(y) * kW + x) * 3] * dOmega;
        }
  ReferenceOptions o;
  o.width = 4;
  o.height = 4;
  o.samplesPerPixel = 2048;
  o.maxBounces = 2;
  o.environment = env;
  const CameraView cam = lookAlong({0, -1, 0}, 0.01f, {0, 1, 0});
  const double sampled = meanRed(renderReference(context, s, cam, o));
  o.environmentSampling = false;
  o.samplesPerPixel = 32768;  // ~1 % of BSDF samples reach the sun
  const double bsdfOnly = meanRed(renderReference(context, s, cam, o));
  std::printf("sun map: sampled %.5f, BSDF only %.5f, quadrature %.5f\n", sampled, bsdfOnly, expected);
  EXPECT_NEAR(sampled, expected, 0.01 * expected);
  EXPECT_NEAR(bsdfOnly, expected, 0.03 * expected);
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(Environment, RasterDrawsTheEnvironmentBehindTheScene) {
  // Pixels no surface covers show the map's radiance along their ray (linear, as the surfaces);
  // covered pixels do not.
  VulkanContext context(test::validatedContext());
  const scene::Scene s = whitePlane(1.0f, 1.0f);
  RasterOptions ro;
  ro.environment = uniformSky({0.25f, 0.5f, 1.0f});
  RasterRenderer raster(context, s, 16, 16, ro);
  const CameraView up = lookAlong({0, 1, 0}, 1.0f, {0, 0.5f, 0});
  const Image sky1 = raster.render(raster.viewProjection(up), up.position);
  for (size_t i = 0; i < sky1.rgb.size(); i += 3) {
    ASSERT_FLOAT_EQ(sky1.rgb[i], 0.25f);
    ASSERT_FLOAT_EQ(sky1.rgb[i + 2], 1.0f);
  }
  const CameraView down = lookAlong({0, -1, 0}, 0.5f, {0, 0.5f, 0});
  const Image plane = raster.render(raster.viewProjection(down), down.position);
  EXPECT_NE(plane.rgb[(8 * 16 + 8) * 3 + 2], 1.0f);  // the plane, lit by no probes: black

  // A map: the pixel at the image centre of a camera looking at +X shows the +X texel.
  const int tx = 3 * kW / 4, ty = kH / 2 - 1;  // just above the horizon: past the plane's edge
  RasterOptions mo;
  mo.environment = oneTexelMap(tx, ty, 3.0f);
  RasterRenderer mapped(context, s, 15, 15, mo);
  const CameraView east = lookAlong(texelCentre(tx, ty), 0.02f, {0, 0.5f, 0});
  const Image img = mapped.render(mapped.viewProjection(east), east.position);
  EXPECT_FLOAT_EQ(img.rgb[(7 * 15 + 7) * 3], 3.0f);
  EXPECT_EQ(context.validationMessages(), 0u);
}

}  // namespace
}  // namespace probecast::renderer
