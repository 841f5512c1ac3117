// The checks a Looking Glass calibration passes, shared by the parser and the interleaver.
#pragma once

#include <string>

#include "probecast/renderer/looking_glass.h"

namespace probecast::renderer {

// Throws std::invalid_argument, prefixed by `where`, for values outside what a panel can have.
void checkLookingGlassCalibration(const LookingGlassCalibration& c, const std::string& where);

}  // namespace probecast::renderer
