// The reference camera path tracer converges to analytic values.
#include <gtest/gtest.h>

#include <cmath>

#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/reference_camera.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

// A closed box x, y, z in [-1, 1] whose inner walls all emit L and reflect with base colour ρ.
scene::Scene emissiveBox(float rho, float roughness, float L) {
  scene::Scene s;
  scene::Material m;
  m.baseColor = glm::vec3(rho);
  m.roughness = roughness;
  m.emission = glm::vec3(L);
  s.materials.push_back(m);
  const float a = -1, b = 1;
  scene::addQuad(s, {a, a, b}, {b, a, b}, {b, a, a}, {a, a, a}, 0);
  scene::addQuad(s, {a, b, a}, {b, b, a}, {b, b, b}, {a, b, b}, 0);
  scene::addQuad(s, {a, a, a}, {b, a, a}, {b, b, a}, {a, b, a}, 0);
  scene::addQuad(s, {b, a, b}, {a, a, b}, {a, b, b}, {b, b, b}, 0);
  scene::addQuad(s, {a, a, b}, {a, a, a}, {a, b, a}, {a, b, b}, 0);
  scene::addQuad(s, {b, a, a}, {b, a, b}, {b, b, b}, {b, b, a}, 0);
  scene::finalizeScene(s);
  return s;
}

// Directional albedo A(n) = ∫ f(n, wo = n, wi) cos θ dω of the glTF dielectric BRDF (Lambert +
// GGX, Smith-Schlick G, Schlick F, F0 = 0.04), by midpoint quadrature in (θ, φ).
double albedoAtNormalIncidence(double rho, double roughness) {
  const double a = roughness * roughness, a2 = a * a, k = a / 2;
  double sum = 0;
  const int nt = 4000;
  for (int i = 0; i < nt; ++i) {
    const double theta = (i + 0.5) / nt * M_PI / 2;
    const double nl = std::cos(theta);
    // wo = n, so h bisects n and wi: n·h = cos(θ/2), v·h = cos(θ/2); the integrand is φ-independent.
    const double nh = std::cos(theta / 2), vh = nh;
    const double d = a2 / (M_PI * std::pow(nh * nh * (a2 - 1) + 1, 2));
    const double g = nl / (nl * (1 - k) + k) * (1.0 / (1.0 * (1 - k) + k));
    const double f = 0.04 + 0.96 * std::pow(1 - vh, 5);
    const double brdf = rho / M_PI + d * g * f / (4 * nl * 1.0);
    sum += brdf * nl * std::sin(theta) * (M_PI / 2 / nt) * 2 * M_PI;
  }
  return sum;
}

TEST(ReferenceCamera, EmissiveBoxConvergesToOneBounceAnswer) {
  // Two interactions: the wall's emission L plus one reflection of the (equally emissive) walls:
  // radiance = L (1 + A(n)) looking straight at a wall.
  ContextOptions co;
  co.validation = true;
  VulkanContext context(co);
  const float rho = 0.5f, roughness = 0.6f, L = 1.0f;
  const scene::Scene s = emissiveBox(rho, roughness, L);
  CameraView cam;
  cam.position = {0, 0, 0};
  cam.forward = {0, 0, -1};
  cam.yfov = 0.05f;  // nearly normal incidence everywhere
  ReferenceOptions o;
  o.width = 8;
  o.height = 8;
  o.samplesPerPixel = 4096;
  o.maxBounces = 2;
  const Image image = renderReference(context, s, cam, o);
  double mean = 0;
  for (size_t i = 0; i < image.rgb.size(); i += 3) mean += image.rgb[i];
  mean /= static_cast<double>(image.rgb.size() / 3);
  const double expected = L * (1.0 + albedoAtNormalIncidence(rho, roughness));
  EXPECT_NEAR(mean, expected, 0.01 * expected) << "A(n) = " << albedoAtNormalIncidence(rho, roughness);
  EXPECT_EQ(context.validationMessages(), 0u);
}

// A square of half-size `half` at y = 0 in material `m`, under a 3 lx sun travelling along `sunPath`.
scene::Scene planeUnderSun(const scene::Material& m, float half, const glm::vec3& sunPath) {
  scene::Scene s;
  s.materials.push_back(m);
  scene::addQuad(s, {-half, 0, half}, {half, 0, half}, {half, 0, -half}, {-half, 0, -half}, 0);
  scene::Light sun;
  sun.type = scene::LightType::Directional;
  sun.direction = glm::normalize(sunPath);
  sun.intensity = 3.0f;
  s.lights.push_back(sun);
  scene::finalizeScene(s);
  return s;
}

