// libFuzzer target: arbitrary bytes as a Looking Glass calibration (visual.json), as `view
// --looking-glass` reads one. Refusals are std::invalid_argument with a message; an accepted
// calibration must hold values a panel can have, and the quilt layout for it.
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "probecast/renderer/looking_glass.h"

using namespace probecast::renderer;

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  LookingGlassCalibration c;
  try {
    c = parseLookingGlassCalibration(text);
  } catch (const std::invalid_argument& e) {
    require(std::string(e.what()).rfind("visual.json: ", 0) == 0);
    return 0;
  }
  require(std::isfinite(c.pitch) && c.pitch > 0.0f && std::isfinite(c.slope) && c.slope != 0.0f &&
          std::isfinite(c.center) && std::isfinite(c.dpi) && c.dpi > 0.0f);
  require(c.screenW >= 1 && c.screenW <= 16384 && c.screenH >= 1 && c.screenH <= 16384);
  require(c.quiltColumns >= 1 && c.quiltRows >= 1 && c.quiltColumns * c.quiltRows <= 81 && c.viewHeight >= 1);
  require(c.cellPatternMode >= 0 && c.cellPatternMode <= 4 && c.subpixelCells.size() <= 64);
  for (const LookingGlassSubpixelCell& cell : c.subpixelCells)
    for (int i = 0; i < 3; ++i)
      require(std::isfinite(cell.dx[i]) && std::fabs(cell.dx[i]) <= 4.0 && std::isfinite(cell.dy[i]) &&
              std::fabs(cell.dy[i]) <= 4.0);
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 4; ++y) {
      const int cell = cellOfPixel(c.cellPatternMode, static_cast<int>(c.subpixelCells.size()), x, y);
      require(cell >= 0 && (c.subpixelCells.empty() ? cell == 0 : cell < static_cast<int>(c.subpixelCells.size())));
    }
  return 0;
}
