// glTF animation: samplers against the glTF specification's formulas, node hierarchies, skins and
// morph targets against answers worked out by hand, the loop, the bounds, and malformed files.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gltf_test_files.h"
#include "probecast/scene/animation.h"
#include "probecast/scene/scene.h"

namespace probecast::scene {
namespace {

constexpr float kPi = 3.14159265358979f;

void expectNear(const glm::vec3& got, const glm::vec3& want, float tol = 1e-5f) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

AnimationSampler sampler(Interpolation i, std::vector<float> input, std::vector<float> output, uint32_t width) {
  AnimationSampler s;
  s.interpolation = i;
  s.input = std::move(input);
  s.output = std::move(output);
  s.width = width;
  return s;
}

TEST(AnimationSampler, LinearInterpolatesAndHoldsOutsideTheKeys) {
  const AnimationSampler s = sampler(Interpolation::Linear, {0.0f, 2.0f}, {0, 0, 0, 2, 4, 6}, 3);
  float v[3];
  sampleAnimation(s, 0.5f, false, v);
  expectNear({v[0], v[1], v[2]}, {0.5f, 1.0f, 1.5f});
  sampleAnimation(s, -1.0f, false, v);
  expectNear({v[0], v[1], v[2]}, {0, 0, 0});
  sampleAnimation(s, 9.0f, false, v);
  expectNear({v[0], v[1], v[2]}, {2, 4, 6});
}

TEST(AnimationSampler, StepHoldsEachKeyUntilTheNext) {
  const AnimationSampler s = sampler(Interpolation::Step, {0.0f, 1.0f, 2.0f}, {1, 2, 3}, 1);
  float v;
  sampleAnimation(s, 0.99f, false, &v);
  EXPECT_EQ(v, 1.0f);
  sampleAnimation(s, 1.0f, false, &v);
  EXPECT_EQ(v, 2.0f);
  sampleAnimation(s, 1.5f, false, &v);
  EXPECT_EQ(v, 2.0f);
}

TEST(AnimationSampler, CubicSplineIsTheSpecificationsHermiteForm) {
  // Keys at 1 s and 3 s: (in-tangent, value, out-tangent) = (0, 1, 2) and (-1, 5, 0). With
  // td = 2 and s = (t - 1) / 2: p = (2s³-3s²+1)·1 + td(s³-2s²+s)·2 + (-2s³+3s²)·5 + td(s³-s²)·(-1).
  const AnimationSampler s = sampler(Interpolation::CubicSpline, {1.0f, 3.0f}, {0, 1, 2, -1, 5, 0}, 1);
  float v;
  sampleAnimation(s, 2.0f, false, &v);  // s = 0.5: 0.5 + 0.5 + 2.5 + 0.25
  EXPECT_NEAR(v, 3.75f, 1e-5f);
  sampleAnimation(s, 1.5f, false, &v);  // s = 0.25: 0.84375 + 0.5625 + 0.78125 + 0.09375
  EXPECT_NEAR(v, 2.28125f, 1e-5f);
  sampleAnimation(s, 1.0f, false, &v);  // at a key: its value, not a tangent
  EXPECT_EQ(v, 1.0f);
  sampleAnimation(s, 3.0f, false, &v);
  EXPECT_EQ(v, 5.0f);
}

TEST(AnimationSampler, LinearRotationsAreSlerpAlongTheShorterArc) {
  const float h = std::sin(kPi / 4), c = std::cos(kPi / 4);  // 90° about +Y: (0, sin 45°, 0, cos 45°)
  const AnimationSampler s = sampler(Interpolation::Linear, {0.0f, 1.0f}, {0, 0, 0, 1, 0, h, 0, c}, 4);
  float q[4];
  sampleAnimation(s, 1.0f / 3.0f, true, q);  // 30° about +Y, not the normalised chord
  EXPECT_NEAR(q[1], std::sin(kPi / 12), 1e-5f);
  EXPECT_NEAR(q[3], std::cos(kPi / 12), 1e-5f);
  EXPECT_NEAR(q[0], 0.0f, 1e-6f);
  // The same rotation written as -q: still the 30° on the way, not the long way round.
  const AnimationSampler neg = sampler(Interpolation::Linear, {0.0f, 1.0f}, {0, 0, 0, 1, 0, -h, 0, -c}, 4);
  sampleAnimation(neg, 1.0f / 3.0f, true, q);
  EXPECT_NEAR(std::fabs(q[1]), std::sin(kPi / 12), 1e-5f);
  EXPECT_NEAR(std::fabs(q[3]), std::cos(kPi / 12), 1e-5f);
  // CUBICSPLINE rotations come out unit length.
  const AnimationSampler cubic =
      sampler(Interpolation::CubicSpline, {0.0f, 1.0f}, {0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, h, 0, c, 0, 0, 0, 0}, 4);
  sampleAnimation(cubic, 0.5f, true, q);
  EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0f, 1e-5f);
}

// A glTF file with a .bin beside it, built accessor by accessor.
struct RigFile {
  std::string bin, views, accessors;
  int count = 0;
  int add(const void* data, size_t bytes, int componentType, size_t elements, const char* type) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t offset = bin.size();
    bin.append(static_cast<const char*>(data), bytes);
    views += (count ? "," : "") + std::string("{\"buffer\":0,\"byteOffset\":") + std::to_string(offset) +
             ",\"byteLength\":" + std::to_string(bytes) + "}";
    accessors += (count ? "," : "") + std::string("{\"bufferView\":") + std::to_string(count) +
                 ",\"componentType\":" + std::to_string(componentType) + ",\"count\":" + std::to_string(elements) +
                 ",\"type\":\"" + type + "\"}";
    return count++;
  }
  int floats(const std::vector<float>& v, const char* type, size_t components) {
    return add(v.data(), v.size() * 4, 5126, v.size() / components, type);
  }
  int ushorts(const std::vector<uint16_t>& v, const char* type, size_t components) {
    return add(v.data(), v.size() * 2, 5123, v.size() / components, type);
  }
  // Writes name.gltf and name.bin under the test folder; returns the .gltf path.
  std::string write(const std::string& name, const std::string& body) const {
    const std::filesystem::path dir = std::filesystem::path(PROBECAST_TEST_TMP) / "animation";
    std::filesystem::create_directories(dir);
    test::writeFile((dir / (name + ".bin")).string(), bin);
    const std::string json = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"" + name +
                             ".bin\",\"byteLength\":" + std::to_string(bin.size()) + "}],\"bufferViews\":[" + views +
                             "],\"accessors\":[" + accessors + "]," + body + "}";
    test::writeFile((dir / (name + ".gltf")).string(), json);
    return (dir / (name + ".gltf")).string();
  }
};

