// The parts of `probecast bench video` (video_bench.h) that its files share: one motion's probes
// and streams, each display's recorded frames, the video sweeps of those frames, and the report.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "probecast/codec/stream.h"
#include "probecast/imaging/svg_chart.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/viewer.h"
#include "video_bench.h"

namespace probecast::bench::video {

// PSNR of 8-bit samples from their summed squared error (infinite for none).
double psnrFromSse(double sse, double samples);
// A PSNR for the JSON: the number, or "identical".
nlohmann::json dbJson(double db);
double squaredError(const uint8_t* a, const uint8_t* b, size_t n);

// A display's frames for one motion: the float-probe render (8-bit RGB, frame after frame) and the
// probe stream's squared error against it.
struct DisplayFrames {
  const VideoDisplay* display = nullptr;
  std::vector<renderer::ViewInfo> views;
  renderer::ViewSetSpec spec;
  renderer::CameraView camera;         // the scene's, before any head motion
  renderer::ViewSetOptions viewOptions;
  std::unique_ptr<renderer::RasterRenderer> floatRaster;
  std::vector<std::unique_ptr<renderer::RasterRenderer>> streamRasters;  // one per stream configuration
  uint32_t width = 0, height = 0;  // the quilt's
  std::vector<uint8_t> reference;
  std::vector<double> sse, worstFramePsnr;  // per stream configuration
  // With converged truth: its renderer, its frames, and each stream's and the float probes' error.
  std::unique_ptr<renderer::RasterRenderer> truthRaster;
  std::vector<uint8_t> truth;
  std::vector<double> truthSse;
  double floatTruthSse = 0.0;
};

// A view set's picture as 8-bit RGB through the viewer's curve; the display's views as one quilt.
std::vector<uint8_t> toRgb8(const renderer::Image& image, float exposure);
renderer::Image renderQuilt(renderer::RasterRenderer& r, const DisplayFrames& d);

struct VideoPoint {
  int crf = 0;
  double bytesPerSecond = 0.0, psnrDb = 0.0, encodeSeconds = 0.0;
  double truthPsnrDb = std::numeric_limits<double>::quiet_NaN();  // against converged truth, when measured
};

// The sweep's bytes at `psnr` (log bytes linear between neighbouring points), and whether that is
// a bound: "at least" above the sweep's best PSNR, "at most" below its worst.
struct AtPsnr {
  double bytesPerSecond = 0.0;
  std::string bound;  // "", "at_least" or "at_most"
};
AtPsnr bytesAtPsnr(std::vector<VideoPoint> points, double psnr);

// One stream configuration's encoder, the decoder a subscriber holds, and what it sent.
struct StreamState {
  const VideoStream* config = nullptr;
  std::unique_ptr<StreamEncoder> encoder;
  std::unique_ptr<StreamDecoder> decoder;
  ProbeVolume decoded;
  size_t bytes = 0, frames = 0, joinBytes = 0;
};

// The video sweeps of one display's frames: per codec, its points.
struct Sweeps {
  std::vector<std::vector<VideoPoint>> points;  // [codec]
  nlohmann::json json = nlohmann::json::array();
};

// Writes the display's recorded frames and encodes them at every codec's CRFs (video_encode.cpp),
// adding a series per codec to `chart`.
Sweeps sweepVideo(const VideoBenchOptions& o, const VideoMotion& m, DisplayFrames& df, const std::string& work,
                  std::vector<imaging::ChartSeries>& chart);
// ffmpeg runs and has the encoders asked for.
void checkFfmpeg(const VideoBenchOptions& o, const std::string& work);

// What every motion's phases see: the options, the GPU, the run's own folder and the seconds
// recorded per motion.
struct VideoSetup {
  const VideoBenchOptions& o;
  renderer::VulkanContext& context;
  const std::string& work;
  double seconds = 0.0;
};

// What the bench reports, filled motion by motion: a JSON entry and table rows per display and
// motion, and each display's chart series.
struct VideoReport {
  nlohmann::json results = nlohmann::json::array();
  std::string table, truthTable;  // the second: against converged truth, when measured
  std::vector<std::pair<std::string, std::vector<imaging::ChartSeries>>> chartSeries;  // per display
};

// One motion's probes: the scene as its clock runs, the updater tracing it, and the streams that
// carry the updater's probes to a subscriber's decoder.
struct MotionProbes {
  MotionProbes(const VideoSetup& s, const VideoMotion& m)
      : context(&s.context),
        current(session::loadSceneOrThrow(m.scene, 0.0)),
        moves(m.rate > 0 && session::sceneMoves(m.scene, current)),
        grid(s.o.grid(current)),
        updater(s.context, current, grid, s.o.updater),
        streams(s.o.streams.size()) {
    for (size_t k = 0; k < streams.size(); ++k) {
      streams[k].config = &s.o.streams[k];
      streams[k].encoder = std::make_unique<StreamEncoder>(streamLayoutFor(grid, s.o.streams[k].repr, 4), s.o.streams[k].encoder);
      streams[k].decoder = std::make_unique<StreamDecoder>(streams[k].encoder->layout());
    }
  }
  renderer::VulkanContext* context;
  scene::Scene current;
  bool moves = false;
  ProbeGrid grid;
  renderer::ProbeUpdater updater;
  std::vector<StreamState> streams;
  std::vector<uint8_t> frame;  // the stream frame last written
  double lastSceneTime = 0.0, updaterSceneTime = 0.0;
  uint32_t recordedUpdates = 0;
  // Converged truth (VideoBenchOptions::truthUpdates): the volume of the scene time `truthTime`,
  // `truthFresh` until every display has taken it.
  ProbeVolume truth;
  double truthTime = -1.0;
  bool truthFresh = false;
};

// The recording (video_frames.cpp): the warm-up updates and each stream's join keyframe; every
// display's views and renderers; the recorded frames.
void warmUp(const VideoBenchOptions& o, const VideoMotion& m, MotionProbes& p);
std::vector<DisplayFrames> makeDisplays(const VideoSetup& s, const MotionProbes& p);
void recordFrames(const VideoBenchOptions& o, const VideoMotion& m, MotionProbes& p, std::vector<DisplayFrames>& displays);

// The report (video_report.cpp): display `i`'s figures for a motion; the run's JSON, table and charts.
void reportDisplay(const VideoSetup& s, const VideoMotion& m, const MotionProbes& p, size_t i, DisplayFrames& df,
                   VideoReport& report);
VideoBenchResult videoResult(const VideoSetup& s, const VideoReport& report);

}  // namespace probecast::bench::video
