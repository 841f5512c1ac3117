// Shared by the tests of view interest: a View (as subscribers send them) from a matrix and an eye.
#pragma once

#include <cstring>

#include <glm/glm.hpp>

#include "probecast/codec/priority.h"

namespace probecast::test {

inline View toView(const glm::mat4& viewProj, const glm::vec3& eye) {
  View v{};
  std::memcpy(v.viewProj, &viewProj[0][0], sizeof v.viewProj);
  v.eye[0] = eye.x;
  v.eye[1] = eye.y;
  v.eye[2] = eye.z;
  return v;
}

}  // namespace probecast::test
