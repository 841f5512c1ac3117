#include "probecast/session/head_trace.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace probecast::session {
namespace {

// The dataset's (x forward, y left, z up) as the project's axes: a proper rotation, so a
// quaternion's vector part maps as a vector does.
glm::quat toProjectFrame(double w, double x, double y, double z) {
  return glm::normalize(glm::quat(static_cast<float>(w), static_cast<float>(-y), static_cast<float>(z),
                                  static_cast<float>(-x)));
}

constexpr const char* kPathMagic = "probecast-camera-path 1";

// A line's whitespace-separated numbers; false when a token is not one.
bool numbersOf(const std::string& line, std::vector<double>& v) {
  std::istringstream fields(line);
  v.clear();
  bool numbers = true;
  for (std::string token; fields >> token;) {
    char* end = nullptr;
    v.push_back(std::strtod(token.c_str(), &end));
    numbers = numbers && end == token.c_str() + token.size();
  }
  return numbers;
}

bool allFinite(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

// One recorded sample (timestamp viewpoint w x y z) into `out`; the reason when it is not one.
std::string addHeadSample(const std::vector<double>& v, HeadTrace& out) {
  if (v.size() != 6) return "expected 6 numbers: timestamp viewpoint w x y z";
  if (!allFinite(v)) return "a number that is not finite";
  const double w = v[2], x = v[3], y = v[4], z = v[5];
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  if (std::fabs(norm - 1.0) > 0.01) return "the quaternion's length is " + std::to_string(norm) + ", not 1";
  out.orientation.push_back(toProjectFrame(w, x, y, z));
  return {};
}

// One key of a camera path (seconds forward right up yaw pitch) into `out`.
std::string addPathKey(const std::vector<double>& v, HeadTrace& out) {
  if (v.size() != 6) return "expected 6 numbers: seconds forward right up yaw pitch";
  if (!allFinite(v)) return "a number that is not finite";
  if (std::fabs(v[1]) > 1e5 || std::fabs(v[2]) > 1e5 || std::fabs(v[3]) > 1e5) return "an offset beyond 100 km";
  if (std::fabs(v[5]) > 90.0) return "a pitch beyond ±90 degrees";
  if (std::fabs(v[4]) > 1e5) return "a yaw beyond ±100000 degrees";
  out.offset.emplace_back(v[1], v[2], v[3]);
  out.yawPitch.emplace_back(v[4], v[5]);
  return {};
}

}  // namespace

bool parseHeadTrace(const std::string& text, HeadTrace& out, std::string& error) {
  out = {};
  std::istringstream lines(text);
  std::string line;
  bool path = false, first = true;
  std::vector<double> v;
  for (size_t number = 1; std::getline(lines, line); ++number) {
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto bad = [&](const std::string& why) { return error = "line " + std::to_string(number) + ": " + why, false; };
    if (std::exchange(first, false)) {
      if (line.rfind("probecast-camera-path", 0) == 0) {
        if (line.substr(0, line.find_last_not_of(" \t\r") + 1) != kPathMagic)
          return bad("an unknown camera path version (this reads \"" + std::string(kPathMagic) + "\")");
        path = true;
        continue;
      }
      if (number == 1 && line.find("timestamp") != std::string::npos) continue;  // the recorded format's header
    }
    const bool numbers = numbersOf(line, v);
    const std::string why = !numbers ? std::string(path ? "expected 6 numbers: seconds forward right up yaw pitch"
                                                        : "expected 6 numbers: timestamp viewpoint w x y z")
                                     : path ? addPathKey(v, out) : addHeadSample(v, out);
    if (!why.empty()) return bad(why);
    if (!out.seconds.empty() && v[0] < out.seconds.back()) return bad("time runs backwards");
    out.seconds.push_back(v[0]);
  }
  if (out.seconds.size() < 2) return error = "fewer than two samples", false;
  if (!(out.duration() > 0.0)) return error = "every sample has the same time", false;
  return true;
}

extern const std::string_view kBuiltinHeadTraceUser1;  // builtin_head_trace.cpp, generated

namespace {
constexpr const char* kBuiltinWalkPath =
    "probecast-camera-path 1\n"
    "# seconds forward right up yaw pitch\n"
    "0 0 0 0 0 0\n"
    "2 0.5 0 0 25 0\n"
    "4 1 0 0 0 -10\n"
    "6 0.5 0 0 -25 0\n"
    "8 0 0 0 0 0\n";
}  // namespace

bool loadHeadTrace(const std::string& path, HeadTrace& out, std::string& error) {
  if (path.rfind("builtin:", 0) == 0) {
    const std::string text = path == kBuiltinHeadTrace ? std::string(kBuiltinHeadTraceUser1)
                             : path == kBuiltinWalk    ? std::string(kBuiltinWalkPath)
                                                       : std::string();
    if (text.empty())
      return error = path + ": no such trace (built in: " + kBuiltinHeadTrace + ", " + kBuiltinWalk + ")", false;
    if (!parseHeadTrace(text, out, error)) return error = path + ": " + error, false;
    return true;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return error = path + ": cannot be read", false;
  std::ostringstream text;
  text << in.rdbuf();
  if (!parseHeadTrace(text.str(), out, error)) return error = path + ": " + error, false;
  return true;
}

namespace {

// The samples around `t` seconds from the first (looping over the duration): the later one's index
// and how far towards it.
std::pair<size_t, float> bracket(const HeadTrace& trace, double t) {
  const double d = trace.duration();
  if (t < 0.0 || t > d) {  // past the end: from the start again
    t = std::fmod(t, d);
    if (t < 0.0) t += d;
  }
  const double at = trace.seconds.front() + t;
  size_t i = 1;
  while (i + 1 < trace.seconds.size() && trace.seconds[i] < at) ++i;
  const double span = trace.seconds[i] - trace.seconds[i - 1];
  const float f = span > 0.0 ? static_cast<float>((at - trace.seconds[i - 1]) / span) : 1.0f;
  return {i, std::clamp(f, 0.0f, 1.0f)};
}

// A camera path's pose at `t`: moved along the level forward, right and up, turned by yaw and pitch.
renderer::CameraView posePath(const renderer::CameraView& camera, const HeadTrace& trace, double t) {
  const auto [i, f] = bracket(trace, t);
  const glm::vec3 o = glm::mix(trace.offset[i - 1], trace.offset[i], f);
  const glm::vec2 yp = glm::mix(trace.yawPitch[i - 1], trace.yawPitch[i], f);
  const glm::vec3 worldUp(0, 1, 0), forward = glm::normalize(camera.forward);
  glm::vec3 level = forward - worldUp * glm::dot(forward, worldUp);
  level = glm::dot(level, level) > 1e-8f ? glm::normalize(level) : glm::normalize(camera.up);  // looking straight down
  const glm::vec3 right = glm::normalize(glm::cross(level, worldUp));
  const glm::quat turn = glm::angleAxis(glm::radians(yp.x), worldUp) * glm::angleAxis(glm::radians(yp.y), right);
  renderer::CameraView posed = camera;
  posed.forward = turn * forward;
  posed.up = turn * glm::normalize(camera.up);
  posed.position = camera.position + level * o.x + right * o.y + worldUp * o.z;
  return posed;
}

}  // namespace

glm::quat HeadTrace::rotationAt(double t) const {
  if (isPath()) return glm::quat(1, 0, 0, 0);  // a path turns the camera in poseCamera, about its own axes
  const auto [i, f] = bracket(*this, t);
  const glm::quat q = glm::slerp(orientation[i - 1], orientation[i], f);
  return glm::normalize(q * glm::inverse(orientation.front()));
}

renderer::CameraView poseCamera(const renderer::CameraView& camera, const HeadTrace& trace, double t) {
  if (trace.isPath()) return posePath(camera, trace, t);
  const glm::quat r = trace.rotationAt(t);
  const glm::vec3 forward = glm::normalize(camera.forward), up = glm::normalize(camera.up);
  const glm::vec3 eyes = forward * kNeckForward + glm::vec3(0, 1, 0) * kNeckUp;  // pivot → eyes at the start
  renderer::CameraView posed = camera;
  posed.forward = r * forward;
  posed.up = r * up;
  posed.position = camera.position - eyes + r * eyes;
  return posed;
}

}  // namespace probecast::session
