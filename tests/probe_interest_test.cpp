// What the views show of each probe (session/probe_interest.h): probeViewFootprints on a wall seen
// straight on, behind an occluder, from inside the scene, and with views that see nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "probecast/session/probe_interest.h"

namespace probecast::session {
namespace {

View toView(const glm::mat4& viewProj, const glm::vec3& eye) {
  View v{};
  std::memcpy(v.viewProj, &viewProj[0][0], sizeof v.viewProj);
  v.eye[0] = eye.x;
  v.eye[1] = eye.y;
  v.eye[2] = eye.z;
  return v;
}

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

}  // namespace
}  // namespace probecast::session
