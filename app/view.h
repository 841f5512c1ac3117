// What `probecast view` shares between its command (commands_view.cpp) and its viewers of a
// server's stream (view_stream.cpp): its options, what a render returns, and the helpers both use.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "live_window.h"
#include "scene_options.h"
#include "probecast/imaging/image_io.h"
#include "probecast/renderer/looking_glass.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/service/client.h"
#include "probecast/session/scene_state.h"

namespace probecast::app {

// Everything `view` is told on its command line.
struct ViewOptions {
  TracingOptions tracing;
  ConnectOptions connection;
  std::string probes = "live", views = "lf:5x5", out = "out/view";
  std::string repr = "float", passes = "per-view", toneMap = "filmic";
  uint32_t shadowMap = 1024, shadowCascades = 4;
  AreaLightCli areaLights{"auto"};  // live: the default; a file or a server: as their probes say
  double waitSeconds = 3.0;
  std::vector<uint32_t> size{320, 200};
  uint32_t updates = 4;
  uint32_t supersample = renderer::RasterOptions{}.samplesPerSide;  // raster samples per pixel side
  uint32_t msaa = renderer::RasterOptions{}.msaaSamples;
  uint32_t anisotropy = renderer::RasterOptions{}.anisotropy;  // texture taps along a footprint
  float exposure = 1.0f;
  bool exr = false;
  bool visibility = true;
  float visibilityReach = 1.0f;
  bool visibilityCulling = true;
  std::string sceneCache;             // --connect: where fetched scenes are kept (empty: the default)
  uint64_t sceneMaxBytes = uint64_t{4} << 30;
  LiveWindowOptions window;          // its --head-trace also moves the camera of --frames pictures
  uint32_t frames = 1;               // --head-trace without --window: pictures along the trace
  double fps = 30.0;                 // and their rate
  std::string lookingGlass;  // a display's calibration (visual.json)
  std::optional<service::SceneHash> streamScene;  // --connect: the scene drawn, which the stream must keep naming
  CLI::Option* viewsOption = nullptr;
  CLI::Option* sizeOption = nullptr;
};

// The views a render made, with its timings.
struct Rendered {
  std::vector<renderer::Image> images;
  double viewsMs = 0.0, shadowMs = 0.0;
};

// The picture a Looking Glass shows: the quilt interleaved by its calibration.
renderer::Image interleaved(renderer::VulkanContext& context, const std::vector<renderer::Image>& images,
                            const std::vector<renderer::ViewInfo>& views, const renderer::LookingGlassCalibration& lg);

// A window shows the interleaved image at the panel's native size.
void showOnLookingGlass(FrameSource& source, renderer::VulkanContext& context,
                        const renderer::LookingGlassCalibration* lg);

// --looking-glass: the display's calibration, its model's view set in `spec` and o.views, and its
// view size in o.size unless --size was given; one line says which (view_looking_glass.cpp).
renderer::LookingGlassCalibration lookingGlassViewSet(ViewOptions& o, renderer::ViewSetSpec& spec);

// Writes looking_glass.png and .exr: the rendered views interleaved for the panel.
void writeLookingGlass(const ViewOptions& o, renderer::VulkanContext& context,
                       const std::vector<renderer::Image>& images, const std::vector<renderer::ViewInfo>& views,
                       const renderer::LookingGlassCalibration& lg);

imaging::ToneMap toneMapOf(const ViewOptions& o);

// --- viewers of local probes (view_local.cpp) ---

// Local probes (--probes live or a file, through --repr) on a raster client of --size.
std::unique_ptr<renderer::RasterRenderer> localRaster(const ViewOptions& o, renderer::VulkanContext& context,
                                                      const scene::Scene& s, renderer::RasterOptions ro);

// The views drawn once from local probes.
Rendered renderLocal(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                     const std::vector<renderer::ViewInfo>& views, const renderer::RasterOptions& ro);

// A live window on local probes: a file's, or traced one update per frame up to --updates.
void windowLocal(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                 const renderer::ViewSetSpec& spec, const renderer::ViewSetOptions& vso, renderer::RasterOptions ro,
                 const renderer::LookingGlassCalibration* lg);

// --frames and --fps (view_sequence.cpp), and what they cannot go with, refused before anything starts.
void addViewSequenceOptions(CLI::App* cmd, ViewOptions& o);
void checkSequenceOptions(const ViewOptions& o);

// --head-trace without --window: --frames quilts, --fps apart, of the camera moved along the trace
// or path, drawn from one set of local probes: frame_NNNN.png (and .exr with --exr) in --out.
void writeSequence(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                   const renderer::ViewSetSpec& spec, const renderer::ViewSetOptions& vso,
                   const renderer::RasterOptions& ro);

// One line on the client area lights a viewer draws (as the probes say).
void printAreaLights(const AreaLightRule& rule, const scene::AreaLightSet& set);

// --- viewers of the server --connect names (view_stream.cpp) ---

// The scene a --connect viewer draws: the stream's (fetched, or its own --scene checked against it).
session::ViewerScene streamScene(const ViewOptions& o);

// A viewer of a server's stream: subscribe for --wait seconds, then render what it holds at its
// display clock (`sceneSpec` shaded at the display time).
Rendered renderFromServer(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                          const std::string& sceneSpec, const std::vector<renderer::ViewInfo>& views,
                          const renderer::RasterOptions& ro);

// A live window on a server's stream: every display frame drawn at the display clock from the
// newest volume held, through stalls and reconnects.
void windowFromServer(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                      const std::string& sceneSpec, const renderer::ViewSetSpec& spec,
                      const renderer::ViewSetOptions& vso, const renderer::RasterOptions& ro,
                      const renderer::LookingGlassCalibration* lg);

}  // namespace probecast::app
