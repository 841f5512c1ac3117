#include "envmap.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <stb_image.h>

#include "probecast/imaging/image_io.h"

namespace probecast::bench {

bool loadEnvMap(const std::string& path, EnvMap& map, std::string& error) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  map = EnvMap{};
  map.name = std::filesystem::path(path).filename().string();
  if (ext == ".hdr") {
    int w = 0, h = 0, n = 0;
    float* data = stbi_loadf(path.c_str(), &w, &h, &n, 3);
    if (!data) {
      error = path + ": cannot read Radiance HDR (" + (stbi_failure_reason() ? stbi_failure_reason() : "unknown") + ")";
      return false;
    }
    map.width = w;
    map.height = h;
    map.rgb.assign(data, data + static_cast<size_t>(w) * h * 3);
    stbi_image_free(data);
  } else if (ext == ".exr") {
    if (!imaging::readExr(path, map.rgb, map.width, map.height, error)) return false;
  } else {
    error = path + ": not an environment map (expected .hdr or .exr)";
    return false;
  }
  if (map.width < 2 || map.height < 1) {
    error = path + ": image too small";
    return false;
  }
  for (float& v : map.rgb)
    if (!std::isfinite(v) || v < 0.0f) v = 0.0f;  // radiance is finite and non-negative
  return true;
}

void envMapDirection(const EnvMap& map, int x, int y, float dir[3]) {
  const float theta = kPi * (static_cast<float>(y) + 0.5f) / static_cast<float>(map.height);
  const float phi = 2.0f * kPi * ((static_cast<float>(x) + 0.5f) / static_cast<float>(map.width) - 0.5f);
  dir[0] = std::sin(theta) * std::sin(phi);
  dir[1] = std::cos(theta);
  dir[2] = -std::sin(theta) * std::cos(phi);
}

float envMapPixelSolidAngle(const EnvMap& map, int y) {
  // Exact band area: 2π/W · (cos θ0 − cos θ1).
  const float t0 = kPi * static_cast<float>(y) / static_cast<float>(map.height);
  const float t1 = kPi * static_cast<float>(y + 1) / static_cast<float>(map.height);
  return 2.0f * kPi / static_cast<float>(map.width) * (std::cos(t0) - std::cos(t1));
}

EnvMap downsample(const EnvMap& map, int factor) {
  EnvMap out;
  out.name = map.name;
  out.width = std::max(1, map.width / factor);
  out.height = std::max(1, map.height / factor);
  out.rgb.assign(static_cast<size_t>(out.width) * out.height * 3, 0.0f);
  std::vector<double> weight(static_cast<size_t>(out.width) * out.height, 0.0);
  std::vector<double> acc(out.rgb.size(), 0.0);
  for (int y = 0; y < map.height; ++y) {
    const double w = envMapPixelSolidAngle(map, y);
    const int oy = std::min(out.height - 1, y / factor);
    for (int x = 0; x < map.width; ++x) {
      const int ox = std::min(out.width - 1, x / factor);
      const size_t o = static_cast<size_t>(oy) * out.width + ox;
      const size_t i = (static_cast<size_t>(y) * map.width + x) * 3;
      weight[o] += w;
      for (int c = 0; c < 3; ++c) acc[o * 3 + c] += w * map.rgb[i + c];
    }
  }
  for (size_t o = 0; o < weight.size(); ++o)
    for (int c = 0; c < 3; ++c) out.rgb[o * 3 + c] = weight[o] > 0 ? static_cast<float>(acc[o * 3 + c] / weight[o]) : 0.0f;
  return out;
}

