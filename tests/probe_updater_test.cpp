// The Vulkan probe updater against analytic answers (docs/CODEC.md §8), determinism, classification
// and validation (zero messages). Runs on lavapipe in CI.
#include <gtest/gtest.h>

#include <cmath>

#include "probecast/codec/probe_offsets.h"
#include "probecast/codec/sh.h"
#include "probecast/codec/stream.h"
#include "probecast/renderer/probe_updater.h"
#include "update_bench.h"

namespace probecast::renderer {
namespace {

using scene::Material;
using scene::Scene;

// Every test checks the validation layer stayed silent.
class Updater : public ::testing::Test {
 protected:
  void SetUp() override {
    ContextOptions options;
    options.validation = true;
    context_ = std::make_unique<VulkanContext>(options);
  }
  void TearDown() override { EXPECT_EQ(context_->validationMessages(), 0u) << "Vulkan validation messages"; }
  std::unique_ptr<VulkanContext> context_;
};

uint32_t addMaterial(Scene& s, glm::vec3 base, glm::vec3 emission) {
  Material m;
  m.baseColor = base;
  m.emission = emission;
  s.materials.push_back(m);
  return static_cast<uint32_t>(s.materials.size() - 1);
}

// Inward-facing box x, y, z in [-1, 1]; `material(face, upperHalf)` picks each half-face's material
// (faces split at z = 0 where they cross it).
template <typename Pick>
Scene halfSplitBox(Pick material) {
  Scene s;
  s.name = "test-box";
  const float a = -1, b = 1;
  // z = ±1 caps.
  scene::addQuad(s, {a, a, a}, {b, a, a}, {b, b, a}, {a, b, a}, material(0, false));  // z = −1, normal +Z
  scene::addQuad(s, {b, a, b}, {a, a, b}, {a, b, b}, {b, b, b}, material(1, true));   // z = +1, normal −Z
  for (int half = 0; half < 2; ++half) {
    const float z0 = half ? 0.0f : a, z1 = half ? b : 0.0f;
    const bool upper = half == 1;
    scene::addQuad(s, {a, a, z1}, {b, a, z1}, {b, a, z0}, {a, a, z0}, material(2, upper));  // y = −1, normal +Y
    scene::addQuad(s, {a, b, z0}, {b, b, z0}, {b, b, z1}, {a, b, z1}, material(3, upper));  // y = +1, normal −Y
    scene::addQuad(s, {a, a, z1}, {a, a, z0}, {a, b, z0}, {a, b, z1}, material(4, upper));  // x = −1, normal +X
    scene::addQuad(s, {b, a, z0}, {b, a, z1}, {b, b, z1}, {b, b, z0}, material(5, upper));  // x = +1, normal −X
  }
  scene::finalizeScene(s);
  return s;
}

ProbeGrid singleProbe(glm::vec3 p) {
  ProbeGrid g;
  g = ProbeGrid{{1, 1, 1}, {{p.x, p.y, p.z}, {p.x, p.y, p.z}}};
  return g;
}

TEST_F(Updater, ClosedEmissiveBoxGivesConstantRadiance) {
  // Radiance L from every inner face, black albedo: c00 = 2√π L and the rest 0 (docs/CODEC.md §8.1).
  const glm::vec3 L(1.0f, 0.5f, 0.25f);
  Scene s;
  const uint32_t m = addMaterial(s, glm::vec3(0.0f), L);
  s = halfSplitBox([&](int, bool) { return m; });
  s.materials.clear();
  addMaterial(s, glm::vec3(0.0f), L);
  UpdaterOptions o;
  o.samplesPerProbe = 256;
  o.maxBounces = 1;  // the emission the probe sees, no reflections of it (GGX reflects even black)
  ProbeUpdater updater(*context_, s, singleProbe({0.1f, -0.2f, 0.05f}), o);
  ASSERT_EQ(updater.volume().active.data()[0], 1);
  for (int u = 0; u < 3; ++u) updater.update();
  const float* p = updater.volume().probes.data();
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(p[c], 3.5449077f * L[c], 1e-4f * L[c]);  // every ray sees L exactly
    for (int i = 1; i < kShCoeffs; ++i) EXPECT_NEAR(p[i * 3 + c], 0.0f, 0.02f * p[c]) << "coefficient " << i;
  }
}

TEST_F(Updater, EmissionTextureIsDecodedFromSrgb) {
  // The constant box again, with emission factor 1 times a uniform sRGB 128 texture:
  // linear ((128/255 + 0.055)/1.055)^2.4 = 0.2158605, so c00 = 2√π · 0.2158605.
  Scene s = halfSplitBox([](int, bool) { return 0u; });
  s.materials.clear();
  const uint32_t m = addMaterial(s, glm::vec3(0.0f), glm::vec3(1.0f));
  s.materials[m].emissiveTexture = 0;
  scene::Texture t;
  t.width = 3;
  t.height = 2;
  t.rgba.assign(3 * 2 * 4, 128);
  s.textures.push_back(t);
  UpdaterOptions o;
  o.samplesPerProbe = 128;
  o.maxBounces = 1;
  ProbeUpdater updater(*context_, s, singleProbe({0.2f, 0.1f, -0.3f}), o);
  updater.update();
  EXPECT_NEAR(updater.volume().probes.data()[0], 3.5449077f * 0.2158605f, 1e-4f);
}

TEST_F(Updater, HalfEmissiveBoxGivesHemisphereAnswer) {
  // Radiance 1 for z > 0, 0 below (docs/CODEC.md §8.2): c00 = √π, c10 = √(3π)/2, c20 = 0, E(+z) = π.
  Scene s;
  s = halfSplitBox([](int, bool upper) { return upper ? 1u : 0u; });
  s.materials.clear();
  addMaterial(s, glm::vec3(0.0f), glm::vec3(0.0f));
  addMaterial(s, glm::vec3(0.0f), glm::vec3(1.0f));
  UpdaterOptions o;
  o.samplesPerProbe = 1024;
  o.maxBounces = 1;
  ProbeUpdater updater(*context_, s, singleProbe({0.0f, 0.0f, 0.0f}), o);
  for (int u = 0; u < 8; ++u) updater.update();
  const float* p = updater.volume().probes.data();
  EXPECT_NEAR(p[0], 1.7724539f, 0.01f);
  EXPECT_NEAR(p[2 * 3], 1.5349900f, 0.015f);
  EXPECT_NEAR(p[6 * 3], 0.0f, 0.015f);
  float e[3];
  shEvalIrradiance(p, 0, 0, 1, e);
  EXPECT_NEAR(e[0], kPi, 0.03f);
  shEvalIrradiance(p, 0, 0, -1, e);
  EXPECT_NEAR(e[0], 0.0f, 0.03f);
}

// glTF metallic-roughness BRDF for a dielectric (metallic 0): Lambert + GGX with Smith-Schlick G
// and Schlick Fresnel, F0 = 0.04 — written independently of the shader.
double dielectricBrdf(double rho, double roughness, const glm::dvec3& n, const glm::dvec3& wo, const glm::dvec3& wi) {
  const double nl = glm::dot(n, wi), nv = glm::dot(n, wo);
  if (nl <= 0 || nv <= 0) return 0;
  const glm::dvec3 h = glm::normalize(wo + wi);
  const double nh = glm::dot(n, h), vh = glm::dot(wo, h);
  const double a = roughness * roughness, a2 = a * a;
  const double d = a2 / (M_PI * std::pow(nh * nh * (a2 - 1) + 1, 2));
  const double k = a / 2;
  const double g = nl / (nl * (1 - k) + k) * nv / (nv * (1 - k) + k);
  const double f = 0.04 + 0.96 * std::pow(1 - vh, 5);
  return rho / M_PI + d * g * f / (4 * nl * nv);
}

// Radiance at the probe from a floor lit by a point light, integrated on the CPU.
TEST_F(Updater, PointLightOnFloorMatchesNumericalIntegral) {
  const float rho = 0.5f, intensity = 4.0f, half = 5.0f;
  const glm::vec3 light(0.3f, 2.0f, 0.0f), probe(0.0f, 1.0f, 0.0f);
  Scene s;
  addMaterial(s, glm::vec3(rho), glm::vec3(0.0f));
  s.materials[0].roughness = 0.6f;
  scene::addQuad(s, {-half, 0, half}, {half, 0, half}, {half, 0, -half}, {-half, 0, -half}, 0);
  scene::Light l;
  l.position = light;
  l.intensity = intensity;
  s.lights.push_back(l);
  scene::finalizeScene(s);
  UpdaterOptions o;
  o.samplesPerProbe = 1024;
  o.maxBounces = 1;  // direct light only: nothing else to bounce off
  ProbeUpdater updater(*context_, s, singleProbe(probe), o);
  for (int u = 0; u < 8; ++u) updater.update();

  // c_i = ∫ L(x) Y_i(ω) dω with dω = cos θ_x dA / r², L(x) = f(x) · I cos θ_l / d².
  double ref[kShCoeffs] = {};
  const int n = 1000;
  const double cell = 2.0 * half / n;
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n; ++k) {
      const glm::dvec3 x(-half + (i + 0.5) * cell, 0.0, -half + (k + 0.5) * cell);
      const glm::dvec3 toLight = glm::dvec3(light) - x, toProbe = glm::dvec3(probe) - x;
      const double dl2 = glm::dot(toLight, toLight), r2 = glm::dot(toProbe, toProbe);
      const double f = dielectricBrdf(rho, 0.6, glm::dvec3(0, 1, 0), glm::normalize(toProbe), glm::normalize(toLight));
      const double radiance = f * intensity * (toLight.y / std::sqrt(dl2)) / dl2;
      const double domega = (toProbe.y / std::sqrt(r2)) * cell * cell / r2;
      const glm::dvec3 w = -toProbe / std::sqrt(r2);
      float y[kShCoeffs];
      shEvalBasis(static_cast<float>(w.x), static_cast<float>(w.y), static_cast<float>(w.z), y);
      for (int c = 0; c < kShCoeffs; ++c) ref[c] += radiance * y[c] * domega;
    }
  }
  const float* p = updater.volume().probes.data();
  for (int c = 0; c < kShCoeffs; ++c)
    EXPECT_NEAR(p[c * 3], ref[c], 0.03 * ref[0]) << "coefficient " << c;
}

