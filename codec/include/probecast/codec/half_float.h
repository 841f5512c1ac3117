// IEEE 754 binary16 conversion, round to nearest even, with Inf/NaN/subnormals.
#pragma once

#include <cstdint>

namespace probecast {

uint16_t floatToHalf(float value);
float halfToFloat(uint16_t half);

}  // namespace probecast
