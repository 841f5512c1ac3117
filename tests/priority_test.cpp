// Brick priority against hand-made frusta (docs/CODEC.md §6).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "probecast/codec/priority.h"

namespace probecast {
namespace {

// Orthographic view looking down −z from `eye`, covering x, y in [cx−h, cx+h] and depth [0, far]:
// clip = (x − cx)/h, (y − cy)/h, (eye.z − z)/far, w = 1 (column-major).
View orthoView(float cx, float cy, float eyeZ, float h, float far) {
  View v{};
  float* m = v.viewProj;
  m[0] = 1.0f / h;
  m[5] = 1.0f / h;
  m[10] = -1.0f / far;
  m[12] = -cx / h;
  m[13] = -cy / h;
  m[14] = eyeZ / far;
  m[15] = 1.0f;
  v.eye[0] = cx;
  v.eye[1] = cy;
  v.eye[2] = eyeZ;
  return v;
}

StreamLayout row() {
  // 16 × 4 × 4 probes in bricks of 4: four bricks along x.
  StreamLayout l;
  l.grid[0] = 16;
  l.grid[1] = 4;
  l.grid[2] = 4;
  l.brickDim = 4;
  return l;
}

GridBounds rowBounds() {
  GridBounds b;
  b.min[0] = 0;
  b.min[1] = 0;
  b.min[2] = 0;
  b.max[0] = 15;
  b.max[1] = 3;
  b.max[2] = 3;
  return b;
}

TEST(Priority, FrustumTestIsConservativeAndCulls) {
  const View v = orthoView(2, 1.5f, 10, 2, 20);  // sees x in [0, 4], y in [−0.5, 3.5], z in [−10, 10]
  const float inMin[3] = {1, 1, 1}, inMax[3] = {2, 2, 2};
  const float outMin[3] = {6, 1, 1}, outMax[3] = {7, 2, 2};
  const float straddleMin[3] = {3.5f, 1, 1}, straddleMax[3] = {8, 2, 2};
  const float behindMin[3] = {1, 1, 11}, behindMax[3] = {2, 2, 12};
  EXPECT_TRUE(boxIntersectsFrustum(v.viewProj, inMin, inMax));
  EXPECT_FALSE(boxIntersectsFrustum(v.viewProj, outMin, outMax));
  EXPECT_TRUE(boxIntersectsFrustum(v.viewProj, straddleMin, straddleMax));
  EXPECT_FALSE(boxIntersectsFrustum(v.viewProj, behindMin, behindMax));
}

TEST(Priority, InfluenceBoxGrowsByOneCell) {
  float lo[3], hi[3];
  brickInfluenceBox(row(), rowBounds(), 1, lo, hi);  // probes x = 4..7
  EXPECT_FLOAT_EQ(lo[0], 3.0f);
  EXPECT_FLOAT_EQ(hi[0], 8.0f);
  EXPECT_FLOAT_EQ(lo[1], 0.0f);  // clipped to the grid
  EXPECT_FLOAT_EQ(hi[1], 3.0f);
}

TEST(Priority, VisibleThenNearThenFar) {
  // One view sees bricks 0 and 1 (x in [0, 8]); brick 0 is nearer the eye at x = 0.
  View v = orthoView(2.5f, 1.5f, 10, 4, 30);
  v.eye[0] = 0;
  std::vector<BrickCandidate> c(4, BrickCandidate{1.0f, 0, 100});
  std::vector<float> s(4);
  scoreBricks(row(), rowBounds(), std::span<const View>(&v, 1), c, PriorityParams{}, s.data());
  EXPECT_GT(s[0], s[1]);
  EXPECT_GT(s[1], s[2]);  // in view beats out of view
  EXPECT_GT(s[2], s[3]);  // both out of view: nearer wins
  EXPECT_GT(s[3], 0.0f);  // out of view still trickles
}

TEST(Priority, ManyViewsUnionAndUnchangedBricksScoreZero) {
  // A light-field array: two views, one over brick 0, one over brick 3.
  const View views[2] = {orthoView(1.5f, 1.5f, 10, 1, 30), orthoView(13.5f, 1.5f, 10, 1, 30)};
  std::vector<BrickCandidate> c(4, BrickCandidate{0.5f, 0, 100});
  c[0].change = 0.0f;  // already up to date
  std::vector<float> s(4);
  scoreBricks(row(), rowBounds(), views, c, PriorityParams{}, s.data());
  EXPECT_EQ(s[0], 0.0f);
  EXPECT_GT(s[3], s[1]);
  EXPECT_GT(s[3], s[2]);
}

TEST(Priority, AgePreventsStarvation) {
  const View v = orthoView(1.5f, 1.5f, 10, 1, 30);  // sees brick 0 only
  std::vector<BrickCandidate> c(4, BrickCandidate{1.0f, 0, 100});
  c[3].ageFrames = 400;
  std::vector<float> s(4);
  scoreBricks(row(), rowBounds(), std::span<const View>(&v, 1), c, PriorityParams{}, s.data());
  EXPECT_GT(s[3], s[0]);
}

TEST(Priority, SelectionRespectsBudget) {
  const std::vector<float> scores = {0.5f, 0.9f, 0.0f, 0.7f, 0.1f};
  std::vector<BrickCandidate> c(5);
  const uint32_t bytes[5] = {100, 300, 50, 250, 40};
  for (int i = 0; i < 5; ++i) c[i].bytes = bytes[i];
  std::vector<uint32_t> out(5);
  const size_t n = selectBricks(scores, c, 450, out.data());
  // 1 (300) fits; 3 (250) does not; 0 (100) fits; 4 (40) fits; 2 has nothing to send.
  ASSERT_EQ(n, 3u);
  EXPECT_EQ(out[0], 1u);
  EXPECT_EQ(out[1], 0u);
  EXPECT_EQ(out[2], 4u);
  EXPECT_EQ(selectBricks(scores, c, 0, out.data()), 0u);
}

}  // namespace
}  // namespace probecast