TEST(ReferenceCamera, RetroreflectionNeverMakesNonFiniteSamples) {
  // The camera looks straight down the sun's path onto a plane, so wo ≈ wi at every pixel: v·h
  // rounds past 1 for many samples, and the Fresnel term's pow(1 − v·h, 5) was undefined there
  // (NaN on llvmpipe) — the cause of the NaN pixels in Sponza renders. No sample may be dropped.
  VulkanContext context(test::validatedContext());
  scene::Material m;
  m.baseColor = glm::vec3(0.8f);
  m.roughness = 0.9f;
  const glm::vec3 sunPath = glm::normalize(glm::vec3(0.3f, -1.0f, 0.15f));  // Sponza's sun: no component rounds away
  const scene::Scene s = planeUnderSun(m, 1.0f, sunPath);
  CameraView cam;
  cam.forward = sunPath;
  cam.position = -cam.forward;  // one metre up the sun's path from the plane's centre
  cam.up = {0, 1, 0};
  cam.yfov = 1e-5f;
  ReferenceOptions o;
  o.width = 8;
  o.height = 8;
  o.samplesPerPixel = 16;
  o.maxBounces = 1;
  ReferenceStats stats;
  const Image img = renderReference(context, s, cam, o, &stats);
  EXPECT_EQ(stats.samples, 8u * 8u * 16u);
  EXPECT_EQ(stats.droppedSamples, 0u);
  for (float v : img.rgb) ASSERT_TRUE(std::isfinite(v));
  // Lambert + GGX: at least the Lambert part 3 lx × cos θ × 0.8/π — the pixels are lit.
  EXPECT_GT(img.rgb[0], 3.0f * 0.9f * 0.8f / 3.14159f);
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(ReferenceCamera, NonFiniteSamplesAreDroppedAndCountedInBothTracers) {
  // A NaN base colour (a scene built in code; the glTF loader refuses such files) poisons every
  // lit sample: the tracers must drop them, count them, and write only finite numbers.
  VulkanContext context(test::validatedContext());
  scene::Material m;
  m.baseColor = glm::vec3(std::nanf(""));
  const scene::Scene s = planeUnderSun(m, 10.0f, {0, -1, 0});
  CameraView cam;
  cam.position = {0, 1, 0};
  cam.forward = {0, -1, 0};
  cam.up = {0, 0, -1};
  cam.yfov = 0.5f;
  ReferenceOptions o;
  o.width = 4;
  o.height = 4;
  o.samplesPerPixel = 4;
  ReferenceStats stats;
  const Image img = renderReference(context, s, cam, o, &stats);
  EXPECT_EQ(stats.droppedSamples, stats.samples);
  for (float v : img.rgb) EXPECT_EQ(v, 0.0f);
  UpdaterOptions uo;
  uo.samplesPerProbe = 64;
  uo.classify = false;
  ProbeUpdater u(context, s, ProbeGrid{{1, 1, 1}, {{0, 1, 0}, {0, 1, 0}}}, uo);
  const UpdateStats st = u.update();
  EXPECT_GT(st.droppedSamples, 20u);  // the plane fills 45 % of the probe's sphere: ~29 of 64
  EXPECT_LT(st.droppedSamples, 40u);
  for (float v : u.volume().probes) EXPECT_TRUE(std::isfinite(v));
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(ReferenceCamera, SameSeedSameImage) {
  VulkanContext context;
  scene::Scene s;
  std::string error;
  ASSERT_TRUE(scene::makeBuiltinScene("cornell", 0.0f, s, error));
  ReferenceOptions o;
  o.width = 16;
  o.height = 12;
  o.samplesPerPixel = 8;
  const Image a = renderReference(context, s, CameraView::fromScene(s), o);
  const Image b = renderReference(context, s, CameraView::fromScene(s), o);
  EXPECT_EQ(a.rgb, b.rgb);
  double sum = 0;
  for (float v : a.rgb) sum += v;
  EXPECT_GT(sum, 0.0);
}

}  // namespace
}  // namespace probecast::renderer
