// What the views show of each probe (renderer/probe_interest.h): probeViewFootprints on a wall seen
// straight on, behind an occluder, from inside the scene, and with views that see nothing; and
// probeViewSensitivity against its formula worked by hand (gamma, direct light, colour, textures,
// bad coefficients).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "probecast/codec/sh.h"
#include "probecast/renderer/glossy_sh.h"
#include "probecast/renderer/probe_interest.h"
#include "view_test_support.h"

namespace probecast::renderer {
namespace {

using test::toView;

// Orthographic, looking down −z from z = 20 at x, y in [−0.5, 2.5].
View straightOn() {
  const glm::vec3 eye(1.0f, 1.0f, 20.0f);
  const glm::mat4 proj = glm::orthoRH_ZO(-1.5f, 1.5f, -1.5f, 1.5f, 0.1f, 40.0f);
  return toView(proj * glm::lookAt(eye, glm::vec3(1.0f, 1.0f, 0.0f), glm::vec3(0, 1, 0)), eye);
}

// Probes at x, y in {0, 1, 2} and z in {0, 1} (index x + 3 (y + 3 z)); a wall in the plane z = 0
// over x, y in [−0.5, 2.5], facing +z.
const ProbeGrid kGrid{{3, 3, 2}, {{0, 0, 0}, {2, 2, 1}}};
scene::Scene wall() {
  scene::Scene s;
  scene::addQuad(s, {-0.5f, -0.5f, 0}, {2.5f, -0.5f, 0}, {2.5f, 2.5f, 0}, {-0.5f, 2.5f, 0}, 0);
  return s;
}
uint32_t at(uint32_t x, uint32_t y, uint32_t z) { return x + 3 * (y + 3 * z); }

TEST(ProbeInterest, AWallSeenStraightOnIsLitByItsOwnPlaneOfProbes) {
  const View v = straightOn();
  const std::vector<float> w = probeViewFootprints(wall(), kGrid, {}, std::span<const View>(&v, 1));
  ASSERT_EQ(w.size(), kGrid.count());
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 3; ++x) {
      EXPECT_GT(w[at(x, y, 0)], 0.0f) << x << " " << y;
      EXPECT_EQ(w[at(x, y, 1)], 0.0f) << x << " " << y;  // the wall lies on their neighbours' plane: weight 0
    }
  // Each of the 64 × 40 pixels sees the wall, and its normalised weights squared sum to between 1/8
  // and 1 (here 1/4 and 1: two probes of each cell weigh 0).
  float total = 0.0f;
  for (float x : w) total += x;
  EXPECT_GE(total, 2560.0f / 4.0f - 1.0f);
  EXPECT_LE(total, 2560.0f + 1.0f);
  EXPECT_NEAR(w[at(0, 0, 0)], w[at(2, 2, 0)], 0.05f * w[at(0, 0, 0)]);  // the view is symmetric
  EXPECT_NEAR(w[at(0, 1, 0)], w[at(2, 1, 0)], 0.05f * w[at(0, 1, 0)]);