TEST_F(Updater, SameSeedIsBitIdenticalOtherSeedIsNot) {
  Scene s;
  std::string error;
  ASSERT_TRUE(scene::makeBuiltinScene("cornell", 0.0f, s, error)) << error;
  ProbeGrid g;
  g = ProbeGrid{{3, 3, 3}, {{-0.8f, 0.2f, -0.8f}, {0.8f, 1.8f, 0.8f}}};
  UpdaterOptions o;
  o.samplesPerProbe = 64;
  std::vector<float> results[3];
  for (int run = 0; run < 3; ++run) {
    o.seed = run < 2 ? 7u : 8u;
    ProbeUpdater updater(*context_, s, g, o);
    updater.update();
    updater.update();
    results[run].assign(updater.volume().probes.data(), updater.volume().probes.data() + g.count() * 27);
  }
  EXPECT_EQ(results[0], results[1]);
  EXPECT_NE(results[0], results[2]);
  for (float v : results[0]) EXPECT_TRUE(std::isfinite(v));
}

TEST_F(Updater, ProbeInsideClosedWallIsInactive) {
  // builtin:closed-box: inner room [-1, 1]³, outer shell [-1.2, 1.2]³. A probe between them sees
  // only back faces; one in the room and one outside see front faces.
  Scene s;
  std::string error;
  ASSERT_TRUE(scene::makeBuiltinScene("closed-box", 0.0f, s, error)) << error;
  ProbeGrid g;
  g = ProbeGrid{{5, 1, 1}, {{0.0f, 0.0f, 0.0f}, {1.6f, 0.0f, 0.0f}}};  // x = 0, 0.4, 0.8, 1.2 (on the outer face: skip), 1.6
  UpdaterOptions o;
  o.samplesPerProbe = 64;
  o.surfaceProbesOnly = false;  // probe 4 lights no surface (the shell's face lies on probe 3's plane): idle
  ProbeUpdater updater(*context_, s, g, o);
  EXPECT_EQ(updater.volume().active.data()[0], 1);  // room centre
  EXPECT_EQ(updater.volume().active.data()[2], 1);  // inside the room near the wall
  EXPECT_EQ(updater.volume().active.data()[4], 1);  // outside the box
  ProbeGrid wall = singleProbe({1.1f, 0.3f, -0.2f});
  ProbeUpdater inWall(*context_, s, wall, o);
  EXPECT_EQ(inWall.volume().active.data()[0], 0);
  const UpdateStats stats = inWall.update();
  EXPECT_EQ(stats.paths, 0u);  // inactive probes get no rays
  for (int i = 0; i < 27; ++i) EXPECT_EQ(inWall.volume().probes.data()[i], 0.0f);
}