// Nodes: 0 parent (rotation about +Z: 0° at 0 s, 90° at 1 s and 2 s) → 1 child at (1, 0, 0) with
// a triangle; 2 j0 (origin) → 3 j1 at (0, 1, 0) (rotation about +Z as node 0); 4 the skinned mesh,
// its own translation (3, 0, 0) ignored as glTF says; 5 a morphed triangle (weights 0,0 → 1,0.5
// over 2 s); 6 STEP translation (0,0,0) → (0,2,0) at 1 s; 7 CUBICSPLINE translation over 2 s.
struct TestRig {
  std::string path;
  static constexpr float kSin45 = 0.70710678f;
};

TestRig writeTestRig(const std::string& name, bool badJoint = false, bool badTimes = false, bool nanValue = false,
                     bool hugeCount = false) {
  RigFile f;
  const int tri = f.floats({0, 0, 0, 0.1f, 0, 0, 0, 0.1f, 0}, "VEC3", 3);
  // Skinned: v0 (0, 0.5, 0) on j0, v1 (0, 1.5, 0) on j1, v2 (0, 1.2, 0) half and half.
  const int skinPos = f.floats({0, 0.5f, 0, 0, 1.5f, 0, 0, 1.2f, 0}, "VEC3", 3);
  const int skinNrm = f.floats({1, 0, 0, 1, 0, 0, 1, 0, 0}, "VEC3", 3);
  const int joints = f.ushorts({0, 0, 0, 0, static_cast<uint16_t>(badJoint ? 7 : 1), 0, 0, 0, 0, 1, 0, 0}, "VEC4", 4);
  const int weights = f.floats({1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0}, "VEC4", 4);
  const int ibm = f.floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,  // j0 at the origin
                            1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1},  // j1 at (0, 1, 0)
                           "MAT4", 16);
  const int morph0 = f.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
  const int morph1 = f.floats({1, 0, 0, 0, 0, 0, 0, 0, 0}, "VEC3", 3);
  const float s = TestRig::kSin45;
  const int times3 = f.floats(badTimes ? std::vector<float>{0, 2, 1} : std::vector<float>{0, 1, 2}, "SCALAR", 1);
  const int rot = f.floats({0, 0, 0, 1, 0, 0, s, s, 0, 0, s, s}, "VEC4", 4);
  const int times2 = f.floats({0, 2}, "SCALAR", 1);
  const int wts = f.floats({0, 0, 1, nanValue ? NAN : 0.5f}, "SCALAR", 1);
  const int step = f.floats({0, 1}, "SCALAR", 1);
  const int stepOut = f.floats({0, 0, 0, 0, 2, 0}, "VEC3", 3);
  // Cubic: (in, value, out) per key: key 0 (0,0,0) (0,0,0) (1,0,0); key 1 (0,0,-1) (0,0,4) (0,0,0).
  const int cubicOut = f.floats({0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 4, 0, 0, 0}, "VEC3", 3);
  const auto a = [](int i) { return std::to_string(i); };
  const std::string body =
      "\"scene\":0,\"scenes\":[{\"nodes\":[0,2,4,5,6,7]}],"
      "\"nodes\":[{\"name\":\"parent\",\"children\":[1]},{\"name\":\"child\",\"translation\":[1,0,0],\"mesh\":0},"
      "{\"name\":\"j0\",\"children\":[3]},{\"name\":\"j1\",\"translation\":[0,1,0]},"
      "{\"name\":\"skinned\",\"mesh\":1,\"skin\":0,\"translation\":[3,0,0]},"
      "{\"name\":\"morphed\",\"mesh\":2},{\"name\":\"stepper\",\"mesh\":0},{\"name\":\"cubic\",\"mesh\":0}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":" + a(tri) + "}}]},"
      "{\"primitives\":[{\"attributes\":{\"POSITION\":" + a(skinPos) + ",\"NORMAL\":" + a(skinNrm) +
      ",\"JOINTS_0\":" + a(joints) + ",\"WEIGHTS_0\":" + a(weights) + "}}]},"
      "{\"primitives\":[{\"attributes\":{\"POSITION\":" + a(tri) + "},\"targets\":[{\"POSITION\":" + a(morph0) +
      "},{\"POSITION\":" + a(morph1) + "}]}],\"weights\":[0,0]}],"
      "\"skins\":[{\"joints\":[2,3],\"inverseBindMatrices\":" + a(ibm) + "}],"
      "\"animations\":[{\"samplers\":["
      "{\"input\":" + a(times3) + ",\"output\":" + a(rot) + "},"
      "{\"input\":" + a(times2) + ",\"output\":" + a(wts) + "},"
      "{\"input\":" + a(step) + ",\"output\":" + a(stepOut) + ",\"interpolation\":\"STEP\"},"
      "{\"input\":" + a(times2) + ",\"output\":" + a(cubicOut) + ",\"interpolation\":\"CUBICSPLINE\"}],"
      "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"rotation\"}},"
      "{\"sampler\":0,\"target\":{\"node\":3,\"path\":\"rotation\"}},"
      "{\"sampler\":1,\"target\":{\"node\":5,\"path\":\"weights\"}},"
      "{\"sampler\":2,\"target\":{\"node\":6,\"path\":\"translation\"}},"
      "{\"sampler\":3,\"target\":{\"node\":7,\"path\":\"translation\"}}]}]";
  if (hugeCount) {  // the two key times' accessor claims 2^62 elements: a size that wraps if multiplied unchecked
    const std::string two = "\"count\":2,\"type\":\"SCALAR\"";
    f.accessors.replace(f.accessors.find(two), two.size(), "\"count\":4611686018427387904,\"type\":\"SCALAR\"");
  }
  // ctest runs the tests of this file in parallel: each writes files of its own.
  return {f.write(name + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name(), body)};
}

