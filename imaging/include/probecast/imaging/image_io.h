// Images on disk: linear float EXR for data, tone-mapped PNG for people.
#pragma once

#include <string>
#include <vector>

namespace probecast::imaging {

// rgb: width × height × 3 floats, row-major from the top.
bool writeExr(const std::string& path, const std::vector<float>& rgb, int width, int height, std::string& error);
bool readExr(const std::string& path, std::vector<float>& rgb, int& width, int& height, std::string& error);
// Radiance .hdr (RGBE) as linear float RGB (stb_image).
bool readHdr(const std::string& path, std::vector<float>& rgb, int& width, int& height, std::string& error);
enum class ToneMap {
  Filmic,  // Narkowicz's fit of the ACES filmic curve (2015), then gamma 2.2: highlights roll off
  Gamma,   // plain gamma 2.2, clamped: what the metrics see, minus the clamp
};
// A PNG for people to look at: exposure, tone map, 8 bits (not for metrics: use the EXR).
bool writePngPreview(const std::string& path, const std::vector<float>& rgb, int width, int height, float exposure,
                     std::string& error, ToneMap toneMap = ToneMap::Filmic);
// "filmic" or "gamma".
bool parseToneMap(const std::string& name, ToneMap& out);

}  // namespace probecast::imaging
