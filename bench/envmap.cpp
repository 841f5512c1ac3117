#include "envmap.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <stb_image.h>

#include "probecast/imaging/image_io.h"

#include "probecast/codec/equirect.h"

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
  equirectDirection(map.width, map.height, x, y, dir);
}

float envMapPixelSolidAngle(const EnvMap& map, int y) { return equirectPixelSolidAngle(map.width, map.height, y); }

EnvMap downsample(const EnvMap& map, int factor) {
  EnvMap out;
  out.name = map.name;
  out.rgb = equirectDownsample(map.rgb.data(), map.width, map.height, factor, out.width, out.height);
  return out;
}

void projectToSh(const EnvMap& map, float probe[kProbeFloats], float rotationY) {
  equirectProjectSh(map.rgb.data(), map.width, map.height, probe, rotationY);
}

void bruteForceIrradiance(const EnvMap& map, const std::vector<float>& normals, std::vector<float>& irradiance) {
  irradiance.assign(normals.size() / 3 * 3, 0.0f);
  equirectIrradiance(map.rgb.data(), map.width, map.height, normals.data(), normals.size() / 3, irradiance.data());
}

std::vector<float> fibonacciSphere(int count) { return probecast::fibonacciSphere(count); }

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
