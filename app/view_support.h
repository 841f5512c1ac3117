// Shared by `probecast view` and `probecast demo`: view sets of a scene's camera, as the raster
// client draws them and as the service's priority needs them.
#pragma once

#include <vector>

#include "probecast/codec/priority.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/scene/scene.h"

namespace probecast::app {

// Views of width × height with the display plane through the centre of the scene's bounds.
renderer::ViewSetOptions viewSetOptions(const scene::Scene& scene, uint32_t width, uint32_t height);
// The same views for the server's frustum priority.
std::vector<View> priorityViews(const std::vector<renderer::ViewInfo>& views);

}  // namespace probecast::app