TEST_F(Updater, MovingLightIsFollowed) {
  // builtin:cornell with the light moved half a turn: probes converge to the new lighting, and the
  // probe nearer the new light position brightens.
  Scene a, b;
  std::string error;
  ASSERT_TRUE(scene::makeBuiltinScene("cornell", 0.0f, a, error));   // light at +x
  ASSERT_TRUE(scene::makeBuiltinScene("cornell", 0.5f, b, error));   // light at −x
  ProbeGrid g;
  g = ProbeGrid{{2, 1, 1}, {{-0.7f, 1.5f, 0.5f}, {0.7f, 1.5f, 0.5f}}};
  UpdaterOptions o;
  o.samplesPerProbe = 256;
  o.minBlendWeight = 0.5f;
  ProbeUpdater updater(*context_, a, g, o);
  for (int u = 0; u < 4; ++u) updater.update();
  const float leftBefore = updater.volume().probes.data()[0], rightBefore = updater.volume().probes.data()[27];
  EXPECT_GT(rightBefore, leftBefore);
  updater.setScene(b);
  for (int u = 0; u < 6; ++u) updater.update();
  const float leftAfter = updater.volume().probes.data()[0], rightAfter = updater.volume().probes.data()[27];
  EXPECT_GT(leftAfter, rightAfter);
  EXPECT_GT(leftAfter, leftBefore);
}

}  // namespace
}  // namespace probecast::renderer

#include "cpu_path_tracer.h"