  // An inactive probe lights nothing; its share goes to the others of its cells.
  std::vector<uint8_t> active(kGrid.count(), 1);
  active[at(1, 1, 0)] = 0;
  const std::vector<float> without = probeViewFootprints(wall(), kGrid, active, std::span<const View>(&v, 1));
  EXPECT_EQ(without[at(1, 1, 0)], 0.0f);
  EXPECT_GT(without[at(1, 0, 0)], w[at(1, 0, 0)]);
}

TEST(ProbeInterest, AnOccluderHidesTheWallAndBringsInTheProbesAroundIt) {
  // A panel at z = 0.5 over x in [−0.5, 1]: its points lie between the two planes of probes.
  scene::Scene s = wall();
  scene::addQuad(s, {-0.5f, -0.5f, 0.5f}, {1.0f, -0.5f, 0.5f}, {1.0f, 2.5f, 0.5f}, {-0.5f, 2.5f, 0.5f}, 0);
  const View v = straightOn();
  const std::vector<float> w = probeViewFootprints(s, kGrid, {}, std::span<const View>(&v, 1));
  for (uint32_t y = 0; y < 3; ++y) {
    EXPECT_GT(w[at(0, y, 1)], 0.0f) << y;
    EXPECT_GT(w[at(1, y, 1)], 0.0f) << y;
    EXPECT_EQ(w[at(2, y, 1)], 0.0f) << y;  // the wall beyond x = 1 only
  }
  // The same panel drawn first or last: the nearest surface wins either way.
  scene::Scene reversed;
  scene::addQuad(reversed, {-0.5f, -0.5f, 0.5f}, {1.0f, -0.5f, 0.5f}, {1.0f, 2.5f, 0.5f}, {-0.5f, 2.5f, 0.5f}, 0);
  scene::addQuad(reversed, {-0.5f, -0.5f, 0}, {2.5f, -0.5f, 0}, {2.5f, 2.5f, 0}, {-0.5f, 2.5f, 0}, 0);
  EXPECT_EQ(probeViewFootprints(reversed, kGrid, {}, std::span<const View>(&v, 1)), w);
}

TEST(ProbeInterest, AFloorThatPassesBehindTheEyeIsClippedNotLost) {
  // Perspective from (1, 0.5, 3) towards (1, 0, 0): a floor y = 0 from z = −1 to z = 10 runs under
  // and behind the eye (through the near plane); the probes at y = 0 light what the view sees of it.
  scene::Scene s;
  scene::addQuad(s, {-0.5f, 0, 10}, {2.5f, 0, 10}, {2.5f, 0, -1}, {-0.5f, 0, -1}, 0);
  const glm::vec3 eye(1.0f, 0.5f, 3.0f);
  const View v = toView(glm::perspectiveRH_ZO(1.2f, 1.6f, 0.05f, 50.0f) * glm::lookAt(eye, {1.0f, 0.0f, 0.0f}, {0, 1, 0}), eye);
  const std::vector<float> w = probeViewFootprints(s, kGrid, {}, std::span<const View>(&v, 1));
  float floor = 0.0f, above = 0.0f;
  for (uint32_t z = 0; z < 2; ++z)
    for (uint32_t x = 0; x < 3; ++x) {
      floor += w[at(x, 0, z)];
      above += w[at(x, 2, z)];
    }
  EXPECT_GT(floor, 0.0f);
  EXPECT_EQ(above, 0.0f);
}

TEST(ProbeInterest, TheSampleGridKeepsItsBudgetOverTheViews) {
  EXPECT_EQ(footprintSampleSize(1), glm::uvec2(256, 160));
  EXPECT_EQ(footprintSampleSize(16), glm::uvec2(64, 40));
  EXPECT_EQ(footprintSampleSize(0), glm::uvec2(256, 160));  // no views: as for one
  for (size_t views : {2u, 3u, 5u, 7u, 16u, 256u, 40960u, 1000000u}) {
    const glm::uvec2 size = footprintSampleSize(views);
    EXPECT_GE(size.x, 1u);
    EXPECT_GE(size.y, 1u);
    if (size.y > 1) {
      EXPECT_LE(size.x * size.y * views, kFootprintSamples) << views;
    }
  }
}

TEST(ProbeInterest, WeightsBlendSlowlyAndKeepWhatIsBroken) {
  std::vector<float> held;
  blendViewWeights(held, std::vector<float>{1.0f, 2.0f, NAN, -1.0f});  // the first weights are taken as they are
  EXPECT_EQ(held, (std::vector<float>{1.0f, 2.0f, 0.0f, 0.0f}));      // but nothing broken
  blendViewWeights(held, std::vector<float>{33.0f, INFINITY, 32.0f, 64.0f});
  EXPECT_FLOAT_EQ(held[0], 1.0f * 31.0f / 32.0f + 33.0f / 32.0f);  // 2
  EXPECT_FLOAT_EQ(held[1], 2.0f);                                  // a non-finite weight changes nothing
  EXPECT_FLOAT_EQ(held[2], 1.0f);
  EXPECT_FLOAT_EQ(held[3], 2.0f);
  blendViewWeights(held, std::vector<float>{5.0f, 6.0f}, 0.5f);  // another grid: started again
  EXPECT_EQ(held, (std::vector<float>{5.0f, 6.0f}));
  blendViewWeights(held, std::vector<float>{7.0f, 8.0f}, 0.5f);
  EXPECT_EQ(held, (std::vector<float>{6.0f, 7.0f}));
}

TEST(ProbeInterest, ViewsThatSeeNothingWeighNothing) {
  EXPECT_TRUE(probeViewFootprints(wall(), kGrid, {}, {}).empty());  // no views: nobody's interest known
  View away = straightOn();
  const glm::vec3 eye(1.0f, 1.0f, 20.0f);
  away = toView(glm::orthoRH_ZO(-1.5f, 1.5f, -1.5f, 1.5f, 0.1f, 40.0f) * glm::lookAt(eye, {1.0f, 1.0f, 40.0f}, {0, 1, 0}), eye);
  View broken = straightOn();
  broken.viewProj[5] = NAN;
  for (const View& v : {away, broken}) {
    const std::vector<float> w = probeViewFootprints(wall(), kGrid, {}, std::span<const View>(&v, 1));
    ASSERT_EQ(w.size(), kGrid.count());
    for (float x : w) EXPECT_EQ(x, 0.0f);
  }
}

// Every probe holds the same uniform grey radiance r: E(n) = π · Y00 · (DC = r / Y00) = π r
// (docs/CODEC.md §1), so a white wall shows L = ρ/π · π r = r without other light.
std::vector<float> uniformProbes(float r) {
  std::vector<float> probes(static_cast<size_t>(kGrid.count()) * kProbeFloats, 0.0f);
  for (uint32_t p = 0; p < kGrid.count(); ++p)
    for (int c = 0; c < 3; ++c) probes[static_cast<size_t>(p) * kProbeFloats + c] = r / kY00;
  return probes;
}

// probeViewSensitivity with the direct light of the scene's own lights (sampleDirectLight).
std::vector<float> sensitivity(const scene::Scene& s, const std::vector<ViewSample>& seen, const SurfaceLighting& lighting,
                               const std::vector<float>& probes) {
  return probeViewSensitivity(seen, sampleDirectLight(s, seen, lighting), lighting, probes, kGrid.count());
}

scene::Scene whiteWall() {
  scene::Scene s = wall();
  s.materials.emplace_back().baseColor = glm::vec3(1.0f);
  return s;
}

// The environment BRDF (A, B) where the straight-on view meets the wall: n·v near 1 and roughness 1
// (glTF's default), the table's last texel (glossy_sh.h, as the raster client builds it). Uniform
// probes give a prefiltered radiance of r (band 0 only, g_0 = 1), so a sample of diffuse colour ρ
// and F0 shows L = r (ρ + F0 A + B).
glm::vec2 envBrdfStraightOn() {
  const std::vector<float> table = renderer::envBrdfTable(32, 256);
  return {table[(31 * 32 + 31) * 2], table[(31 * 32 + 31) * 2 + 1]};
}
double glossyOfDielectric() {
  const glm::vec2 ab = envBrdfStraightOn();
  return 0.04 * ab.x + ab.y;
}

TEST(ProbeInterest, SensitivityIsTheFootprintTimesTheGammaSlopeWorkedByHand) {
  // With one light in every probe, each probe's part of a sample is ŵ · L, so its change after
  // gamma is g′(L) · 0.2 · ŵ L = (0.2 / 2.2) L^(1/2.2) ŵ per channel: the sensitivity is
  // 3 (0.2 / 2.2)² L^(2/2.2) times the footprint, for every probe, with L = r (1 + F0 A + B).
  const scene::Scene s = whiteWall();
  const View v = straightOn();
  const std::vector<ViewSample> seen = sampleViewSurfaces(s, kGrid, {}, {}, std::span<const View>(&v, 1));
  ASSERT_EQ(seen.size(), 64u * 40u);
  const std::vector<float> footprint = probeViewFootprints(seen, kGrid.count());
  const SurfaceLighting lighting = surfaceLighting(s, {});
  for (float r : {0.25f, 4.0f}) {
    const std::vector<float> w = sensitivity(s, seen, lighting, uniformProbes(r));
    const double k = 3.0 * (0.2 / 2.2) * (0.2 / 2.2) * std::pow(r * (1.0 + glossyOfDielectric()), 2.0 / 2.2);
    for (uint32_t p = 0; p < kGrid.count(); ++p) EXPECT_NEAR(w[p], k * footprint[p], 1e-4 * k * footprint[p] + 1e-12) << p;
  }
}

TEST(ProbeInterest, DirectLightMakesTheProbesCountLessAsGammaDoes) {
  // A directional light straight onto the white wall with irradiance π r adds r to every sample,
  // L = r (1 + G) with G = F0 A + B the glossy part, so each sensitivity falls by
  // g′(L + r)² / g′(L)² = ((2 + G) / (1 + G))^(2/2.2 − 2).
  scene::Scene s = whiteWall();
  const float r = 0.5f;
  s.lights.push_back({scene::LightType::Directional, {}, {0, 0, -1}, glm::vec3(1.0f), kPi * r});
  const View v = straightOn();
  const std::vector<ViewSample> seen = sampleViewSurfaces(s, kGrid, {}, {}, std::span<const View>(&v, 1));
  const std::vector<float> dark = sensitivity(s, seen, surfaceLighting(wall(), {}), uniformProbes(r));
  scene::Scene unlit = s;
  unlit.lights.clear();
  const std::vector<float> without = sensitivity(s, seen, surfaceLighting(unlit, {}), uniformProbes(r));
  const std::vector<float> with = sensitivity(s, seen, surfaceLighting(s, {}), uniformProbes(r));
  const double g = glossyOfDielectric();
  const double ratio = std::pow((2.0 + g) / (1.0 + g), 2.0 / 2.2 - 2.0);
  for (uint32_t p = 0; p < kGrid.count(); ++p) {
    EXPECT_NEAR(with[p], ratio * without[p], 1e-4 * without[p] + 1e-12) << p;
    // A scene without materials counts its surfaces as glTF's default 0.8 grey.
    EXPECT_NEAR(dark[p], std::pow((0.8 + g) / (1.0 + g), 2.0 / 2.2) * without[p], 1e-4 * without[p] + 1e-12) << p;
  }
  // A light from behind the wall lights nothing the view sees.
  s.lights[0].direction = {0, 0, 1};
  EXPECT_EQ(sensitivity(s, seen, surfaceLighting(s, {}), uniformProbes(r)), without);
}

TEST(ProbeInterest, ThePunctualLightsCastShadows) {
  const View v = straightOn();
  // A directional light from +x, +z at 45°: the white wall gets E cos 45° = 0.7071 × π r, so
  // ρ/π E = 0.7071 r where it is lit. A panel in the plane x = 2.7 (outside the view), z in [0, 1.7],
  // shades every point of the wall with x > 1 (its ray to the light crosses x = 2.7 at z = 2.7 − x).
  {
    scene::Scene s = whiteWall();
    const float r = 2.0f;
    s.lights.push_back({scene::LightType::Directional, {}, glm::normalize(glm::vec3(-1, 0, -1)), glm::vec3(1.0f), kPi * r});
    scene::addQuad(s, {2.7f, -1.0f, 0.0f}, {2.7f, -1.0f, 1.7f}, {2.7f, 3.0f, 1.7f}, {2.7f, 3.0f, 0.0f}, 0);
    const std::vector<ViewSample> seen = sampleViewSurfaces(s, kGrid, {}, {}, std::span<const View>(&v, 1));
    const std::vector<glm::vec3> direct = sampleDirectLight(s, seen, surfaceLighting(s, {}));
    ASSERT_EQ(direct.size(), seen.size());
    int lit = 0, shaded = 0;
    for (size_t i = 0; i < seen.size(); ++i) {
      if (seen[i].point.x < 0.9f) {
        EXPECT_NEAR(direct[i].x, 0.7071f * r, 1e-3f) << seen[i].point.x;
        ++lit;
      }
      if (seen[i].point.x > 1.1f) {
        EXPECT_EQ(direct[i].x, 0.0f) << seen[i].point.x;
        ++shaded;
      }
    }
    EXPECT_GT(lit, 500);
    EXPECT_GT(shaded, 500);
  }
  // A point light at (1, 1, 2) and a square at z = 1.5 over x, y in [0.8, 1.2]: its shadow on the
  // wall spans x, y in [0.2, 1.8] (4× from the light); outside it the wall gets I cos θ / d².
  {
    scene::Scene s = whiteWall();
    const glm::vec3 at(1.0f, 1.0f, 2.0f);
    s.lights.push_back({scene::LightType::Point, at, {}, glm::vec3(1.0f), 5.0f});
    scene::addQuad(s, {0.8f, 0.8f, 1.5f}, {1.2f, 0.8f, 1.5f}, {1.2f, 1.2f, 1.5f}, {0.8f, 1.2f, 1.5f}, 0);
    const std::vector<ViewSample> seen = sampleViewSurfaces(s, kGrid, {}, {}, std::span<const View>(&v, 1));
    const std::vector<glm::vec3> direct = sampleDirectLight(s, seen, surfaceLighting(s, {}));
    int lit = 0, shaded = 0;
    for (size_t i = 0; i < seen.size(); ++i) {
      const glm::vec3 p = seen[i].point;
      if (p.z > 0.1f) continue;  // the square itself
      const float reach = std::max(std::fabs(p.x - 1.0f), std::fabs(p.y - 1.0f));
      if (reach < 0.7f) {
        EXPECT_EQ(direct[i].x, 0.0f) << p.x << " " << p.y;
        ++shaded;
      }
      if (reach > 0.9f) {
        const glm::vec3 d = at - p;
        const float expected = 5.0f * d.z / std::pow(glm::length(d), 3.0f) / kPi;  // ρ/π · I cos θ / d²
        EXPECT_NEAR(direct[i].x, expected, 1e-3f * expected) << p.x << " " << p.y;
        ++lit;
      }
    }
    EXPECT_GT(lit, 200);
    EXPECT_GT(shaded, 200);
  }
}

TEST(ProbeInterest, ATextureCountsByItsMeanLinearColour) {
  // Half the texels sRGB 255, half 0: a mean linear colour of 0.5, so L and each part go from
  // r (1 + G) to r (0.5 + G) and the sensitivity falls by ((0.5 + G) / (1 + G))^(2/2.2).
  scene::Scene s = whiteWall();
  scene::Texture& t = s.textures.emplace_back();
  t.width = 2;
  t.height = 2;
  t.rgba = {255, 255, 255, 255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255, 255};
  const View v = straightOn();
  const std::vector<ViewSample> seen = sampleViewSurfaces(s, kGrid, {}, {}, std::span<const View>(&v, 1));
  const std::vector<float> plain = sensitivity(s, seen, surfaceLighting(s, {}), uniformProbes(1.0f));
  s.materials[0].baseColorTexture = 0;
  const SurfaceLighting lighting = surfaceLighting(s, {});
  ASSERT_EQ(lighting.materials.size(), 1u);
  EXPECT_NEAR(lighting.materials[0].diffuse.x, 0.5f, 1e-6f);
  const std::vector<float> textured = sensitivity(s, seen, lighting, uniformProbes(1.0f));
  for (uint32_t p = 0; p < kGrid.count(); ++p)
    EXPECT_NEAR(textured[p], std::pow((0.5 + glossyOfDielectric()) / (1.0 + glossyOfDielectric()), 2.0 / 2.2) * plain[p],
                1e-4 * plain[p] + 1e-12)
        << p;
}

TEST(ProbeInterest, AMetalTakesOnlyTheGlossyTerm) {
  // White metal: no diffuse light and F0 = 1, so L = r (A + B) against r (1 + 0.04 A + B).
  scene::Scene s = whiteWall();
  const View v = straightOn();
  const std::vector<ViewSample> seen = sampleViewSurfaces(s, kGrid, {}, {}, std::span<const View>(&v, 1));
  // The eye is 20 m away: every n·v is past 31.5/32, where the table's last texel answers.
  for (const ViewSample& x : seen) ASSERT_GT(glm::dot(x.toEye, x.normal), 31.5f / 32.0f);
  const std::vector<float> dielectric = sensitivity(s, seen, surfaceLighting(s, {}), uniformProbes(1.0f));
  s.materials[0].metallic = 1.0f;
  const SurfaceLighting metal = surfaceLighting(s, {});
  EXPECT_EQ(metal.materials[0].diffuse, glm::vec3(0.0f));
  EXPECT_EQ(metal.materials[0].specular, glm::vec3(1.0f));
  const std::vector<float> shiny = sensitivity(s, seen, metal, uniformProbes(1.0f));
  const glm::vec2 ab = envBrdfStraightOn();
  const double ratio = std::pow((ab.x + ab.y) / (1.0 + glossyOfDielectric()), 2.0 / 2.2);
  for (uint32_t p = 0; p < kGrid.count(); ++p)
    EXPECT_NEAR(shiny[p], ratio * dielectric[p], 1e-4 * dielectric[p] + 1e-12) << p;
}

TEST(ProbeInterest, ABrighterProbeCountsForMoreAndABrokenOneForNothing) {
  const scene::Scene s = whiteWall();
  const View v = straightOn();
  const std::vector<ViewSample> seen = sampleViewSurfaces(s, kGrid, {}, {}, std::span<const View>(&v, 1));
  const SurfaceLighting lighting = surfaceLighting(s, {});
  const std::vector<float> even = sensitivity(s, seen, lighting, uniformProbes(1.0f));
  std::vector<float> probes = uniformProbes(1.0f);
  for (int c = 0; c < 3; ++c) probes[static_cast<size_t>(at(1, 1, 0)) * kProbeFloats + c] *= 4.0f;
  const std::vector<float> bright = sensitivity(s, seen, lighting, probes);
  EXPECT_GT(bright[at(1, 1, 0)], 4.0f * even[at(1, 1, 0)]);  // (4/L)² with L up by less than 4×
  EXPECT_LT(bright[at(0, 0, 0)], even[at(0, 0, 0)]);         // its neighbours' pixels got brighter
  // A NaN or infinite coefficient makes that probe count as black, and nothing else non-finite.
  probes[static_cast<size_t>(at(1, 1, 0)) * kProbeFloats + 13] = NAN;
  probes[static_cast<size_t>(at(2, 2, 0)) * kProbeFloats + 0] = INFINITY;
  const std::vector<float> broken = sensitivity(s, seen, lighting, probes);
  EXPECT_EQ(broken[at(1, 1, 0)], 0.0f);
  EXPECT_EQ(broken[at(2, 2, 0)], 0.0f);
  for (float x : broken) EXPECT_TRUE(std::isfinite(x));
  EXPECT_GT(broken[at(0, 0, 0)], 0.0f);
  // Too few coefficients for the grid: the probes past them count as black.
  probes.resize(kProbeFloats);
  const std::vector<float> short_ = sensitivity(s, seen, lighting, probes);
  ASSERT_EQ(short_.size(), kGrid.count());
  EXPECT_GT(short_[0], 0.0f);
  for (uint32_t p = 1; p < kGrid.count(); ++p) EXPECT_EQ(short_[p], 0.0f);
}

TEST(ProbeInterest, AClientAreaLightIsAddedAsTheViewersAddIt) {
  // An emissive panel facing the wall, 0.5 m in front of it: client-lit, it adds its unshadowed
  // Lambertian light to every sample, and every probe counts for less; off, the probes carry it.
  scene::Scene s = whiteWall();
  auto& lamp = s.materials.emplace_back();
  lamp.baseColor = glm::vec3(0.0f);
  lamp.emission = glm::vec3(10.0f);
  scene::addQuad(s, {0.5f, 0.5f, 0.5f}, {0.5f, 1.5f, 0.5f}, {1.5f, 1.5f, 0.5f}, {1.5f, 0.5f, 0.5f}, 1);  // faces −z
  const View v = straightOn();
  const std::vector<ViewSample> seen = sampleViewSurfaces(s, kGrid, {}, {}, std::span<const View>(&v, 1));
  scene::AreaLightOptions on;
  on.enabled = true;
  const SurfaceLighting lit = surfaceLighting(s, on);
  ASSERT_EQ(lit.areaLights.lights.size(), 1u);
  const std::vector<float> without = sensitivity(s, seen, surfaceLighting(s, {}), uniformProbes(0.1f));
  const std::vector<float> with = sensitivity(s, seen, lit, uniformProbes(0.1f));
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 3; ++x) EXPECT_LT(with[at(x, y, 0)], without[at(x, y, 0)]) << x << " " << y;
}

}  // namespace
}  // namespace probecast::renderer
