// Head traces (session/head_trace.h): the recorded format read as it is written and refused line
// by line when it is not, the dataset's axes mapped onto the project's, and a camera turned about
// the neck's pivot; scripted camera paths read, refused and followed the same way.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "probecast/session/head_trace.h"

namespace probecast::session {
namespace {

std::string failure(const std::string& text) {
  HeadTrace t;
  std::string error;
  EXPECT_FALSE(parseHeadTrace(text, t, error)) << text;
  return error;
}

TEST(HeadTrace, ReadsTheRecordedFormatAndRefusesWhatIsNotIt) {
  HeadTrace t;
  std::string error;
  ASSERT_TRUE(parseHeadTrace("timestamp viewpoint w x y z\n0.0 0 1 0 0 0\n# a comment\n\n0.5 0 1 0 0 0\n", t, error))
      << error;
  EXPECT_EQ(t.seconds.size(), 2u);
  EXPECT_DOUBLE_EQ(t.duration(), 0.5);
  EXPECT_NE(failure("0 0 1 0 0\n1 0 1 0 0 0\n").find("line 1: expected 6 numbers"), std::string::npos);
  EXPECT_NE(failure("0 0 1 0 0 0\n1 0 1 0 0 0 7\n").find("line 2: expected 6 numbers"), std::string::npos);
  EXPECT_NE(failure("0 0 1 0 0 0\n1 0 nan 0 0 0\n").find("line 2: a number that is not finite"), std::string::npos);
  EXPECT_NE(failure("0 0 1 0 0 0\n1 0 2 0 0 0\n").find("line 2: the quaternion's length is 2"), std::string::npos);
  EXPECT_NE(failure("1 0 1 0 0 0\n0.5 0 1 0 0 0\n").find("line 2: time runs backwards"), std::string::npos);
  EXPECT_NE(failure("0 0 1 0 0 0\n").find("fewer than two samples"), std::string::npos);
  EXPECT_NE(failure("1 0 1 0 0 0\n1 0 1 0 0 0\n").find("the same time"), std::string::npos);
  HeadTrace missing;
  EXPECT_FALSE(loadHeadTrace("/nonexistent/trace.txt", missing, error));
  EXPECT_NE(error.find("/nonexistent/trace.txt: cannot be read"), std::string::npos) << error;
}

// A turn of 90° about the dataset's z (up) over one second: the project's camera, looking down −Z
// at the start, looks down −X after it (turning left, as z up and y left make a positive turn),
// half-way at 0.5 s, and the eyes swing about the pivot behind them. The trace loops.
TEST(HeadTrace, TheBuiltInTraceIsTenSecondsOfARealHead) {
  HeadTrace t;
  std::string error;
  ASSERT_TRUE(loadHeadTrace(kBuiltinHeadTrace, t, error)) << error;
  EXPECT_GT(t.seconds.size(), 500u);  // about 56 samples a second
  EXPECT_NEAR(t.duration(), 10.0, 0.05);
  // The head moves: somewhere in the first two seconds it has turned by more than 5 degrees.
  float most = 0.0f;
  for (double s = 0.0; s < 2.0; s += 0.05) most = std::max(most, glm::degrees(glm::angle(t.rotationAt(s))));
  EXPECT_GT(most, 5.0f);
  EXPECT_FALSE(loadHeadTrace("builtin:nobody", t, error));
  EXPECT_NE(error.find("builtin:nobody: no such trace (built in: builtin:mmsys18-user1, builtin:walk-1m)"), std::string::npos) << error;
}

TEST(HeadTrace, TurnsTheCameraAboutTheNeckAsTheHeadTurned) {
  const double s = std::sqrt(0.5);
  HeadTrace t;
  std::string error;
  ASSERT_TRUE(parseHeadTrace("0 0 1 0 0 0\n1 0 " + std::to_string(s) + " 0 0 " + std::to_string(s) + "\n", t, error))
      << error;
  renderer::CameraView c;
  c.position = {0, 1.7f, 0};
  c.forward = {0, 0, -1};
  c.up = {0, 1, 0};
  const renderer::CameraView end = poseCamera(c, t, 1.0), half = poseCamera(c, t, 0.5), start = poseCamera(c, t, 0.0);
  EXPECT_NEAR(glm::length(end.forward - glm::vec3(-1, 0, 0)), 0.0f, 1e-4f);
  EXPECT_NEAR(glm::length(end.up - glm::vec3(0, 1, 0)), 0.0f, 1e-4f);
  EXPECT_NEAR(glm::length(half.forward - glm::normalize(glm::vec3(-1, 0, -1))), 0.0f, 1e-4f);
  EXPECT_NEAR(glm::length(start.position - c.position), 0.0f, 1e-6f);
  // The pivot sits kNeckForward behind the eyes: after the turn the eyes are ahead of it along −X.
  const glm::vec3 pivot = c.position - glm::vec3(0, 0, -kNeckForward);
  EXPECT_NEAR(glm::length(end.position - (pivot + glm::vec3(-kNeckForward, 0, 0))), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(poseCamera(c, t, 1.5).forward - half.forward), 0.0f, 1e-4f);  // 1.5 s: looped to 0.5
}

TEST(CameraPath, ReadsKeysAndRefusesWhatIsNotOne) {
  HeadTrace t;
  std::string error;
  ASSERT_TRUE(parseHeadTrace("probecast-camera-path 1\n# t f r u yaw pitch\n0 0 0 0 0 0\n2 1 0.5 0 90 -10\n", t, error)) << error;
  EXPECT_TRUE(t.isPath());
  EXPECT_DOUBLE_EQ(t.duration(), 2.0);
  const std::string head = "probecast-camera-path 1\n0 0 0 0 0 0\n";
  EXPECT_NE(failure(head + "1 0 0 0 0\n").find("line 3: expected 6 numbers: seconds forward right up yaw pitch"),
            std::string::npos);
  EXPECT_NE(failure(head + "1 0 0 nan 0 0\n").find("line 3: a number that is not finite"), std::string::npos);
  EXPECT_NE(failure(head + "1 0 0 0 0 91\n").find("line 3: a pitch beyond"), std::string::npos);
  EXPECT_NE(failure(head + "1 1e9 0 0 0 0\n").find("line 3: an offset beyond 100 km"), std::string::npos);
  EXPECT_NE(failure(head + "-1 0 0 0 0 0\n").find("line 3: time runs backwards"), std::string::npos);
  EXPECT_NE(failure(head).find("fewer than two samples"), std::string::npos);
  EXPECT_NE(failure("probecast-camera-path 2\n0 0 0 0 0 0\n1 0 0 0 0 0\n").find("line 1: an unknown camera path version"),
            std::string::npos);
  ASSERT_TRUE(loadHeadTrace(kBuiltinWalk, t, error)) << error;
  EXPECT_TRUE(t.isPath());
  EXPECT_DOUBLE_EQ(t.duration(), 8.0);
}

// A camera looking down −Z and a little down: the path walks it along its level forward (not into
// the floor), turns it left about the world's up, and loops; the same time gives the same pose.
TEST(CameraPath, WalksAndTurnsTheCameraAsItsKeysSay) {
  HeadTrace t;
  std::string error;
  ASSERT_TRUE(parseHeadTrace("probecast-camera-path 1\n0 0 0 0 0 0\n2 2 1 0.5 90 0\n", t, error)) << error;
  renderer::CameraView c;
  c.position = {0, 1.7f, 0};
  c.forward = glm::normalize(glm::vec3(0, -0.2f, -1));
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::vec3(0, 1, 0)), c.forward));
  const renderer::CameraView end = poseCamera(c, t, 2.0), half = poseCamera(c, t, 1.0);
  EXPECT_NEAR(glm::length(end.position - glm::vec3(1, 2.2f, -2)), 0.0f, 1e-5f);  // 2 ahead, 1 right, 0.5 up
  EXPECT_NEAR(glm::length(half.position - glm::vec3(0.5f, 1.95f, -1)), 0.0f, 1e-5f);
  // Turned 90° left: the level part of its view now points along −X, its downward tilt kept.
  EXPECT_NEAR(glm::length(end.forward - glm::vec3(c.forward.z, c.forward.y, 0)), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::dot(end.forward, end.up), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(poseCamera(c, t, 3.0).position - half.position), 0.0f, 1e-5f);  // looped
  EXPECT_NEAR(glm::length(poseCamera(c, t, 1.0).forward - half.forward), 0.0f, 0.0f);     // deterministic
  EXPECT_NEAR(glm::length(poseCamera(c, t, 0.0).position - c.position), 0.0f, 1e-6f);
}

}  // namespace
}  // namespace probecast::session
