#pragma once
// Head motion recorded from people wearing a headset, to move a viewer's camera as a head moves.
//
// File format (the MMSys'18 360° video head-movement dataset's, one sample a line):
//   timestamp viewpoint w x y z
// a header line naming the columns, then seconds from the start (non-decreasing), a viewpoint
// index (ignored), and the head's orientation as a unit quaternion in the dataset's frame: x
// forward, y left, z up. Lines starting with '#' and blank lines are skipped.
//
// The camera follows the head's rotation since its first sample, applied about the world's axes
// to the scene's camera (x forward → −Z, y left → −X, z up → +Y), with a neck model: the eyes
// kNeckForward ahead of and kNeckUp above the pivot the head turns about, so turning the head
// also moves the eyes as it does a person's.
//
// A scripted camera path (a walking mono or game camera) is read by the same calls: a first line
// `probecast-camera-path 1`, then one key a line,
//   seconds forward right up yaw pitch
// metres along the scene camera's level forward, its right and the world's up from where it
// stands, and degrees: yaw turning left about the world's up, pitch looking up. Keys are
// interpolated linearly and the path loops; no neck model (the camera is the eye).

#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "probecast/renderer/reference_camera.h"

namespace probecast::session {

struct HeadTrace {
  std::vector<double> seconds;
  std::vector<glm::quat> orientation;  // in the project's frame (y up, −z forward); empty for a path
  // A camera path's keys instead: (forward, right, up) metres and (yaw, pitch) degrees.
  std::vector<glm::vec3> offset;
  std::vector<glm::vec2> yawPitch;
  bool isPath() const { return !offset.empty(); }
  double duration() const { return seconds.empty() ? 0.0 : seconds.back() - seconds.front(); }
  // The rotation since the first sample at `t` seconds from it (spherical interpolation between
  // samples; the trace loops over its duration).
  glm::quat rotationAt(double t) const;
};

inline constexpr float kNeckForward = 0.10f;  // metres from the neck's pivot to the eyes, ahead
inline constexpr float kNeckUp = 0.10f;       // and above

// A trace built into the binary: the first 10 s of user 1 of the MMSys'18 traces (Corbillon et
// al., MIT licence; examples/head-traces/).
inline constexpr const char* kBuiltinHeadTrace = "builtin:mmsys18-user1";
// A path built in: 1 m forward and back over 8 s at a stroll, looking 25° left, ahead and a
// little down, 25° right, ahead again.
inline constexpr const char* kBuiltinWalk = "builtin:walk-1m";

// Reads a trace (a file, or kBuiltinHeadTrace); false with a message naming the file and line on
// anything malformed (a bad number, a quaternion far from unit length, time running backwards,
// fewer than two samples), or an unknown builtin: name. A camera path is refused in the same way.
bool loadHeadTrace(const std::string& path, HeadTrace& out, std::string& error);
bool parseHeadTrace(const std::string& text, HeadTrace& out, std::string& error);

// `camera` turned by the trace at `t` seconds, about the neck's pivot; or moved along the path.
renderer::CameraView poseCamera(const renderer::CameraView& camera, const HeadTrace& trace, double t);

}  // namespace probecast::session
