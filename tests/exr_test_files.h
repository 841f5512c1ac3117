// Test support: EXR files written with OpenEXR directly, in each compression, to check what
// probecast reads (imaging::readExr, bench::loadEnvMap) against what was written.
#pragma once

#include <string>
#include <vector>

namespace probecast::testing {

struct ExrCompressionCase {
  const char* name;   // "ZIP", "B44", … (OpenEXR's names, used in file names)
  int compression;    // Imf::Compression
  bool half;          // stored as HALF (B44/B44A/DWA compress only half channels lossily)
  float tolerance;    // max |read − stored| / max(1, |stored|); 0 = exact
};

// NO, RLE, ZIPS, ZIP, PIZ (float, exact), PXR24 (float → 24-bit float), B44, B44A, DWAA, DWAB (half, lossy).
const std::vector<ExrCompressionCase>& exrCompressionCases();

// A smooth HDR test image (width × height × 3, values in about [0.01, 6]) with a few sharp edges.
std::vector<float> exrTestImage(int width, int height);

// Rounds each value to the nearest half (what a HALF channel stores).
std::vector<float> roundToHalf(const std::vector<float>& rgb);

// Writes `rgb` with OpenEXR as R, G, B (or, with `luminanceOnly`, only Y = the R values), plus an
// A channel when `withAlpha`. The data window is offset by (dataX, dataY) inside a display window
// of the same size when both are 0, else the display window is (0,0)-(width-1,height-1) and the
// data window the same size shifted. Throws on failure.
void writeTestExr(const std::string& path, const std::vector<float>& rgb, int width, int height, int compression,
                  bool half, bool luminanceOnly = false, bool withAlpha = false, int dataX = 0, int dataY = 0);

}  // namespace probecast::testing
