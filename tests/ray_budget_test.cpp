// The per-update ray budget of the probe updater (UpdaterOptions::raysPerUpdate): probes in view
// get more samples, every probe gets some, a probe left without rays keeps its history, and no
// budget is the plain update bit for bit.
#include <gtest/gtest.h>

#include <cstring>

#include "probecast/renderer/probe_updater.h"
#include "probecast/scene/scene.h"

namespace probecast::renderer {
namespace {

class RayBudget : public ::testing::Test {
 protected:
  void SetUp() override {
    ContextOptions options;
    options.validation = true;
    context_ = std::make_unique<VulkanContext>(options);
  }
  void TearDown() override { EXPECT_EQ(context_->validationMessages(), 0u) << "Vulkan validation messages"; }
  std::unique_ptr<VulkanContext> context_;
};

scene::Scene cornell(float t) {
  scene::Scene s;
  std::string error;
  EXPECT_TRUE(scene::makeBuiltinScene("cornell", t, s, error)) << error;
  return s;
}

// FNV-1a over the bytes of the floats.
uint64_t fnv(const std::vector<float>& v) {
  uint64_t h = 1469598103934665603ull;
  for (float f : v) {
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    for (int b = 0; b < 4; ++b) h = (h ^ ((bits >> (8 * b)) & 0xffu)) * 1099511628211ull;
  }
  return h;
}

TEST_F(RayBudget, NoBudgetIsThePlainUpdateBitForBit) {
  // Pinned from the updater before it had a budget: 3³ probes of builtin:cornell, 64 spp, 4
  // updates with the light moved after the second (a restart), default blending.
  UpdaterOptions o;
  o.samplesPerProbe = 64;
  ProbeUpdater u(*context_, cornell(0.0f), sceneGrid(cornell(0.0f), {3, 3, 3}), o);
  u.update();
  u.update();
  u.setScene(cornell(0.5f));
  u.update();
  u.update();
  EXPECT_EQ(fnv(u.volume().probes), 0xe1e00875c72e841bull);
  EXPECT_EQ(fnv(u.volume().noise), 0x18eba08be0017cb4ull);
  for (uint32_t n : u.lastSamples()) EXPECT_EQ(n, 64u);
}

}  // namespace
}  // namespace probecast::renderer
