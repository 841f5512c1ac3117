// `probecast bench video`: the probe stream against streaming the same views as video.
//
// Several stream configurations (representation, noise rule) are measured on the same probes, so
// the stream too has points of bytes against PSNR.
// For each motion (a scene and the rate its clock runs at) the updater traces the probes at the
// stream's rate (--hz) while displays render at --fps: every frame each display's views are drawn
// twice, once from the updater's float probes (the picture a perfect link would give, and what a
// video server would encode) and once from what a subscriber decodes from the stream (the probe
// stream's picture), both tone-mapped to the 8-bit pixels a screen shows. The float frames are then
// encoded with ffmpeg (x265 and AV1, 4:4:4 and 4:2:0, low latency, a fixed GOP, a CRF sweep),
// decoded, and set against the float frames. Both PSNRs are over all frames of a display (RGB,
// peak 255, from the summed squared error). The video's bytes at the probe stream's PSNR come from
// the sweep (log bytes linear in PSNR between neighbouring points); outside the sweep the bound is
// given as such.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/codec/stream.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/vulkan_context.h"
#include "probecast/scene/scene.h"
#include "probecast/session/head_trace.h"

namespace probecast::bench {

// A display: a view set (renderer/view_sets.h) at a size per view, shown as one quilt.
struct VideoDisplay {
  std::string name;
  std::string viewSet;  // stereo, lf:NxM, lfh:NxM, mono
  uint32_t width = 0, height = 0;  // per view; even (4:2:0 needs even frame sizes)
  bool followsHead = true;  // its camera turns with VideoBenchOptions::headTrace (a headset; not a panel)
};

// What moves: `scene` (glTF or builtin:NAME) with its clock at `rate` scene seconds per second.
struct VideoMotion {
  std::string name;
  std::string scene;
  double rate = 0.0;
};

// One video encoder setting, swept over `crfs`.
struct VideoCodec {
  std::string name;     // x265-444, x265-420, av1-444, av1-420
  std::string encoder;  // libx265 or libaom-av1
  std::string pixFmt;   // yuv444p or yuv420p
  std::vector<int> crfs;
};

// A probe stream configuration: a representation and the encoder's rules.
struct VideoStream {
  std::string name;
  Representation repr = Representation::Zh3;
  EncoderOptions encoder;
};

// "x265-444", "x265-420", "av1-444" or "av1-420" with the CRFs of its family; false with a message.
bool parseVideoCodec(const std::string& name, const std::vector<int>& x265Crfs, const std::vector<int>& av1Crfs,
                     VideoCodec& out, std::string& error);
// "NAME=VIEWSET@WxH"; false with a message.
bool parseVideoDisplay(const std::string& text, VideoDisplay& out, std::string& error);

struct VideoBenchOptions {
  std::vector<VideoMotion> motions;
  std::vector<VideoDisplay> displays;
  std::vector<VideoCodec> codecs;
  std::function<ProbeGrid(const scene::Scene&)> grid;  // the probe grid for a motion's scene
  renderer::UpdaterOptions updater;  // areaLights as the raster client's
  renderer::ContextOptions context;
  renderer::RasterOptions raster;
  std::vector<VideoStream> streams;  // measured side by side on the same probes
  double hz = 10.0;        // probe updates per second
  double fps = 30.0;       // display frames per second
  uint32_t frames = 60;    // recorded frames per motion
  uint32_t warmup = 16;    // probe updates at scene time 0 before recording
  uint32_t gop = 30;       // video frames per keyframe interval
  // The camera of every display that follows a head turns as this head turned
  // (session/head_trace.h), from its start, at the display clock; none: the cameras are still.
  std::shared_ptr<const session::HeadTrace> headTrace;
  // Converged truth: every recorded moment's probes traced again from scratch for this many
  // updates, drawn through the same raster, and the streams and the videos scored against that
  // picture too (beside the float-probe one); 0: off.
  uint32_t truthUpdates = 0;
  std::string preset = "medium";  // x265's preset; AV1 (libaom, realtime) runs at cpu-used 6
  float exposure = 1.0f;
  std::string ffmpeg = "ffmpeg";
  std::string workDir;  // a folder of the run's own is made in here (removed at the end unless keepFiles)
  bool keepFiles = false;
  std::string command;
  std::function<void(const std::string&)> progress;
};

struct VideoBenchResult {
  nlohmann::json json;
  std::string table;
  std::vector<std::pair<std::string, std::string>> charts;  // display name, SVG
};

// Throws std::invalid_argument for options that cannot run (no motion, display or codec; odd
// sizes; rates or counts out of range) and std::runtime_error when ffmpeg is missing or fails
// (with what it printed).
VideoBenchResult runVideoBench(const VideoBenchOptions& options);

}  // namespace probecast::bench