void projectToSh(const EnvMap& map, float probe[kProbeFloats], float rotationY) {
  double acc[kProbeFloats] = {};
  const float cr = std::cos(rotationY), sr = std::sin(rotationY);
  for (int y = 0; y < map.height; ++y) {
    const double dw = envMapPixelSolidAngle(map, y);
    for (int x = 0; x < map.width; ++x) {
      float d[3];
      envMapDirection(map, x, y, d);
      const float rx = cr * d[0] + sr * d[2];
      const float rz = -sr * d[0] + cr * d[2];
      float basis[kShCoeffs];
      shEvalBasis(rx, d[1], rz, basis);
      const float* L = &map.rgb[(static_cast<size_t>(y) * map.width + x) * 3];
      for (int i = 0; i < kShCoeffs; ++i)
        for (int c = 0; c < 3; ++c) acc[i * 3 + c] += dw * basis[i] * L[c];
    }
  }
  for (int i = 0; i < kProbeFloats; ++i) probe[i] = static_cast<float>(acc[i]);
}

void bruteForceIrradiance(const EnvMap& map, const std::vector<float>& normals, std::vector<float>& irradiance) {
  const size_t pixels = static_cast<size_t>(map.width) * map.height;
  std::vector<float> dirs(pixels * 3), weighted(pixels * 3);
  for (int y = 0; y < map.height; ++y) {
    const float dw = envMapPixelSolidAngle(map, y);
    for (int x = 0; x < map.width; ++x) {
      const size_t i = static_cast<size_t>(y) * map.width + x;
      envMapDirection(map, x, y, &dirs[i * 3]);
      for (int c = 0; c < 3; ++c) weighted[i * 3 + c] = map.rgb[i * 3 + c] * dw;
    }
  }
  const size_t count = normals.size() / 3;
  irradiance.assign(count * 3, 0.0f);
  for (size_t n = 0; n < count; ++n) {
    const float* nn = &normals[n * 3];
    double e[3] = {0, 0, 0};
    for (size_t i = 0; i < pixels; ++i) {
      const float cosine = nn[0] * dirs[i * 3] + nn[1] * dirs[i * 3 + 1] + nn[2] * dirs[i * 3 + 2];
      if (cosine <= 0.0f) continue;
      for (int c = 0; c < 3; ++c) e[c] += cosine * weighted[i * 3 + c];
    }
    for (int c = 0; c < 3; ++c) irradiance[n * 3 + c] = static_cast<float>(e[c]);
  }
}

std::vector<float> fibonacciSphere(int count) {
  std::vector<float> out(static_cast<size_t>(count) * 3);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    out[i * 3] = static_cast<float>(r * std::cos(golden * i));
    out[i * 3 + 1] = static_cast<float>(r * std::sin(golden * i));
    out[i * 3 + 2] = static_cast<float>(z);
  }
  return out;
}

std::vector<EnvMap> builtinEnvMaps() {
  std::vector<EnvMap> maps;
  const int w = 256, h = 128;
  // Sunny sky: blue gradient, warm ground, a small bright sun 35° above the horizon.
  EnvMap sky{"builtin-sky", w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  const float sun[3] = {0.5f, 0.574f, -0.649f};
  // Dim room: grey walls, one bright window on the +X side.
  EnvMap room{"builtin-room", w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float d[3];
      envMapDirection(sky, x, y, d);
      float* s = &sky.rgb[(static_cast<size_t>(y) * w + x) * 3];
      if (d[1] > 0) {
        s[0] = 0.3f + 0.3f * (1 - d[1]);
        s[1] = 0.5f + 0.3f * (1 - d[1]);
        s[2] = 1.0f;
      } else {
        s[0] = 0.25f;
        s[1] = 0.2f;
        s[2] = 0.15f;
      }
      if (d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2] > 0.9990f)
        for (int c = 0; c < 3; ++c) s[c] = 5000.0f;
      float* r = &room.rgb[(static_cast<size_t>(y) * w + x) * 3];
      const bool window = d[0] > 0.85f && std::fabs(d[1] - 0.1f) < 0.3f;
      for (int c = 0; c < 3; ++c) r[c] = window ? 30.0f : 0.08f + 0.04f * static_cast<float>(c == 0);
    }
  }
  maps.push_back(std::move(sky));
  maps.push_back(std::move(room));
  return maps;
}

}  // namespace probecast::bench
