// The producer's view weights reach its hub's encoder: with the noise rule, the probes that no
// subscriber's view shows are held longer (re-sent less often) than the same stream re-sends them
// when nobody has told the hub what they look at; the probes in view are not held back.
#include <gtest/gtest.h>

#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "probecast/renderer/probe_interest.h"
#include "probecast/session/probe_producer.h"
#include "view_test_support.h"
#include "vulkan_test_support.h"

namespace probecast {
namespace {

// A subscriber standing inside the box by the open front, looking at a patch of the right wall.
View rightWallView() {
  const glm::vec3 eye(0.4f, 1.0f, 0.8f);
  return test::toView(glm::perspectiveRH_ZO(0.9f, 1.0f, 0.05f, 10.0f) * glm::lookAt(eye, {1.0f, 1.0f, 0.6f}, {0, 1, 0}), eye);
}

TEST(ProducerViewWeights, ProbesNoViewShowsAreResentLessAndTheSeenOnesAreNot) {
  renderer::VulkanContext context(test::validatedContext());
  const scene::Scene s = test::builtinScene("cornell");
  const ProbeGrid grid = renderer::sceneGrid(s, {8, 8, 8});
  renderer::UpdaterOptions uo;
  uo.samplesPerProbe = 32;
  uo.seed = 3;
  uo.rejectSigmas = 4.0f;
  service::HubConfig hc = service::hubConfigFor(grid, Representation::Zh3, 4, 1);
  hc.encoder.noiseScale = 1.5f;
  const View view = rightWallView();
  // Which probes the view shows (what the producer works out, without the light).
  const std::vector<float> shown = renderer::probeViewFootprints(s, grid, {}, std::span<const View>(&view, 1));
  ASSERT_EQ(shown.size(), grid.count());

  constexpr int kUpdates = 48;
  // resent[withViews][probe]: updates whose reconstruction changed that probe.
  std::vector<uint32_t> resent[2];
  for (const bool withViews : {false, true}) {
    session::ProbeProducer producer(hc);
    producer.traceScene(context, "builtin:cornell", s, grid, uo, session::Animation{});
    const uint64_t id = producer.hub().addSubscriber(0, 0, {}, [] {});
    if (withViews) producer.hub().setViews(id, {view});
    resent[withViews].assign(grid.count(), 0);
    std::vector<float> before;
    for (int k = 0; k < kUpdates; ++k) {
      producer.step();
      const ProbeVolume held = producer.hub().reconstruction();
      if (!before.empty())
        for (uint32_t p = 0; p < grid.count(); ++p)
          resent[withViews][p] += std::memcmp(&held.probes[p * kProbeFloats], &before[p * kProbeFloats],
                                              kProbeFloats * sizeof(float)) != 0;
      before = held.probes;
    }
  }
  // The probes the view shows most: at least 1.5 × the mean of those it shows at all.
  double mean = 0.0;
  uint32_t shownCount = 0;
  for (float x : shown)
    if (x > 0.0f) mean += x, ++shownCount;
  mean /= shownCount;
  uint32_t unseen[2] = {0, 0}, most[2] = {0, 0}, mostCount = 0;
  for (uint32_t p = 0; p < grid.count(); ++p) {
    mostCount += shown[p] >= 1.5 * mean;
    for (int w = 0; w < 2; ++w) {
      if (shown[p] == 0.0f) unseen[w] += resent[w][p];
      if (shown[p] >= 1.5 * mean) most[w] += resent[w][p];
    }
  }
  ASSERT_GT(unseen[0], 0u);  // the stream without views re-sends them now and then
  EXPECT_LT(unseen[1], unseen[0] * 3 / 4) << unseen[1] << " against " << unseen[0];
  EXPECT_GE(most[1], most[0]) << most[1] << " against " << most[0];
}

}  // namespace
}  // namespace probecast