// The posed vertices of the primitive on `node`.
std::vector<glm::vec3> verticesOf(const Scene& s, uint32_t node) {
  for (const RigPrimitive& p : s.rig->primitives)
    if (p.node == node) return {s.positions.begin() + p.firstVertex, s.positions.begin() + p.firstVertex + p.vertexCount};
  ADD_FAILURE() << "node " << node << " has no moving primitive";
  return {};
}

Scene load(const std::string& path, double t) {
  Scene s;
  std::string error;
  EXPECT_TRUE(loadScene(path, t, s, error)) << error;
  return s;
}

TEST(GltfAnimation, HierarchyCarriesTheChildAlong) {
  const std::string path = writeTestRig("rig").path;
  const Scene at0 = load(path, 0.0), at1 = load(path, 1.0), half = load(path, 0.5);
  ASSERT_TRUE(sceneAnimates(at0));
  EXPECT_FLOAT_EQ(static_cast<float>(animationDuration(at0)), 2.0f);
  expectNear(verticesOf(at0, 1)[0], {1, 0, 0});
  expectNear(verticesOf(at1, 1)[0], {0, 1, 0});     // 90° about +Z carries (1, 0, 0) to (0, 1, 0)
  expectNear(verticesOf(at1, 1)[1], {0, 1.1f, 0});  // and the child's (0.1, 0, 0) to (0, 0.1, 0)
  expectNear(verticesOf(half, 1)[0], {TestRig::kSin45, TestRig::kSin45, 0});  // slerp: 45°
}

