// Client area lights: the polygon irradiance against closed forms, the rule that picks them, the
// emitter furnace (probes with client area lights plus the client's direct term equal the probes
// without, and the raster image matches the reference tracer), and soft shadows from the emitter.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "area_light_math.h"
#include "probecast/codec/sh.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/reference_camera.h"
#include "probecast/scene/area_lights.h"
#include "vulkan_test_support.h"

namespace probecast::renderer {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// Form factor from a differential area to a parallel a × b rectangle whose corner lies on its
// normal at distance c (Howell's catalogue, configuration B-3).
double parallelRectangleCorner(double a, double b, double c) {
  const double x = a / c, y = b / c;
  const double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
  return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2 * kPiD);
}

// ∫ cos dω of a quad (two triangles a b c, a c d), from area_light_math.h.
double quadCosineSolidAngle(glm::vec3 p, glm::vec3 n, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
  return static_cast<double>(arealight::triangleCosineSolidAngle(p, n, a, b, c)) +
         static_cast<double>(arealight::triangleCosineSolidAngle(p, n, a, c, d));
}

TEST(AreaLightMath, UnitSquareAbovePointMatchesTheClosedForm) {
  // A unit square 1 m above the point, facing it: centred (four 0.5 × 0.5 corners) and off-centre.
  const glm::vec3 p(0.0f), n(0, 1, 0);
  const double centred = 4 * parallelRectangleCorner(0.5, 0.5, 1.0);
  // Corners counter-clockwise seen from below (the emitting side).
  const double got = quadCosineSolidAngle(p, n, {-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {-0.5f, 1, 0.5f});
  EXPECT_NEAR(got / kPiD, centred, 1e-3 * centred);
  const double corner = parallelRectangleCorner(1.0, 1.0, 1.0);  // the point under one corner
  const double got2 = quadCosineSolidAngle(p, n, {0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1});
  EXPECT_NEAR(got2 / kPiD, corner, 1e-3 * corner);
  // Seen from behind the emitter: nothing.
  EXPECT_EQ(quadCosineSolidAngle({0, 2, 0}, {0, -1, 0}, {0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}), 0.0);
}

TEST(AreaLightMath, SquareAcrossTheHorizonMatchesQuadrature) {
  // A vertical unit square 1 m away, half below the receiver's horizon: only the upper half lights
  // it. Midpoint quadrature of cos θ_r cos θ_e / r² over the square's area.
  const glm::dvec3 p(0.0), n(0, 0, 1);
  const int steps = 1000;
  double sum = 0;
  for (int i = 0; i < steps; ++i)
    for (int j = 0; j < steps; ++j) {
      const glm::dvec3 q(1.0, -0.5 + (i + 0.5) / steps, -0.5 + (j + 0.5) / steps);
      const glm::dvec3 d = q - p;
      const double r2 = glm::dot(d, d), r = std::sqrt(r2);
      const double cr = glm::dot(d, n) / r, ce = d.x / r;  // the square faces −x, toward p
      if (cr > 0) sum += cr * ce / r2;
    }
  const double expected = sum / (steps * steps);
  // Corners counter-clockwise seen from −x.
  const double got = quadCosineSolidAngle(glm::vec3(p), glm::vec3(n), {1, -0.5f, -0.5f}, {1, -0.5f, 0.5f},
                                          {1, 0.5f, 0.5f}, {1, 0.5f, -0.5f});
  EXPECT_NEAR(got, expected, 1e-3 * expected);
  // And its solid angle, against the same quadrature.
  double omega = 0;
  for (int i = 0; i < steps; ++i)
    for (int j = 0; j < steps; ++j) {
      const glm::dvec3 d(1.0, -0.5 + (i + 0.5) / steps, -0.5 + (j + 0.5) / steps);
      omega += d.x / std::pow(glm::dot(d, d), 1.5);
    }
  omega /= steps * steps;
  const double gotOmega =
      static_cast<double>(arealight::triangleSolidAngle(glm::vec3(p), {1, -0.5f, -0.5f}, {1, 0.5f, -0.5f}, {1, 0.5f, 0.5f}) +
                          arealight::triangleSolidAngle(glm::vec3(p), {1, -0.5f, -0.5f}, {1, 0.5f, 0.5f}, {1, -0.5f, 0.5f}));
  EXPECT_NEAR(gotOmega, omega, 1e-3 * omega);
}

TEST(AreaLights, CornellPanelIsTheOneClientLightAndTheRuleHasItsOptions) {
  scene::Scene s;
  std::string error;
  ASSERT_TRUE(scene::loadScene(std::string(PROBECAST_TEST_DATA) + "/scenes/cornell-box/CornellBox-Original.gltf", 0,
                               s, error))
      << error;
  scene::AreaLightOptions o;
  EXPECT_TRUE(scene::extractAreaLights(s, o).lights.empty());  // off by default
  o.enabled = true;
  const scene::AreaLightSet set = scene::extractAreaLights(s, o);
  ASSERT_EQ(set.lights.size(), 1u);
  const scene::AreaLight& l = set.lights[0];
  EXPECT_EQ(l.corners.size(), 6u);  // the panel's two triangles, one connected piece
  EXPECT_NEAR(l.normal.y, -1.0f, 1e-4f);  // emitting down into the room
  EXPECT_NEAR(l.area, 0.47f * 0.38f, 1e-3f);
  EXPECT_NEAR(l.power, set.totalEmittedPower, 1e-3f * l.power);
  int lit = 0;
  for (uint8_t f : set.clientLitMaterial) lit += f;
  EXPECT_EQ(lit, 1);
  EXPECT_EQ(set.clientLitMaterial[l.material], 1);
  // A cap of one triangle leaves the panel to the probes; so does textured emission.
  o.maxTriangles = 1;
  EXPECT_TRUE(scene::extractAreaLights(s, o).lights.empty());
  o.maxTriangles = 64;
  o.minPowerFraction = std::nanf("");
  EXPECT_THROW(scene::extractAreaLights(s, o), std::invalid_argument);
  o.minPowerFraction = 0.05f;
  s.materials[l.material].emissiveTexture = 0;
  s.textures.push_back({1, 1, {255, 255, 255, 255}});
  EXPECT_TRUE(scene::extractAreaLights(s, o).lights.empty());
}

// A closed box [-1, 1]³ seen from inside: diffuse walls of albedo `rho`, the ceiling (y = +1)
// emitting `L` and black.
scene::Scene emitterBox(float rho, glm::vec3 L) {
  scene::Scene s;
  s.name = "emitter-box";
  scene::Material wall;
  wall.baseColor = glm::vec3(rho);
  scene::Material light;
  light.baseColor = glm::vec3(0.0f);
  light.emission = L;
  s.materials = {wall, light};
  const float a = -1, b = 1;
  scene::addQuad(s, {a, a, a}, {b, a, a}, {b, b, a}, {a, b, a}, 0);  // z = −1, normal +Z
  scene::addQuad(s, {b, a, b}, {a, a, b}, {a, b, b}, {b, b, b}, 0);  // z = +1, normal −Z
  scene::addQuad(s, {a, a, b}, {b, a, b}, {b, a, a}, {a, a, a}, 0);  // y = −1, normal +Y
  scene::addQuad(s, {a, b, a}, {b, b, a}, {b, b, b}, {a, b, b}, 1);  // y = +1, normal −Y: the light
  scene::addQuad(s, {a, a, b}, {a, a, a}, {a, b, a}, {a, b, b}, 0);  // x = −1, normal +X
  scene::addQuad(s, {b, a, a}, {b, a, b}, {b, b, b}, {b, b, a}, 0);  // x = +1, normal −X
  scene::finalizeScene(s);
  return s;
}

// The band 0 and 1 SH coefficients (no Condon-Shortley phase, as the updater) of radiance 1 over
// the light's triangles seen from p: Y00 × solid angle and 0.4886 × the polygon's vector
// irradiance ∫ ω dω (the edge integral per axis).
std::array<double, 4> directShL1(const scene::AreaLight& l, glm::vec3 p) {
  double omega = 0;
  glm::dvec3 vec(0.0);
  for (size_t t = 0; t < l.corners.size(); t += 3) {
    const glm::vec3 v[3] = {l.corners[t] - p, l.corners[t + 1] - p, l.corners[t + 2] - p};
    omega += static_cast<double>(arealight::triangleSolidAngle(p, l.corners[t], l.corners[t + 1], l.corners[t + 2]));
    glm::dvec3 tri(0.0);
    for (int axis = 0; axis < 3; ++axis) {
      glm::vec3 e(0.0f);
      e[axis] = 1.0f;
      float sum = 0;
      for (int k = 0; k < 3; ++k) sum += arealight::edgeIntegral(v[k], v[(k + 1) % 3], e);
      tri[axis] = 0.5 * static_cast<double>(sum);
    }
    // The winding sets the sign: the vector points toward the triangle.
    if (glm::dot(tri, glm::dvec3(v[0] + v[1] + v[2])) < 0) tri = -tri;
    vec += tri;
  }
  const double y1 = 0.488602512;
  return {0.282094792 * omega, y1 * vec.y, y1 * vec.z, y1 * vec.x};  // (c00, c1−1 ∝ y, c10 ∝ z, c11 ∝ x)
}

TEST(AreaLights, EmitterFurnaceProbesPlusClientDirectEqualProbesWithout) {
  VulkanContext context(test::validatedContext());
  const glm::vec3 L(4.0f, 2.0f, 1.0f);
  const scene::Scene s = emitterBox(0.5f, L);
  const ProbeGrid grid{{2, 2, 2}, {{-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}}};
  UpdaterOptions uo;
  uo.samplesPerProbe = 4096;
  uo.maxBounces = 3;  // paths are the same with and without: any bounce count tells
  uo.minBlendWeight = 0.0f;  // a true mean of the updates
  uo.rejectSigmas = 0.0f;
  uo.indirectClamp = 0.0f;
  uo.classify = false;
  ProbeUpdater off(context, s, grid, uo);
  uo.areaLights.enabled = true;
  ProbeUpdater on(context, s, grid, uo);
  for (int u = 0; u < 2; ++u) {
    off.update();
    on.update();
  }
  const scene::AreaLightSet set = scene::extractAreaLights(s, uo.areaLights);
  ASSERT_EQ(set.lights.size(), 1u);
  for (uint32_t p = 0; p < grid.count(); ++p) {
    const uint32_t ix = p % 2, iy = (p / 2) % 2, iz = p / 4;
    const glm::vec3 pos(ix ? 0.5f : -0.5f, iy ? 0.5f : -0.5f, iz ? 0.5f : -0.5f);
    const std::array<double, 4> direct = directShL1(set.lights[0], pos);
    const float* cOff = off.volume().probes.data() + p * 27;
    const float* cOn = on.volume().probes.data() + p * 27;
    for (int c = 0; c < 3; ++c) {
      // The probes left out a large share (the test can tell), and the direct part: the same paths
      // with and without, so what differs is the direction set's quadrature of the panel (≤ 3 %).
      EXPECT_GT(direct[0] * L[c], 0.2 * cOff[c]) << "probe " << p;
      for (int k = 0; k < 4; ++k) {
        const double want = static_cast<double>(cOff[k * 3 + c]) - direct[static_cast<size_t>(k)] * L[c];
        EXPECT_NEAR(cOn[k * 3 + c], want, 0.03 * direct[0] * L[c]) << "probe " << p << " coefficient " << k;
      }
    }
  }
  EXPECT_EQ(context.validationMessages(), 0u);
}

CameraView lookingAlong(glm::vec3 position, glm::vec3 forward, float yfov) {
  CameraView cam;
  cam.position = position;
  cam.forward = glm::normalize(forward);
  cam.up = {0, 1, 0};
  cam.yfov = yfov;
  return cam;
}

Image reference(VulkanContext& context, const scene::Scene& s, const CameraView& cam, uint32_t w, uint32_t h,
                uint32_t bounces) {
  ReferenceOptions ro;
  ro.width = w;
  ro.height = h;
  ro.samplesPerPixel = 256;
  ro.maxBounces = bounces;
  return renderReference(context, s, cam, ro);
}

// Mean of channel c over the pixels [x0, x1) × [y0, y1).
double regionMean(const Image& img, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1, int c) {
  double sum = 0;
  for (uint32_t y = y0; y < y1; ++y)
    for (uint32_t x = x0; x < x1; ++x) sum += static_cast<double>(img.rgb[(y * img.width + x) * 3 + c]);
  return sum / static_cast<double>((x1 - x0) * (y1 - y0));
}

TEST(AreaLights, EmitterFurnaceRasterImageMatchesTheReferenceOnAWall) {
  VulkanContext context(test::validatedContext());
  const glm::vec3 L(4.0f, 2.0f, 1.0f);
  const scene::Scene s = emitterBox(0.5f, L);
  const CameraView cam = lookingAlong({0.9f, -0.2f, 0.0f}, {-1, 0, 0}, 0.9f);
  const uint32_t w = 40, h = 30;
  const Image want = reference(context, s, cam, w, h, 8);
  UpdaterOptions uo;
  uo.samplesPerProbe = 256;
  uo.maxBounces = 8;
  uo.minBlendWeight = 0.0f;
  uo.rejectSigmas = 0.0f;
  uo.areaLights.enabled = true;
  ProbeUpdater updater(context, s, sceneGrid(s, {3, 3, 3}), uo);
  for (int u = 0; u < 4; ++u) updater.update();
  RasterOptions rop;
  rop.areaLights = uo.areaLights;
  RasterRenderer raster(context, s, w, h, rop);
  raster.setProbes(updater.volume());
  const Image image = raster.render(raster.viewProjection(cam), cam.position);
  // The far wall x = −1 fills the middle of the view: compare a central block, per channel.
  for (int c = 0; c < 3; ++c) {
    const double ref = regionMean(want, 12, 28, 9, 21, c), got = regionMean(image, 12, 28, 9, 21, c);
    EXPECT_NEAR(got, ref, 0.05 * ref) << "channel " << c;
  }
  EXPECT_EQ(context.validationMessages(), 0u);
}

// A floor lit by a small panel 2 m above it, a box hovering between them (or not).
scene::Scene blockedPanel(bool withBox = true) {
  scene::Scene s;
  s.name = "blocked-panel";
  scene::Material floor;
  floor.baseColor = glm::vec3(0.8f);
  scene::Material light;
  light.baseColor = glm::vec3(0.0f);
  light.emission = glm::vec3(20.0f);
  s.materials = {floor, light};
  scene::addQuad(s, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, 0);                     // floor, normal +Y
  scene::addQuad(s, {-0.25f, 2, -0.25f}, {0.25f, 2, -0.25f}, {0.25f, 2, 0.25f}, {-0.25f, 2, 0.25f}, 1);  // normal −Y
  if (withBox) scene::addBox(s, {0, 0.7f, 0}, {0.3f, 0.05f, 0.3f}, 0.0f, 0);
  scene::finalizeScene(s);
  return s;
}

// The pixel a world point lands on.
glm::uvec2 pixelOf(const glm::mat4& viewProj, glm::vec3 p, uint32_t w, uint32_t h) {
  const glm::vec4 clip = viewProj * glm::vec4(p, 1.0f);
  const glm::vec2 ndc = glm::vec2(clip) / clip.w;
  return {static_cast<uint32_t>((ndc.x * 0.5f + 0.5f) * static_cast<float>(w)),
          static_cast<uint32_t>((ndc.y * 0.5f + 0.5f) * static_cast<float>(h))};
}

TEST(AreaLights, BlockerShadowsTheFloorUnderItAndNotFarAway) {
  VulkanContext context(test::validatedContext());
  const scene::Scene s = blockedPanel();
  const uint32_t w = 64, h = 48;
  const CameraView cam = lookingAlong({0.0f, 0.4f, 2.5f}, {0.0f, -0.4f, -2.5f}, 0.8f);  // below the box
  RasterOptions ro;
  ro.areaLights.enabled = true;
  RasterRenderer shadowed(context, s, w, h, ro);
  ro.maxShadowLayers = 0;  // no layer for any light: unshadowed
  RasterRenderer open(context, s, w, h, ro);
  ASSERT_EQ(shadowed.areaLights().lights.size(), 1u);
  const glm::mat4 vp = shadowed.viewProjection(cam);
  const Image a = shadowed.render(vp, cam.position), b = open.render(vp, cam.position);
  const glm::uvec2 under = pixelOf(vp, {0, 0, 0}, w, h), aside = pixelOf(vp, {1.6f, 0, 0}, w, h);
  const auto at = [&](const Image& img, glm::uvec2 px) { return img.rgb[(px.y * w + px.x) * 3]; };
  ASSERT_GT(at(b, under), 0.2f);  // lit without shadows (≈ 0.8/π × 20 × 0.0625)
  EXPECT_LT(at(a, under), 0.3f * at(b, under));  // the box's umbra
  EXPECT_NEAR(at(a, aside), at(b, aside), 0.02f * at(b, aside));  // outside its shadow: as lit
  // The unshadowed floor under the panel: albedo/π × L × ∫cos dω, plus a small GGX share.
  const glm::vec3 c[4] = {{-0.25f, 2, -0.25f}, {0.25f, 2, -0.25f}, {0.25f, 2, 0.25f}, {-0.25f, 2, 0.25f}};
  const double diffuse = 0.8 / kPiD * 20.0 * quadCosineSolidAngle({0, 0, 0}, {0, 1, 0}, c[0], c[1], c[2], c[3]);
  EXPECT_GT(at(b, under), 0.99 * diffuse);
  EXPECT_LT(at(b, under), 1.10 * diffuse);
  EXPECT_EQ(context.validationMessages(), 0u);
}

TEST(AreaLights, GlossyFloorReflectsThePanelCloseToTheReference) {
  // Direct light only (no probes; the reference stops after the light's own emission: 2 bounces)
  // on a metal floor of roughness 0.5 and 0.25 under the panel, seen where it mirrors the panel.
  // The GGX term is a representative-point approximation: this bounds its error on the region.
  VulkanContext context(test::validatedContext());
  for (const float roughness : {0.5f, 0.25f}) {
    scene::Scene s = blockedPanel(false);
    s.materials[0].metallic = 1.0f;
    s.materials[0].roughness = roughness;
    const CameraView cam = lookingAlong({0.0f, 1.0f, 2.0f}, {0.0f, -1.0f, -1.3f}, 0.9f);
    const uint32_t w = 32, h = 24;
    const Image traced = reference(context, s, cam, w, h, 2);
    RasterOptions rop;
    rop.areaLights.enabled = true;
    RasterRenderer raster(context, s, w, h, rop);
    const Image image = raster.render(raster.viewProjection(cam), cam.position);
    const double want = regionMean(traced, 4, 28, 4, 20, 0), got = regionMean(image, 4, 28, 4, 20, 0);
    std::printf("roughness %.2f: raster %.4f, reference %.4f (%+.1f %%)\n", static_cast<double>(roughness), got, want,
                100.0 * (got / want - 1.0));
    EXPECT_NEAR(got, want, 0.2 * want) << "roughness " << roughness;  // measured +3.5 % and +16 %
  }
  EXPECT_EQ(context.validationMessages(), 0u);
}

}  // namespace
}  // namespace probecast::renderer
