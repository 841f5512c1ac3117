// Environment maps: loading with checks, nearest-texel radiance, and the sampling distribution.
#include "probecast/renderer/environment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "probecast/codec/equirect.h"
#include "probecast/imaging/image_io.h"

namespace probecast::renderer {
namespace {

float luminance(const float* rgb) { return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2]; }

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

bool loadEnvironment(const std::string& path, float intensity, float rotationDegrees, Environment& env,
                     std::string& error) {
  if (!std::isfinite(intensity) || intensity < 0.0f) {
    char got[32];
    std::snprintf(got, sizeof got, "%g", static_cast<double>(intensity));
    error = std::string("environment intensity must be finite and >= 0 (got ") + got + ")";
    return false;
  }
  if (!std::isfinite(rotationDegrees)) {
    error = "environment rotation must be finite";
    return false;
  }
  if (!std::filesystem::is_regular_file(path)) {
    error = path + ": no such file";
    return false;
  }
  Environment out;
  out.name = std::filesystem::path(path).filename().string();
  const std::string ext = lowerExtension(path);
  bool ok = false;
  if (ext == ".hdr") ok = imaging::readHdr(path, out.rgb, out.width, out.height, error);
  else if (ext == ".exr") ok = imaging::readExr(path, out.rgb, out.width, out.height, error);
  else error = path + ": not an environment map (expected .hdr or .exr)";
  if (!ok) return false;
  if (out.width < 2 || out.height < 1 || out.rgb.size() != static_cast<size_t>(out.width) * out.height * 3) {
    error = path + ": the map is too small (" + std::to_string(out.width) + "x" + std::to_string(out.height) + ")";
    return false;
  }
  size_t bad = 0, first = 0;
  for (size_t i = 0; i < out.rgb.size(); ++i)
    if (!std::isfinite(out.rgb[i]) || out.rgb[i] < 0.0f) {
      if (bad++ == 0) first = i / 3;
    }
  if (bad > 0) {
    error = path + ": " + std::to_string(bad) + " pixel values are not finite and non-negative radiance (the first at x " +
            std::to_string(first % static_cast<size_t>(out.width)) + ", y " +
            std::to_string(first / static_cast<size_t>(out.width)) + ")";
    return false;
  }
  for (float& v : out.rgb) v *= intensity;
  out.rotation = rotationDegrees * (3.14159265358979f / 180.0f);
  env = std::move(out);
  return true;
}

bool makeUniformSky(const glm::vec3& rgb, Environment& env, std::string& error) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(rgb[c]) || rgb[c] < 0.0f) {
      error = "sky radiance must be three finite values >= 0";
      return false;
    }
  env = Environment{};
  env.name = "sky";
  env.width = env.height = 1;  // one texel covers the sphere: sampling it is uniform on the sphere
  env.rgb = {rgb.r, rgb.g, rgb.b};
  return true;
}

glm::vec3 environmentToMap(const Environment& env, const glm::vec3& w) {
  const float c = std::cos(env.rotation), s = std::sin(env.rotation);
  return {c * w.x - s * w.z, w.y, s * w.x + c * w.z};
}

glm::vec3 environmentToWorld(const Environment& env, const glm::vec3& m) {
  const float c = std::cos(env.rotation), s = std::sin(env.rotation);
  return {c * m.x + s * m.z, m.y, -s * m.x + c * m.z};
}

glm::vec3 environmentRadiance(const Environment& env, const glm::vec3& dir) {
  if (env.empty()) return glm::vec3(0.0f);
  const glm::vec3 m = environmentToMap(env, dir);
  const float d[3] = {m.x, m.y, m.z};
  int x = 0, y = 0;
  equirectPixel(env.width, env.height, d, x, y);
  const float* p = &env.rgb[(static_cast<size_t>(y) * env.width + x) * 3];
  return {p[0], p[1], p[2]};
}

EnvironmentDistribution buildEnvironmentDistribution(const Environment& env) {
  EnvironmentDistribution dist;
  if (env.empty()) return dist;
  const auto w = static_cast<size_t>(env.width), h = static_cast<size_t>(env.height);
  dist.rows.resize(h);
  dist.columns.resize(h * w);
  std::vector<double> rowWeight(h, 0.0);
  for (size_t y = 0; y < h; ++y) {
    const double omega = equirectPixelSolidAngle(env.width, env.height, static_cast<int>(y));
    double sum = 0.0;
    for (size_t x = 0; x < w; ++x) {
      sum += static_cast<double>(luminance(&env.rgb[(y * w + x) * 3]));
      dist.columns[y * w + x] = static_cast<float>(sum);
    }
    for (size_t x = 0; x < w; ++x)  // a black row is never chosen; keep its CDF well formed anyway
      dist.columns[y * w + x] = sum > 0.0 ? static_cast<float>(dist.columns[y * w + x] / sum)
                                          : static_cast<float>(x + 1) / static_cast<float>(w);
    dist.columns[y * w + w - 1] = 1.0f;
    rowWeight[y] = sum * omega;
    dist.total += rowWeight[y];
  }
  double cumulative = 0.0;
  for (size_t y = 0; y < h; ++y) {
    cumulative += rowWeight[y];
    dist.rows[y] = dist.total > 0.0 ? static_cast<float>(cumulative / dist.total)
                                    : static_cast<float>(y + 1) / static_cast<float>(h);
  }
  dist.rows[h - 1] = 1.0f;  // a uniform draw in [0, 1) always lands on a row
  return dist;
}

}  // namespace probecast::renderer
