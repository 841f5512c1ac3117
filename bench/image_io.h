// Images on disk: linear float EXR for data, tone-mapped PNG for people.
#pragma once

#include <string>
#include <vector>

namespace probecast::bench {

// rgb: width × height × 3 floats, row-major from the top.
bool writeExr(const std::string& path, const std::vector<float>& rgb, int width, int height, std::string& error);
bool readExr(const std::string& path, std::vector<float>& rgb, int& width, int& height, std::string& error);
// Plain gamma 2.2 after exposure, clamped to [0, 1] (for looking at, not for metrics).
bool writePngPreview(const std::string& path, const std::vector<float>& rgb, int width, int height, float exposure,
                     std::string& error);

}  // namespace probecast::bench