namespace probecast::renderer {
namespace {

// builtin:cornell, 3 × 3 × 3 probes over the room: the small grid of the blending tests.
ProbeGrid cornellGrid(const Scene& s) { return sceneGrid(s, {3, 3, 3}); }

Scene cornellAt(float t) {
  Scene s;
  std::string error;
  EXPECT_TRUE(scene::makeBuiltinScene("cornell", t, s, error)) << error;
  return s;
}

// A converged volume: a plain mean (no rejection) of 16 updates of 2048 paths per probe.
std::vector<float> convergedProbes(VulkanContext& context, const Scene& s, const ProbeGrid& g) {
  UpdaterOptions o;
  o.samplesPerProbe = 2048;
  o.rejectSigmas = 0.0f;
  o.seed = 77;
  ProbeUpdater u(context, s, g, o);
  for (int k = 0; k < 16; ++k) u.update();
  return u.volume().probes;
}

// RMSE of the luminance of c00 against `reference` over the active probes, and the mean noise the
// updater states for them.
std::pair<double, double> dcError(const ProbeVolume& v, const std::vector<float>& reference) {
  double se = 0, noise = 0;
  int n = 0;
  for (uint32_t p = 0; p < v.count(); ++p) {
    if (!v.active[p]) continue;
    const float* a = v.probes.data() + p * 27;
    const float* b = reference.data() + p * 27;
    const double d = 0.2126 * (a[0] - b[0]) + 0.7152 * (a[1] - b[1]) + 0.0722 * (a[2] - b[2]);
    se += d * d;
    noise += v.noise.empty() ? 0.0 : v.noise[p] * v.noise[p];
    ++n;
  }
  return {std::sqrt(se / n), std::sqrt(noise / n)};
}

TEST_F(Updater, StillProbeErrorFallsAsOneOverRootN) {
  // The light still: with w = 1/n and no false restarts the history is the mean of n updates, so
  // its error against a converged volume (32× the paths of the longest run) halves every time n
  // quadruples, and the standard error the updater states tracks the error it actually has.
  const Scene s = cornellAt(0.0f);
  const ProbeGrid g = cornellGrid(s);
  const std::vector<float> reference = convergedProbes(*context_, s, g);
  UpdaterOptions o;
  o.samplesPerProbe = 32;
  // The default blend (w_min 0): a true mean until the history restarts.
  ProbeUpdater u(*context_, s, g, o);
  std::vector<std::pair<double, double>> at;
  uint32_t restarts = 0;
  for (uint32_t n = 1; n <= 64; ++n) {
    restarts += u.update().restartedProbes;
    if (n == 4 || n == 16 || n == 64) at.push_back(dcError(u.volume(), reference));
  }
  for (size_t k = 0; k + 1 < at.size(); ++k) {
    const double ratio = at[k].first / at[k + 1].first;  // 2 for 1/√n
    EXPECT_GT(ratio, 1.5) << "n = " << (4 << (2 * k));
    EXPECT_LT(ratio, 2.7) << "n = " << (4 << (2 * k));
  }
  EXPECT_LT(restarts, g.count() / 3) << "restarts with the light still";
  for (auto [e, noise] : at) {
    EXPECT_GT(noise, 0.5 * e);
    EXPECT_LT(noise, 2.0 * e);
  }
}

TEST_F(Updater, HistoryRejectionFollowsALightJumpWithinTwoUpdates) {
  // Converged with the light at t = 0, then it jumps to t = 0.5: a probe whose estimate disagrees
  // holds it back, and restarts when the next one confirms, so two updates later the volume is
  // about as close to the new lighting as a fresh updater after two updates — not 16/18 the old
  // lighting, as a plain running mean would be.
  const Scene before = cornellAt(0.0f), after = cornellAt(0.5f);
  const ProbeGrid g = cornellGrid(before);
  const std::vector<float> reference = convergedProbes(*context_, after, g);
  UpdaterOptions o;
  o.samplesPerProbe = 256;
  ProbeUpdater u(*context_, before, g, o);
  for (int k = 0; k < 16; ++k) u.update();
  u.setScene(after);
  uint32_t restarted = 0, active = 0;
  for (int k = 0; k < 2; ++k) {
    const UpdateStats st = u.update();
    restarted += st.restartedProbes;
    active = st.activeProbes;
  }
  o.seed = 5;
  ProbeUpdater fresh(*context_, after, g, o);
  for (int k = 0; k < 2; ++k) fresh.update();
  const double jumped = bench::irradianceRmseRel(u.volume().probes.data(), reference.data(), u.volume().active.data(), g.count());
  const double fromScratch =
      bench::irradianceRmseRel(fresh.volume().probes.data(), reference.data(), fresh.volume().active.data(), g.count());
  EXPECT_LT(jumped, 1.5 * fromScratch);
  EXPECT_GT(restarted, active / 2);
}

// The adaptive rule (w_min 0) at 32 samples, with the given neighbour and change history caps.
UpdaterOptions adaptiveAt32Samples(float neighbourHistory, float changeHistory) {
  UpdaterOptions o;
  o.samplesPerProbe = 32;
  o.minBlendWeight = 0.0f;
  o.neighbourHistory = neighbourHistory;
  o.changeHistory = changeHistory;
  return o;
}

TEST_F(Updater, RestartsShortenTheirNeighboursHistorySoTheVolumeFollowsAJumpSooner) {
  // After a light jump, probes whose change is below what one update can tell from noise keep
  // averaging the old light into the new; when restarts around them (not lone ones) cap their
  // history (UpdaterOptions::neighbourHistory) they follow sooner. Same seeds, same rays: only
  // the rule differs (4³ probes, 32 samples, w_min 0).
  const Scene before = cornellAt(0.0f), after = cornellAt(0.5f);
  const ProbeGrid g = sceneGrid(before, {4, 4, 4});
  const std::vector<float> reference = convergedProbes(*context_, after, g);
  std::vector<double> error;
  for (float cap : {0.0f, 8.0f}) {
    ProbeUpdater u(*context_, before, g, adaptiveAt32Samples(cap, 0.0f));  // the neighbour rule alone
    for (int k = 0; k < 24; ++k) u.update();
    u.setScene(after);
    for (int k = 0; k < 24; ++k) u.update();
    error.push_back(bench::irradianceRmseRel(u.volume().probes.data(), reference.data(), u.volume().active.data(),
                                             g.count()));
  }
  std::printf("irradiance error 24 updates after the jump: %.4f without, %.4f with neighbour history 8\n", error[0],
              error[1]);
  EXPECT_LT(error[1], 0.85 * error[0]);  // measured on lavapipe: 0.143 against 0.189
}

TEST_F(Updater, AMovingLightIsFollowedWhenTheSceneSaysItChanged) {
  // The light moves by t = 0.01 an update for 16 updates, less than one update's noise at 32
  // samples for most probes, so few restart and a plain mean keeps the light's whole path. With
  // UpdaterOptions::changeHistory every setScene that moves it caps the histories at 8 updates:
  // 8 updates after it stops, the volume is nearer the light where it stopped (4³ probes, w_min 0,
  // same seeds and rays).
  const Scene first = cornellAt(0.0f);
  const ProbeGrid g = sceneGrid(first, {4, 4, 4});
  const float last = 0.16f;
  const std::vector<float> reference = convergedProbes(*context_, cornellAt(last), g);
  std::vector<double> error;
  for (float cap : {0.0f, 8.0f}) {
    ProbeUpdater u(*context_, first, g, adaptiveAt32Samples(UpdaterOptions{}.neighbourHistory, cap));
    for (int k = 0; k < 24; ++k) u.update();
    for (int k = 1; k <= 16; ++k) {
      u.setScene(cornellAt(last * static_cast<float>(k) / 16.0f));
      u.update();
    }
    for (int k = 0; k < 8; ++k) u.update();
    error.push_back(bench::irradianceRmseRel(u.volume().probes.data(), reference.data(), u.volume().active.data(),
                                             g.count()));
  }
  std::printf("irradiance error 8 updates after the light stops: %.4f without, %.4f with change history 8\n",
              error[0], error[1]);
  EXPECT_LT(error[1], 0.85 * error[0]);
}

TEST_F(Updater, StillUpdatesCountFromTheLastChangeOfTheScene) {
  // ProbeVolume::stillUpdates: every active probe counts the updates since setScene last changed
  // what lights it (restarts, which noise causes too, do not reset it); inactive probes hold 0.
  // Setting an equal scene is no change.
  const Scene s = cornellAt(0.0f);
  const ProbeGrid g = sceneGrid(s, {4, 4, 4});
  ProbeUpdater u(*context_, s, g, adaptiveAt32Samples(8.0f, 8.0f));
  const auto expectAll = [&](uint32_t updates, const char* when) {
    const ProbeVolume& v = u.volume();
    ASSERT_EQ(v.stillUpdates.size(), g.count()) << when;
    uint32_t active = 0;
    for (uint32_t p = 0; p < g.count(); ++p) {
      EXPECT_EQ(v.stillUpdates[p], v.active[p] ? updates : 0u) << when << ", probe " << p;
      active += v.active[p];
    }
    EXPECT_GT(active, 0u);
  };
  uint32_t restarts = 0;
  for (int k = 0; k < 24; ++k) restarts += u.update().restartedProbes;
  expectAll(24, "24 still updates");
  u.setScene(cornellAt(0.0f));
  u.update();
  expectAll(25, "the same scene set again");
  u.setScene(cornellAt(0.5f));  // the light jumps
  for (int k = 0; k < 3; ++k) restarts += u.update().restartedProbes;
  expectAll(3, "3 updates after the light jumped");
  EXPECT_GT(restarts, 0u);  // restarts happened, and reset nothing
  std::string error;
  EXPECT_TRUE(checkProbeVolume(u.volume(), error)) << error;
}

TEST_F(Updater, SettingTheSameSceneAgainChangesNothing) {
  // setScene with a scene equal to the one set is no change: no history is capped, and the volume
  // is bit for bit that of an updater left alone (same seed).
  const Scene s = cornellAt(0.0f);
  const ProbeGrid g = sceneGrid(s, {3, 3, 3});
  UpdaterOptions o;
  o.samplesPerProbe = 32;
  o.minBlendWeight = 0.0f;
  ProbeUpdater alone(*context_, s, g, o), reset(*context_, s, g, o);
  for (int k = 0; k < 12; ++k) {
    alone.update();
    reset.setScene(cornellAt(0.0f));
    reset.update();
  }
  EXPECT_EQ(alone.volume().probes, reset.volume().probes);
  EXPECT_EQ(alone.volume().noise, reset.volume().noise);
}

TEST_F(Updater, ChangedTexturesReachTheTracer) {
  // Every material of the box takes its base colour from one 1×1 texture; setScene turns it from
  // white to dark grey, positions, indices and materials unchanged. 16 updates later the volume is
  // that of a fresh updater of the dark box (up to noise), far from the white box's. (Before, a
  // setScene without new geometry uploaded only lights and materials: the tracer kept the white
  // texture, and a material naming a texture the device lacked read past the texture table.)
  Scene white = cornellAt(0.0f);
  white.textures = {scene::Texture{1, 1, {255, 255, 255, 255}}};
  for (scene::Material& m : white.materials) m.baseColorTexture = 0;
  Scene dark = white;
  dark.textures[0].rgba = {40, 40, 40, 255};
  const ProbeGrid g = sceneGrid(white, {3, 3, 3});
  UpdaterOptions o;
  o.samplesPerProbe = 64;
  ProbeUpdater fresh(*context_, dark, g, o), u(*context_, white, g, o);
  for (int k = 0; k < 16; ++k) fresh.update();
  for (int k = 0; k < 8; ++k) u.update();
  const std::vector<float> whiteProbes = u.volume().probes;
  u.setScene(dark);
  for (int k = 0; k < 16; ++k) u.update();
  const std::vector<float>& darkProbes = fresh.volume().probes;
  const uint8_t* active = fresh.volume().active.data();
  const double before = bench::irradianceRmseRel(whiteProbes.data(), darkProbes.data(), active, g.count());
  const double after = bench::irradianceRmseRel(u.volume().probes.data(), darkProbes.data(), active, g.count());
  std::printf("against a fresh dark box: white %.4f, after the texture changed %.4f\n", before, after);
  EXPECT_GT(before, 0.2);
  EXPECT_LT(after, 0.25 * before);
}

TEST_F(Updater, StillVolumeIsRarelyResent) {
  // The light still: what changes from update to update is noise the updater states, so an
  // encoder with a noise scale makes new brick versions only now and then, while one without
  // re-sends the noise above its dead-zone every frame (4³ probes: one brick). Not nothing: the
  // threshold c·σ shrinks as 1/√n while the mean wanders, so a probe is re-sent each time n has
  // grown by a factor of about 1 + c² — ever rarer, never never.
  const Scene s = cornellAt(0.0f);
  const ProbeGrid g = sceneGrid(s, {4, 4, 4});
  UpdaterOptions o;
  o.samplesPerProbe = 32;
  // The default blend (w_min 0): a true mean, whose stated noise keeps falling.
  ProbeUpdater u(*context_, s, g, o);
  const StreamLayout layout = streamLayoutFor(g, Representation::Zh3, 4);
  EncoderOptions withNoise;
  withNoise.deadzone = 1;
  withNoise.noiseScale = 2.0f;
  EncoderOptions plain;
  plain.deadzone = 1;
  StreamEncoder noiseAware(layout, withNoise), always(layout, plain);
  uint32_t versions = 0, plainVersions = 0;
  for (int k = 0; k < 96; ++k) {
    u.update();
    const uint32_t a = noiseAware.update(u.volume().probes.data(), u.volume().active.data(), u.volume().noise.data());
    const uint32_t b = always.update(u.volume().probes.data(), u.volume().active.data());
    if (k >= 64) {
      versions += a;
      plainVersions += b;
    }
  }
  EXPECT_LE(versions, 12u) << "bricks re-sent over the last 32 still updates";
  EXPECT_EQ(plainVersions, 32u);
}

TEST_F(Updater, CornellProbesMatchCpuReference) {
  // GPU: 32 updates × 2048 paths with w_min = 0 (the plain mean of 65k paths), no clamp.
  // CPU: 65k independent paths (uniform directions, cosine continuation). Both estimate the same
  // integral; the point light close to the ceiling makes paths noisy: four CPU seeds at 65k paths
  // spread ±0.5 % in c00, so the tolerance (3 % of c00, 5 % for the other coefficients) is ≥ 4σ.
  scene::Scene s;
  std::string error;
  ASSERT_TRUE(scene::makeBuiltinScene("cornell", 0.0f, s, error));
  ProbeGrid g;
  g = ProbeGrid{{2, 1, 2}, {{-0.7f, 1.3f, -0.6f}, {0.7f, 1.8f, 0.7f}}};  // above both boxes (the tall one ends at y = 1.2)
  UpdaterOptions o;
  o.samplesPerProbe = 2048;
  o.minBlendWeight = 0.0f;
  o.rejectSigmas = 0.0f;  // the plain mean
  o.indirectClamp = 0.0f;
  ProbeUpdater updater(*context_, s, g, o);
  for (int u = 0; u < 32; ++u) updater.update();
  for (uint32_t p = 0; p < g.count(); ++p) {
    ASSERT_EQ(updater.volume().active.data()[p], 1) << p;
    test::CpuTraceOptions co;
    co.samples = 65536;
    co.seed = 100 + p;
    float pos[3];
    g.position(p, pos);
    const auto ref = test::cpuTraceProbe(s, glm::vec3(pos[0], pos[1], pos[2]), co);
    const float* gpu = updater.volume().probes.data() + p * 27;
    for (int c = 0; c < 3; ++c) {
      const double dc = ref[c];
      ASSERT_GT(dc, 0.0);
      EXPECT_NEAR(gpu[c], dc, 0.03 * dc) << "probe " << p << " channel " << c;
      for (int i = 1; i < 9; ++i)
        EXPECT_NEAR(gpu[i * 3 + c], ref[i * 3 + c], 0.05 * dc) << "probe " << p << " coefficient " << i << " channel " << c;
    }
  }
}

// builtin:thin-wall's wall fills x in [-0.1, 0.1] (the full height and depth of the room; the light
// is at x = 1.2). Three probes along x at the scene grid's spacing (4/9 m, as --grid 9,5,5): the
// middle one sits in the wall, where classification alone switches it off.
ProbeGrid thinWallRow() { return ProbeGrid{{3, 1, 1}, {{-4.0f / 9.0f, 1.0f, 0.1f}, {4.0f / 9.0f, 1.0f, 0.1f}}}; }

TEST_F(Updater, RelocationKeepsAProbeInAThinWallUseful) {
  Scene s;
  std::string error;
  ASSERT_TRUE(scene::makeBuiltinScene("thin-wall", 0.0f, s, error)) << error;
  const ProbeGrid g = thinWallRow();
  UpdaterOptions o;
  o.samplesPerProbe = 1024;
  o.minBlendWeight = 0.0f;
  o.rejectSigmas = 0.0f;
  o.indirectClamp = 0.0f;
  o.relocate = false;
  {
    ProbeUpdater fixed(*context_, s, g, o);
    EXPECT_EQ(fixed.volume().active[1], 0);  // in the wall: off
    EXPECT_TRUE(fixed.volume().offsets.empty());
  }
  o.relocate = true;
  ProbeUpdater updater(*context_, s, g, o);
  const ProbeVolume& v = updater.volume();
  ASSERT_EQ(v.active[1], 1) << "the probe in the wall was not moved out of it";
  EXPECT_EQ(updater.classifyStats().insideAtGrid, 1u);
  EXPECT_EQ(updater.classifyStats().inactive, 0u);
  ASSERT_EQ(v.offsets.size(), 9u);
  const float dx = v.offsets[3];
  RecordProperty("offset_x_m", std::to_string(dx));
  EXPECT_GT(std::fabs(dx), 0.1f);                      // out of the wall
  EXPECT_LE(std::fabs(dx), 0.45f * (4.0f / 9.0f));     // within its allowed box
  std::string why;
  EXPECT_TRUE(checkProbeVolume(v, why)) << why;
  for (int u = 0; u < 16; ++u) updater.update();
  // Against an independent tracer at the moved position: on the lit side the radiance agrees (3 %
  // of c00, as CornellProbesMatchCpuReference); on the dark side both see next to nothing (under
  // 1 % of the lit neighbour).
  float at[3];
  g.position(1, at);
  const glm::vec3 moved(at[0] + dx, at[1] + v.offsets[4], at[2] + v.offsets[5]);
  test::CpuTraceOptions co;
  co.samples = 32768;
  co.seed = 7;
  const auto ref = test::cpuTraceProbe(s, moved, co);
  const float* gpu = v.probes.data() + 27;
  const float lit = v.probes[2 * 27 + 1];  // the lit neighbour's green c00
  ASSERT_GT(lit, 0.0f);
  for (int c = 0; c < 3; ++c) {
    if (dx > 0.0f) {
      ASSERT_GT(ref[c], 0.05 * lit);
      EXPECT_NEAR(gpu[c], ref[c], 0.03 * ref[c]) << "channel " << c;
    } else {
      EXPECT_LT(gpu[c], 0.01f * lit) << "channel " << c;
      EXPECT_LT(ref[c], 0.01 * lit) << "channel " << c;
    }
  }
}

TEST_F(Updater, OffsetsStayWithin45PercentOfACellAndFreeProbesNeverMove) {
  Scene s;
  std::string error;
  ASSERT_TRUE(scene::makeBuiltinScene("cornell", 0.0f, s, error)) << error;
  const ProbeGrid g = sceneGrid(s, {8, 8, 8});
  UpdaterOptions o;
  o.samplesPerProbe = 32;
  o.surfaceProbesOnly = false;  // relocation alone: the probes far from every surface are classified too
  ProbeUpdater updater(*context_, s, g, o);
  const ProbeVolume& v = updater.volume();
  const ClassifyStats& st = updater.classifyStats();
  EXPECT_EQ(st.idle, 0u);
  EXPECT_GT(st.moved, 0u);  // the boxes hold probes, and some sit near their faces
  EXPECT_LT(st.inactive, st.insideAtGrid);
  ASSERT_EQ(v.offsets.size(), g.count() * 3u);
  for (uint32_t p = 0; p < g.count(); ++p)
    for (int a = 0; a < 3; ++a)
      EXPECT_LE(std::fabs(v.offsets[p * 3 + a]), 0.45f * probeCellSize(g, a) * (1.0f + 1e-6f)) << p << " " << a;
  EXPECT_LE(st.maxOffsetCells, 0.45 + 1e-6);
  std::string why;
  EXPECT_TRUE(checkProbeVolume(v, why)) << why;
  // The probes nearest the room's centre are far from every surface (the boxes end below them).
  for (uint32_t x : {3u, 4u})
    for (uint32_t y : {5u, 6u})
      for (uint32_t z : {3u, 4u}) {
        const uint32_t p = x + 8 * (y + 8 * z);
        EXPECT_EQ(v.active[p], 1);
        for (int a = 0; a < 3; ++a) EXPECT_EQ(v.offsets[p * 3 + a], 0.0f) << p;
      }
  // And in the thin-wall row, the probes 0.34 m from the wall (clearance 0.2 × 0.44 m) stay put.
  Scene wall;
  ASSERT_TRUE(scene::makeBuiltinScene("thin-wall", 0.0f, wall, error)) << error;
  ProbeUpdater row(*context_, wall, thinWallRow(), o);
  ASSERT_EQ(row.volume().offsets.size(), 9u);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(row.volume().offsets[a], 0.0f);
    EXPECT_EQ(row.volume().offsets[6 + a], 0.0f);
  }
}

}  // namespace
}  // namespace probecast::renderer

