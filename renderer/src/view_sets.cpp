#include "probecast/renderer/view_sets.h"

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "probecast/codec/priority.h"

namespace probecast::renderer {
namespace {

constexpr int kMaxSide = 16;  // views per light-field row or column
static_assert(kMaxSide * kMaxSide <= static_cast<int>(kMaxViewsPerSet), "every lf:NxM set fits one view update");

}  // namespace

bool parseViewSet(const std::string& text, ViewSetSpec& spec, std::string& error) {
  if (text == "mono") {
    spec = {ViewSetSpec::Kind::Mono, 1, 1};
    return true;
  }
  if (text == "stereo") {
    spec = {ViewSetSpec::Kind::Stereo, 2, 1};
    return true;
  }
  int n = 0, m = 0;
  char tail = 0;
  const auto sides = [&] { return n >= 1 && m >= 1 && n <= kMaxSide && m <= kMaxSide; };
  if (std::sscanf(text.c_str(), "lf:%dx%d%c", &n, &m, &tail) == 2 && sides()) {
    spec = {ViewSetSpec::Kind::LightField, n, m};
    return true;
  }
  if (std::sscanf(text.c_str(), "lfh:%dx%d%c", &n, &m, &tail) == 2 && sides()) {
    spec = {ViewSetSpec::Kind::HorizontalLightField, n, m};
    return true;
  }
  error = "views must be mono, stereo, lf:NxM or lfh:NxM with 1 ≤ N, M ≤ 16 (got '" + text + "')";
  return false;
}

glm::mat4 vulkanPerspective(float yfov, float aspect, float znear, float zfar) {
  glm::mat4 proj = glm::perspectiveRH_ZO(yfov, aspect, znear, zfar);
  proj[1][1] = -proj[1][1];  // Vulkan's y points down
  return proj;
}

std::vector<ViewInfo> makeViewSet(const CameraView& camera, const ViewSetSpec& spec, const ViewSetOptions& o) {
  const glm::vec3 f = glm::normalize(camera.forward);
  const glm::vec3 r = glm::normalize(glm::cross(f, camera.up));
  const glm::vec3 u = glm::cross(r, f);
  const float halfH = o.displayDistance * std::tan(0.5f * camera.yfov);
  const float halfW = halfH * o.aspect;
  // Eye offsets (right, up) in metres.
  std::vector<glm::vec2> offsets;
  if (spec.kind == ViewSetSpec::Kind::Mono) {
    offsets.push_back({0, 0});
  } else if (spec.kind == ViewSetSpec::Kind::Stereo) {
    offsets.push_back({-0.5f * o.ipd, 0});
    offsets.push_back({0.5f * o.ipd, 0});
  } else if (spec.kind == ViewSetSpec::Kind::HorizontalLightField) {
    const int count = spec.count();
    const float span = 2.0f * o.displayDistance * std::tan(glm::radians(0.5f * o.lfConeDeg));
    const float step = count > 1 ? span / static_cast<float>(count - 1) : 0.0f;
    for (int k = 0; k < count; ++k) offsets.push_back({(static_cast<float>(k) - 0.5f * static_cast<float>(count - 1)) * step, 0});
  } else {
    const float span = 2.0f * o.displayDistance * std::tan(glm::radians(0.5f * o.lfConeDeg));
    const float step = spec.columns > 1 ? span / static_cast<float>(spec.columns - 1) : 0.0f;
    for (int row = 0; row < spec.rows; ++row)
      for (int col = 0; col < spec.columns; ++col)
        offsets.push_back({(static_cast<float>(col) - 0.5f * static_cast<float>(spec.columns - 1)) * step,
                           (static_cast<float>(row) - 0.5f * static_cast<float>(spec.rows - 1)) * step});
  }
  std::vector<ViewInfo> views;
  for (size_t k = 0; k < offsets.size(); ++k) {
    const glm::vec2 s = offsets[k];
    const glm::vec3 eye = camera.position + r * s.x + u * s.y;
    // The shared display rectangle, seen from the shifted eye: a sheared frustum.
    const float scale = o.znear / o.displayDistance;
    glm::mat4 proj = glm::frustumRH_ZO((-halfW - s.x) * scale, (halfW - s.x) * scale, (-halfH - s.y) * scale,
                                       (halfH - s.y) * scale, o.znear, o.zfar);
    proj[1][1] = -proj[1][1];  // Vulkan's y points down
    proj[2][1] = -proj[2][1];
    ViewInfo v;
    v.viewProj = proj * glm::lookAtRH(eye, eye + f, u);
    v.eye = eye;
    v.camera = camera;
    v.camera.position = eye;
    v.camera.forward = f;
    v.camera.up = u;
    v.camera.shift = -s / o.displayDistance;
    v.column = spec.kind == ViewSetSpec::Kind::Mono ? 0 : static_cast<int>(k) % spec.columns;
    v.row = spec.kind == ViewSetSpec::Kind::Mono ? 0 : static_cast<int>(k) / spec.columns;
    views.push_back(v);
  }
  return views;
}

Image composeQuilt(const std::vector<Image>& views, const std::vector<ViewInfo>& info, int columns, int rows) {
  Image quilt;
  if (views.empty()) return quilt;
  const uint32_t w = views[0].width, h = views[0].height;
  quilt.width = w * static_cast<uint32_t>(columns);
  quilt.height = h * static_cast<uint32_t>(rows);
  quilt.rgb.assign(static_cast<size_t>(quilt.width) * quilt.height * 3, 0.0f);
  for (size_t k = 0; k < views.size(); ++k) {
    const uint32_t x0 = w * static_cast<uint32_t>(info[k].column);
    const uint32_t y0 = h * static_cast<uint32_t>(rows - 1 - info[k].row);
    for (uint32_t y = 0; y < h; ++y)
      std::copy_n(views[k].rgb.begin() + static_cast<std::ptrdiff_t>(y * w * 3), w * 3,
                  quilt.rgb.begin() + static_cast<std::ptrdiff_t>(((y0 + y) * quilt.width + x0) * 3));
  }
  return quilt;
}

}  // namespace probecast::renderer
