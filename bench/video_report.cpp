// bench video's report: per display and motion, each stream's bytes and PSNR against the video's
// bytes at that PSNR (and against converged truth), the table and a chart per display.
#include "video_parts.h"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "harness.h"
#include "probecast/imaging/image_io.h"
#include "probecast/imaging/svg_chart.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/viewer.h"

namespace probecast::bench::video {
namespace {

// The video's bytes at a stream's PSNR: per codec, and the codec that needs the fewest.
struct VideoAtPsnr {
  nlohmann::json perCodec = nlohmann::json::array();
  std::string bestName, bestBound;
  double bestBytes = std::numeric_limits<double>::infinity();
};

// `truth`: the sweeps' PSNR against converged truth, not against the float-probe render.
VideoAtPsnr videoAtPsnr(const VideoBenchOptions& o, const Sweeps& sweeps, double psnr, bool truth = false) {
  VideoAtPsnr v;
  for (size_t c = 0; c < o.codecs.size(); ++c) {
    std::vector<VideoPoint> points = sweeps.points[c];
    if (truth)
      for (VideoPoint& q : points) q.psnrDb = q.truthPsnrDb;
    const AtPsnr at = bytesAtPsnr(points, psnr);
    v.perCodec.push_back({{"codec", o.codecs[c].name},
                          {"bytes_per_second", at.bytesPerSecond},
                          {"bound", at.bound.empty() ? nlohmann::json(nullptr) : nlohmann::json(at.bound)}});
    if (at.bytesPerSecond < v.bestBytes) v.bestBytes = at.bytesPerSecond, v.bestName = o.codecs[c].name, v.bestBound = at.bound;
  }
  return v;
}

// Stream `k`'s PSNR against converged truth and the video's bytes at that PSNR (also against
// truth), into the JSON and the truth table's rows.
void addTruthFigures(const VideoBenchOptions& o, const Sweeps& sweeps, const DisplayFrames& df, const std::string& motion,
                     size_t k, double bytesPerSecond, VideoReport& report, nlohmann::json& results) {
  const double psnr = psnrFromSse(df.truthSse[k], static_cast<double>(df.truth.size()));
  const VideoAtPsnr v = videoAtPsnr(o, sweeps, psnr, /*truth=*/true);
  const double ratio = bytesPerSecond > 0 ? v.bestBytes / bytesPerSecond : std::numeric_limits<double>::infinity();
  results.push_back({{"stream", o.streams[k].name},
                     {"psnr_db", dbJson(psnr)},
                     {"video_at_equal_psnr", v.perCodec},
                     {"best_video", v.bestName},
                     {"best_video_bytes_per_second", v.bestBytes},
                     {"best_video_bound", v.bestBound.empty() ? nlohmann::json(nullptr) : nlohmann::json(v.bestBound)},
                     {"video_to_probe_bytes", std::isfinite(ratio) ? nlohmann::json(ratio) : nlohmann::json(nullptr)}});
  const char* mark = v.bestBound == "at_least" ? "≥" : (v.bestBound == "at_most" ? "≤" : "");
  report.truthTable += fmt::format("{:<10} {:<8} {:<8} {:>10.0f} {:>7} {:>9} {:>3}{:>7.0f} {:>3}{:>5}\n", df.display->name,
                                   motion, o.streams[k].name, bytesPerSecond,
                                   std::isfinite(psnr) ? fmt::format("{:.2f}", psnr) : std::string("same"), v.bestName,
                                   mark, v.bestBytes, mark, std::isfinite(ratio) ? fmt::format("{:.1f}", ratio) : "-");
}

}  // namespace

// Display `i`'s figures for a motion: its video sweeps, then per stream its bytes and PSNR against
// the video's bytes at that PSNR, into the JSON, the table and the display's chart.
void reportDisplay(const VideoSetup& s, const VideoMotion& m, const MotionProbes& p, size_t i, DisplayFrames& df,
                   VideoReport& report) {
  const VideoBenchOptions& o = s.o;
  const Sweeps sweeps = sweepVideo(o, m, df, s.work, report.chartSeries[i].second);
  nlohmann::json streamResults = nlohmann::json::array(), streamResultsTruth = nlohmann::json::array();
  for (size_t k = 0; k < p.streams.size(); ++k) {
    const StreamState& st = p.streams[k];
    const double bytesPerSecond = static_cast<double>(st.bytes) / s.seconds;
    const double psnr = psnrFromSse(df.sse[k], static_cast<double>(df.reference.size()));
    const VideoAtPsnr v = videoAtPsnr(o, sweeps, psnr);
    const double ratio = bytesPerSecond > 0 ? v.bestBytes / bytesPerSecond : std::numeric_limits<double>::infinity();
    if (!df.truth.empty()) addTruthFigures(o, sweeps, df, m.name, k, bytesPerSecond, report, streamResultsTruth);
    streamResults.push_back({{"stream", st.config->name},
                             {"representation", representationName(st.config->repr)},
                             {"deadzone", st.config->encoder.deadzone},
                             {"noise_scale", st.config->encoder.noiseScale},
                             {"frames_sent", st.frames},
                             {"bytes_per_second", bytesPerSecond},
                             {"join_bytes", st.joinBytes},
                             {"psnr_db", dbJson(psnr)},
                             {"psnr_db_worst_frame", dbJson(df.worstFramePsnr[k])},
                             {"video_at_equal_psnr", v.perCodec},
                             {"best_video", v.bestName},
                             {"best_video_bytes_per_second", v.bestBytes},
                             {"best_video_bound", v.bestBound.empty() ? nlohmann::json(nullptr) : nlohmann::json(v.bestBound)},
                             {"video_to_probe_bytes", std::isfinite(ratio) ? nlohmann::json(ratio) : nlohmann::json(nullptr)}});
    report.chartSeries[i].second.push_back(
        {m.name + " " + st.config->name, {{std::max(bytesPerSecond, 1.0), std::isfinite(psnr) ? psnr : 99.0, st.config->name}}, false});
    const char* mark = v.bestBound == "at_least" ? "≥" : (v.bestBound == "at_most" ? "≤" : "");
    report.table += fmt::format("{:<10} {:<8} {:<8} {:>10.0f} {:>7} {:>9} {:>3}{:>7.0f} {:>3}{:>5}\n", df.display->name,
                                m.name, st.config->name, bytesPerSecond,
                                std::isfinite(psnr) ? fmt::format("{:.2f}", psnr) : std::string("same"), v.bestName, mark,
                                v.bestBytes, mark, std::isfinite(ratio) ? fmt::format("{:.1f}", ratio) : std::string("-"));
  }
  report.results.push_back({{"display", df.display->name},
                            {"follows_head", o.headTrace != nullptr && df.display->followsHead},
                            {"view_set", df.display->viewSet},
                            {"frame_size", {df.width, df.height}},
                            {"motion", m.name},
                            {"scene", m.scene},
                            {"rate", m.rate},
                            {"grid", {p.grid.dims[0], p.grid.dims[1], p.grid.dims[2]}},
                            {"probe_updates", p.recordedUpdates},
                            {"video", sweeps.json},
                            {"streams", streamResults}});
  if (!df.truth.empty()) {
    const double n = static_cast<double>(df.truth.size());
    report.results.back()["against_converged_truth"] = {{"float_probes_psnr_db", dbJson(psnrFromSse(df.floatTruthSse, n))},
                                                       {"streams", streamResultsTruth}};
  }
}

// The run's JSON (its settings and every display and motion's figures), its table, and a chart per
// display.
VideoBenchResult videoResult(const VideoSetup& s, const VideoReport& report) {
  const VideoBenchOptions& o = s.o;
  VideoBenchResult r;
  r.json = {{"command", o.command},
            {"probe_hz", o.hz},
            {"fps", o.fps},
            {"frames", o.frames},
            {"seconds", s.seconds},
            {"warmup_updates", o.warmup},
            {"gop", o.gop},
            {"camera", !o.headTrace         ? std::string("still")
                       : o.headTrace->isPath() ? fmt::format("a scripted camera path ({:.1f} s, looping)", o.headTrace->duration())
                                               : fmt::format("a recorded head's motion ({:.1f} s trace), neck model {} m ahead, {} m up",
                                                             o.headTrace->duration(), session::kNeckForward, session::kNeckUp)},
            {"x265", fmt::format("libx265, preset {}, tune zerolatency (no B-frames, no lookahead)", o.preset)},
            {"av1", "libaom-av1, realtime usage, cpu-used 6, no lag"},
            {"psnr", "8-bit RGB of every frame against the float-probe render's, from the summed squared error"},
            {"probe_bytes", "stream frames of the changed bricks after the warm-up (the join keyframe apart)"},
            {"results", report.results}};
  if (o.keepFiles) r.json["kept_files"] = s.work;  // the run's own folder in --work-dir
  r.table = "bench video: bytes per second at equal PSNR against the float-probe render (≤/≥: beyond the CRF sweep)\n" + report.table;
  if (o.truthUpdates > 0) {
    r.json["truth"] = fmt::format("each recorded moment's probes traced from scratch for {} updates of {} samples per "
                                  "probe, through the same raster",
                                  o.truthUpdates, o.updater.samplesPerProbe);
    r.table += "\nagainst converged truth\n" +
               fmt::format("{:<10} {:<8} {:<8} {:>10} {:>7} {:>9} {:>10} {:>8}\n", "display", "motion", "stream",
                           "probes B/s", "dB", "video", "video B/s", "ratio") +
               report.truthTable;
  }
  for (const auto& [name, series] : report.chartSeries) {
    imaging::ChartSpec spec;
    spec.title = "Probe stream against video: " + name;
    spec.xLabel = "bytes per second";
    spec.yLabel = "PSNR against the float-probe render (dB)";
    spec.logX = true;
    spec.yFromZero = false;
    spec.footnote = o.command;
    r.charts.push_back({name, imaging::renderSvgChart(spec, series)});
  }
  return r;
}

}  // namespace probecast::bench::video
