// Which probes viewers can see: the weight the updater's ray budget gives each probe for being
// inside some subscriber's view (ProbeUpdater::setViewWeights).
#pragma once

#include <span>
#include <vector>

#include "probecast/codec/priority.h"
#include "probecast/codec/probe_offsets.h"
#include "probecast/codec/probe_volume.h"
#include "probecast/scene/scene.h"

namespace probecast::session {

// Per probe (grid order): 1 when the box it shades (its position, plus `offsets` when not empty,
// grown by one cell on every side: its trilinear support) meets the frustum of any of `views`,
// else 0. Empty when there are no views: nobody's interest is known, every probe counts alike.
// A view with non-finite numbers sees nothing.
std::vector<float> probeViewWeights(const ProbeGrid& grid, const std::vector<float>& offsets, std::span<const View> views);

// Per probe (grid order): how much of the views' pixels it lights, Σ over the pixels of its
// normalised weight squared (what an error in that probe adds to the views' squared error, per
// unit of the pixel's irradiance). Each view's nearest surfaces are found at width × height pixel
// centres by a depth-buffered rasterisation of the scene's triangles on the CPU (Vulkan clip space,
// as View holds it: clipped at the near plane z = 0, nothing past the far one), and each point is lit as the raster client does without visibility: the eight
// probes of its grid cell, trilinear × backface ((cos + 1)/2)² + 0.2, the inactive ones left out.
// Empty when there are no views. A view with non-finite numbers sees nothing.
std::vector<float> probeViewFootprints(const scene::Scene& scene, const ProbeGrid& grid, std::span<const uint8_t> active,
                                       std::span<const View> views, uint32_t width = 64, uint32_t height = 40);

}  // namespace probecast::session