TEST(GltfAnimation, SkinsBlendJointsAndIgnoreTheMeshNode) {
  const std::string path = writeTestRig("rig").path;
  const Scene at0 = load(path, 0.0), at1 = load(path, 1.0);
  const std::vector<glm::vec3> rest = verticesOf(at0, 4), bent = verticesOf(at1, 4);
  // At rest the skin reproduces the bind pose; the node's (3, 0, 0) plays no part.
  expectNear(rest[0], {0, 0.5f, 0});
  expectNear(rest[1], {0, 1.5f, 0});
  // j1 turned 90° about +Z around (0, 1, 0): (0, 1.5, 0) → (-0.5, 1, 0); the half-and-half
  // vertex is the mean of (0, 1.2, 0) and (-0.2, 1, 0).
  expectNear(bent[0], {0, 0.5f, 0});
  expectNear(bent[1], {-0.5f, 1.0f, 0});
  expectNear(bent[2], {-0.1f, 1.1f, 0});
  // The normal of the vertex on j1 turns with it: (1, 0, 0) → (0, 1, 0).
  for (const RigPrimitive& p : at1.rig->primitives)
    if (p.node == 4) expectNear(at1.normals[p.firstVertex + 1], {0, 1, 0});
}

TEST(GltfAnimation, MorphWeightsAddTargetDeltas) {
  const std::string path = writeTestRig("rig").path;
  const std::vector<glm::vec3> at0 = verticesOf(load(path, 0.0), 5), at1 = verticesOf(load(path, 1.0), 5);
  expectNear(at0[0], {0, 0, 0});
  // Weights (0.5, 0.25) at 1 s: every vertex + 0.5·(0, 0, 1), vertex 0 also + 0.25·(1, 0, 0).
  expectNear(at1[0], {0.25f, 0, 0.5f});
  expectNear(at1[1], {0.1f, 0, 0.5f});
}

TEST(GltfAnimation, StepAndCubicSplineChannelsMoveNodes) {
  const std::string path = writeTestRig("rig").path;
  expectNear(verticesOf(load(path, 0.99), 6)[0], {0, 0, 0});
  expectNear(verticesOf(load(path, 1.0), 6)[0], {0, 2, 0});
  // Cubic at 1 s (s = 0.5, td = 2): x = 0.125·2·1 = 0.25; z = 0.5·4 − 0.125·2·(−1) = 2.25.
  expectNear(verticesOf(load(path, 1.0), 7)[0], {0.25f, 0, 2.25f});
}

