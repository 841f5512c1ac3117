// Which probes viewers can see: the weight the updater's ray budget gives each probe for being
// inside some subscriber's view (ProbeUpdater::setViewWeights).
#pragma once

#include <span>
#include <vector>

#include "probecast/codec/priority.h"
#include "probecast/codec/probe_offsets.h"
#include "probecast/codec/probe_volume.h"

namespace probecast::session {

// Per probe (grid order): 1 when the box it shades (its position, plus `offsets` when not empty,
// grown by one cell on every side: its trilinear support) meets the frustum of any of `views`,
// else 0. Empty when there are no views: nobody's interest is known, every probe counts alike.
// A view with non-finite numbers sees nothing.
std::vector<float> probeViewWeights(const ProbeGrid& grid, const std::vector<float>& offsets, std::span<const View> views);

}  // namespace probecast::session
