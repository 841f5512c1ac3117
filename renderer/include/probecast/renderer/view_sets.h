// View sets for one scene camera: mono, a stereo pair, or an N×M light-field array.
//
// Every view looks along the camera's axis from an eye shifted in the camera's right/up plane,
// with an off-axis (sheared) frustum through one shared display rectangle at distance
// `displayDistance`, so all views agree on that plane (zero parallax there).
//   stereo: eyes at ±IPD/2 (64 mm) along right, parallel axes.
//   lf:NxM: N columns × M rows of eyes spanning a viewing cone of `lfConeDeg` horizontally (and
//           the same angular step vertically): full parallax; view 0 is bottom-left, then
//           left → right, rows bottom → top.
//   lfh:NxM: N × M eyes on one horizontal line across the cone, view 0 leftmost, laid out in the
//           quilt the same way (tile k at column k mod N, row k div N): horizontal parallax only,
//           as a Looking Glass display expects its quilt.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "probecast/renderer/reference_camera.h"

namespace probecast::renderer {

struct ViewSetSpec {
  enum class Kind { Mono, Stereo, LightField, HorizontalLightField } kind = Kind::Mono;
  int columns = 1;
  int rows = 1;
  int count() const { return columns * rows; }
};

// Parses "mono", "stereo", "lf:NxM" or "lfh:NxM" (1 ≤ N, M ≤ 16); false with a message otherwise.
bool parseViewSet(const std::string& text, ViewSetSpec& spec, std::string& error);

struct ViewInfo {
  glm::mat4 viewProj;  // world → Vulkan clip (y down, z in [0, 1])
  glm::vec3 eye;
  CameraView camera;  // the same view as a camera (off-axis shift included), for the reference tracer
  int column = 0;
  int row = 0;
};

struct ViewSetOptions {
  float aspect = 1.0f;           // width / height of each view
  float displayDistance = 3.0f;  // metres from the camera to the shared display plane
  float ipd = 0.064f;            // metres
  float lfConeDeg = 35.0f;       // horizontal viewing cone of a light-field array
  float znear = 0.01f;
  float zfar = 200.0f;
};

// glm's right-handed perspective with z in [0, 1] and y flipped: Vulkan clip conventions.
glm::mat4 vulkanPerspective(float yfov, float aspect, float znear, float zfar);

std::vector<ViewInfo> makeViewSet(const CameraView& camera, const ViewSetSpec& spec, const ViewSetOptions& options);

// Places equally sized views into a quilt of columns × rows tiles: view (column, row) at tile
// x = column, y = rows − 1 − row (row 0 at the bottom, as Looking Glass quilts).
Image composeQuilt(const std::vector<Image>& views, const std::vector<ViewInfo>& info, int columns, int rows);

}  // namespace probecast::renderer
