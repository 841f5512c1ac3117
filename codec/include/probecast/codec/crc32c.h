// CRC-32C of frame headers and sections (private to the codec; declared for tests under internal/).
#pragma once

#include "probecast/codec/internal/crc32c.h"
