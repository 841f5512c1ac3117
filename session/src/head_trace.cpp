#include "probecast/session/head_trace.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace probecast::session {
namespace {

// The dataset's (x forward, y left, z up) as the project's axes: a proper rotation, so a
// quaternion's vector part maps as a vector does.
glm::quat toProjectFrame(double w, double x, double y, double z) {
  return glm::normalize(glm::quat(static_cast<float>(w), static_cast<float>(-y), static_cast<float>(z),
                                  static_cast<float>(-x)));
}

}  // namespace

bool parseHeadTrace(const std::string& text, HeadTrace& out, std::string& error) {
  out = {};
  std::istringstream lines(text);
  std::string line;
  for (size_t number = 1; std::getline(lines, line); ++number) {
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (number == 1 && line.find("timestamp") != std::string::npos) continue;  // the header
    std::istringstream fields(line);
    std::vector<double> v;
    bool numbers = true;
    for (std::string token; fields >> token;) {
      char* end = nullptr;
      v.push_back(std::strtod(token.c_str(), &end));
      numbers = numbers && end == token.c_str() + token.size();
    }
    const auto bad = [&](const std::string& why) { return error = "line " + std::to_string(number) + ": " + why, false; };
    if (!numbers || v.size() != 6) return bad("expected 6 numbers: timestamp viewpoint w x y z");
    const double t = v[0], w = v[2], x = v[3], y = v[4], z = v[5];
    if (!std::isfinite(t) || !std::isfinite(w) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
      return bad("a number that is not finite");
    const double norm = std::sqrt(w * w + x * x + y * y + z * z);
    if (std::fabs(norm - 1.0) > 0.01) return bad("the quaternion's length is " + std::to_string(norm) + ", not 1");
    if (!out.seconds.empty() && t < out.seconds.back()) return bad("time runs backwards");
    out.seconds.push_back(t);
    out.orientation.push_back(toProjectFrame(w, x, y, z));
  }
  if (out.seconds.size() < 2) return error = "fewer than two samples", false;
  if (!(out.duration() > 0.0)) return error = "every sample has the same time", false;
  return true;
}

extern const std::string_view kBuiltinHeadTraceUser1;  // builtin_head_trace.cpp, generated

bool loadHeadTrace(const std::string& path, HeadTrace& out, std::string& error) {
  if (path.rfind("builtin:", 0) == 0) {
    if (path != kBuiltinHeadTrace) return error = path + ": no such trace (built in: " + kBuiltinHeadTrace + ")", false;
    if (!parseHeadTrace(std::string(kBuiltinHeadTraceUser1), out, error)) return error = path + ": " + error, false;
    return true;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return error = path + ": cannot be read", false;
  std::ostringstream text;
  text << in.rdbuf();
  if (!parseHeadTrace(text.str(), out, error)) return error = path + ": " + error, false;
  return true;
}

glm::quat HeadTrace::rotationAt(double t) const {
  const double d = duration();
  if (t < 0.0 || t > d) {  // past the end: from the start again
    t = std::fmod(t, d);
    if (t < 0.0) t += d;
  }
  const double at = seconds.front() + t;
  size_t i = 1;
  while (i + 1 < seconds.size() && seconds[i] < at) ++i;
  const double span = seconds[i] - seconds[i - 1];
  const float f = span > 0.0 ? static_cast<float>((at - seconds[i - 1]) / span) : 1.0f;
  const glm::quat q = glm::slerp(orientation[i - 1], orientation[i], std::clamp(f, 0.0f, 1.0f));
  return glm::normalize(q * glm::inverse(orientation.front()));
}

renderer::CameraView poseCamera(const renderer::CameraView& camera, const HeadTrace& trace, double t) {
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