TEST(GltfAnimation, LoopsOverTheLongestClipAndBoundsHoldEveryPose) {
  const std::string path = writeTestRig("rig").path;
  Scene s = load(path, 0.0);
  const Scene at05 = load(path, 0.5);
  poseScene(s, 2.5);  // one loop later
  EXPECT_EQ(s.positions, at05.positions);
  // The stepper reaches y = 2.1 only after 1 s, the morphed triangle z = 1: the bounds hold both
  // at every time.
  EXPECT_GE(s.boundsMax.y, 2.1f - 1e-5f);
  EXPECT_GE(s.boundsMax.z, 1.0f - 1e-5f);
  EXPECT_EQ(load(path, 0.0).boundsMax, at05.boundsMax);
}

TEST(GltfAnimation, PosingKeepsTrianglesAndOrder) {
  const std::string path = writeTestRig("rig").path;
  const Scene a = load(path, 0.0), b = load(path, 1.3);
  EXPECT_EQ(a.indices, b.indices);
  EXPECT_EQ(a.triangleMaterial, b.triangleMaterial);
  EXPECT_NE(a.positions, b.positions);
}

TEST(GltfAnimation, MalformedAnimationsAreRefusedWithTheReason) {
  Scene s;
  std::string error;
  EXPECT_FALSE(loadScene(writeTestRig("bad-joint", true).path, 0.0, s, error));
  EXPECT_NE(error.find("JOINTS names joint 7 of a skin with 2"), std::string::npos) << error;
  EXPECT_FALSE(loadScene(writeTestRig("bad-times", false, true).path, 0.0, s, error));
  EXPECT_NE(error.find("key times must be finite, not negative and increasing"), std::string::npos) << error;
  EXPECT_FALSE(loadScene(writeTestRig("nan-value", false, false, true).path, 0.0, s, error));
  EXPECT_NE(error.find("output holds NaN or Inf"), std::string::npos) << error;
  EXPECT_FALSE(loadScene(writeTestRig("huge-count", false, false, false, true).path, 0.0, s, error));
  EXPECT_NE(error.find("reads past the end of its buffer"), std::string::npos) << error;
}

TEST(GltfAnimation, AnimatedCornellBoxMovesItsCubeAndBendsItsArm) {
  const std::string path = std::string(PROBECAST_TEST_DATA) + "/scenes/cornell-animated/cornell-animated.gltf";
  const Scene at0 = load(path, 0.0), at2 = load(path, 2.0);
  ASSERT_TRUE(sceneAnimates(at0));
  EXPECT_NEAR(animationDuration(at0), 4.0, 1e-3);
  const auto centroid = [](const std::vector<glm::vec3>& v) {
    glm::vec3 c(0.0f);
    for (const glm::vec3& p : v) c += p;
    return c / static_cast<float>(v.size());
  };
  // The mover (node 9) slides from x = -0.6 to 0.6 by 2 s at 1.3 m.
  expectNear(centroid(verticesOf(at0, 9)), {-0.6f, 1.3f, 0.2f}, 1e-3f);
  expectNear(centroid(verticesOf(at2, 9)), {0.6f, 1.3f, 0.2f}, 1e-3f);
  // The arm (node 12, skinned) leans toward -X at 2 s: its top moves left and down.
  const std::vector<glm::vec3> arm0 = verticesOf(at0, 12), arm2 = verticesOf(at2, 12);
  float top0 = -1e9f, top2 = -1e9f;
  for (const glm::vec3& p : arm0) top0 = std::max(top0, p.y);
  for (const glm::vec3& p : arm2) top2 = std::max(top2, p.y);
  EXPECT_NEAR(top0, 1.0f, 1e-3f);
  EXPECT_LT(top2, 0.9f);
  EXPECT_LT(centroid(arm2).x, centroid(arm0).x - 0.05f);
}

}  // namespace
}  // namespace probecast::scene