namespace probecast::renderer {
namespace {

TEST_F(Updater, ProbesNextToMovedGeometryFollowItWithinTwoUpdates) {
  // The animated Cornell box's cube slides 1.2 m between 0 s and 2 s. setScene with the moved
  // vertices classifies again and restarts only the probes within a cell of moved triangles (the
  // rest keep their history; the offsets stay, so a stream keeps its epoch). Two updates later the
  // probes whose light the move changed are as near the converged light at 2 s as two updates of
  // a fresh updater at 2 s, while the light they held before is far from it.
  const std::string path = std::string(PROBECAST_TEST_DATA) + "/scenes/cornell-animated/cornell-animated.gltf";
  Scene at0, at2;
  std::string error;
  ASSERT_TRUE(scene::loadScene(path, 0.0, at0, error)) << error;
  ASSERT_TRUE(scene::loadScene(path, 2.0, at2, error)) << error;
  const ProbeGrid g = sceneGrid(at0, {8, 8, 8});
  UpdaterOptions o;
  o.samplesPerProbe = 256;
  o.relocate = false;  // the same probe positions in every volume compared
  UpdaterOptions ro = o;
  ro.samplesPerProbe = 1024;
  ro.rejectSigmas = 0.0f;
  ro.seed = 77;
  ProbeUpdater converged(*context_, at2, g, ro);
  for (int k = 0; k < 8; ++k) converged.update();
  const std::vector<float> reference = converged.volume().probes;

  ProbeUpdater u(*context_, at0, g, o);
  for (int k = 0; k < 8; ++k) u.update();
  const std::vector<float> before = u.volume().probes;
  u.setScene(at2);
  EXPECT_TRUE(u.classifyStats().partial);
  EXPECT_GT(u.classifyStats().nearMoved, 0u);
  EXPECT_LT(u.classifyStats().nearMoved, g.count() / 2);  // not the whole volume
  // The cube's and the arm's triangles were refitted in place; nothing was built from scratch again.
  EXPECT_EQ(u.geometryStats().builds, 1u);
  EXPECT_GE(u.geometryStats().refits, 1u);
  for (int k = 0; k < 2; ++k) u.update();
  o.seed = 9;
  ProbeUpdater fresh(*context_, at2, g, o);
  for (int k = 0; k < 2; ++k) fresh.update();

  // The probes whose irradiance the move changed by more than a third.
  std::vector<uint8_t> changed(g.count(), 0);
  uint32_t count = 0;
  for (uint32_t p = 0; p < g.count(); ++p) {
    if (!u.volume().active[p] || !fresh.volume().active[p]) continue;
    const uint8_t one = 1;
    changed[p] = bench::irradianceRmseRel(before.data() + 27 * p, reference.data() + 27 * p, &one, 1) > 0.33;
    count += changed[p];
  }
  ASSERT_GE(count, 3u);
  const double followed = bench::irradianceRmseRel(u.volume().probes.data(), reference.data(), changed.data(), g.count());
  const double fromScratch =
      bench::irradianceRmseRel(fresh.volume().probes.data(), reference.data(), changed.data(), g.count());
  const double stale = bench::irradianceRmseRel(before.data(), reference.data(), changed.data(), g.count());
  std::printf("irradiance error where the move changed the light (%u probes; %u classified again): %.4f two updates "
              "after, %.4f fresh, %.4f before\n",
              count, u.classifyStats().nearMoved, followed, fromScratch, stale);
  EXPECT_LT(followed, 1.5 * fromScratch + 0.01);
  EXPECT_GT(stale, 2.0 * followed);
}

}  // namespace
}  // namespace probecast::renderer
