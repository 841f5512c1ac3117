#include "probecast/imaging/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include <stb_image.h>
#include <stb_image_write.h>
#include <tinyexr.h>

namespace probecast::imaging {

bool writeExr(const std::string& path, const std::vector<float>& rgb, int width, int height, std::string& error) {
  if (rgb.size() != static_cast<size_t>(width) * height * 3) return error = path + ": image size mismatch", false;
  const char* err = nullptr;
  if (SaveEXR(rgb.data(), width, height, 3, 0, path.c_str(), &err) != TINYEXR_SUCCESS) {
    error = path + ": cannot write EXR (" + (err ? err : "unknown") + ")";
    if (err) FreeEXRErrorMessage(err);
    return false;
  }
  return true;
}

bool readExr(const std::string& path, std::vector<float>& rgb, int& width, int& height, std::string& error) {
  float* data = nullptr;
  const char* err = nullptr;
  if (LoadEXR(&data, &width, &height, path.c_str(), &err) != TINYEXR_SUCCESS) {
    error = path + ": cannot read EXR (" + (err ? err : "unknown") + ")";
    if (err) FreeEXRErrorMessage(err);
    return false;
  }
  rgb.resize(static_cast<size_t>(width) * height * 3);
  for (size_t i = 0; i < static_cast<size_t>(width) * height; ++i)
    for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = data[i * 4 + c];
  std::free(data);
  return true;
}

bool readHdr(const std::string& path, std::vector<float>& rgb, int& width, int& height, std::string& error) {
  int channels = 0;
  float* data = stbi_loadf(path.c_str(), &width, &height, &channels, 3);
  if (!data) {
    error = path + ": cannot read Radiance HDR (" + (stbi_failure_reason() ? stbi_failure_reason() : "unknown") + ")";
    return false;
  }
  rgb.assign(data, data + static_cast<size_t>(width) * height * 3);
  stbi_image_free(data);
  return true;
}

bool parseToneMap(const std::string& name, ToneMap& out) {
  if (name == "filmic") out = ToneMap::Filmic;
  else if (name == "gamma") out = ToneMap::Gamma;
  else return false;
  return true;
}

bool writePngPreview(const std::string& path, const std::vector<float>& rgb, int width, int height, float exposure,
                     std::string& error, ToneMap toneMap) {
  std::vector<uint8_t> bytes(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    float v = std::isfinite(rgb[i]) ? std::max(0.0f, rgb[i] * exposure) : 0.0f;
    if (toneMap == ToneMap::Filmic) v = v * (2.51f * v + 0.03f) / (v * (2.43f * v + 0.59f) + 0.14f);
    bytes[i] = static_cast<uint8_t>(std::lround(255.0f * std::min(1.0f, std::pow(v, 1.0f / 2.2f))));
  }
  if (!stbi_write_png(path.c_str(), width, height, 3, bytes.data(), width * 3))
    return error = path + ": cannot write PNG", false;
  return true;
}

}  // namespace probecast::imaging
