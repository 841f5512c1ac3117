// The probe stream against video of the same views (video_bench.h).
#include "video_bench.h"

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

namespace probecast::bench {
namespace {

namespace fs = std::filesystem;

std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string fileTail(const std::string& path, size_t maxChars = 600) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s.size() > maxChars ? "…" + s.substr(s.size() - maxChars) : s;
}

int exitCode(int status) { return status == -1 ? -1 : (WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)); }

// Runs `cmd` through the shell with its output in `log`; throws with the log's tail on failure.
void runOrThrow(const std::string& cmd, const std::string& log, const std::string& what) {
  const int rc = exitCode(std::system((cmd + " >" + shellQuote(log) + " 2>&1").c_str()));
  if (rc != 0) throw std::runtime_error(fmt::format("bench video: {} failed (exit {}): {}", what, rc, fileTail(log)));
}

// What a command prints on stdout (its stderr to `log`); throws on failure.
std::string captureOrThrow(const std::string& cmd, const std::string& log, const std::string& what) {
  FILE* p = popen((cmd + " 2>" + shellQuote(log)).c_str(), "r");
  if (!p) throw std::runtime_error("bench video: cannot start " + what);
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int rc = exitCode(pclose(p));
  if (rc != 0) throw std::runtime_error(fmt::format("bench video: {} failed (exit {}): {}", what, rc, fileTail(log)));
  return out;
}

double psnrFromSse(double sse, double samples) {
  if (samples <= 0) return 0.0;
  if (sse <= 0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 * samples / sse);
}

nlohmann::json dbJson(double db) { return std::isfinite(db) ? nlohmann::json(db) : nlohmann::json("identical"); }

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

std::vector<uint8_t> toRgb8(const renderer::Image& image, float exposure) {
  const std::vector<unsigned char> rgba = imaging::toneMapRgba8(image.rgb, exposure);
  std::vector<uint8_t> rgb(static_cast<size_t>(image.width) * image.height * 3);
  for (size_t p = 0; p < rgb.size() / 3; ++p)
    for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = rgba[p * 4 + c];
  return rgb;
}

renderer::Image renderQuilt(renderer::RasterRenderer& r, const DisplayFrames& d) {
  const std::vector<renderer::Image> images = r.renderViews(d.views);
  return renderer::composeQuilt(images, d.views, d.spec.columns, d.spec.rows);
}

double squaredError(const uint8_t* a, const uint8_t* b, size_t n) {
  double s = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double e = static_cast<double>(a[i]) - static_cast<double>(b[i]);
    s += e * e;
  }
  return s;
}

struct VideoPoint {
  int crf = 0;
  double bytesPerSecond = 0.0, psnrDb = 0.0, encodeSeconds = 0.0;
  double truthPsnrDb = std::numeric_limits<double>::quiet_NaN();  // against converged truth, when measured
};

// Encodes `d.reference` at `crf`, decodes it and compares.
VideoPoint encodeAndMeasure(const VideoBenchOptions& o, const VideoCodec& c, int crf, const DisplayFrames& d,
                            const std::string& framesPath, const std::string& stem) {
  const bool hevc = c.encoder == "libx265";
  const std::string bitstream = stem + (hevc ? ".hevc" : ".obu");
  const std::string input = fmt::format("-f rawvideo -pix_fmt rgb24 -s {}x{} -r {} -i {}", d.width, d.height, o.fps,
                                        shellQuote(framesPath));
  std::string codec;
  if (hevc)
    codec = fmt::format(
        "-c:v libx265 -preset {} -tune zerolatency -crf {} -g {} -keyint_min {} "
        "-x265-params log-level=error:scenecut=0:open-gop=0 -pix_fmt {} -f hevc",
        o.preset, crf, o.gop, o.gop, c.pixFmt);
  else
    codec = fmt::format(
        "-c:v libaom-av1 -usage realtime -cpu-used 6 -lag-in-frames 0 -row-mt 1 -crf {} -b:v 0 -g {} "
        "-keyint_min {} -pix_fmt {} -f obu",
        crf, o.gop, o.gop, c.pixFmt);
  const auto t0 = std::chrono::steady_clock::now();
  runOrThrow(fmt::format("{} -nostdin -hide_banner -y {} {} {}", shellQuote(o.ffmpeg), input, codec, shellQuote(bitstream)),
             stem + ".encode.log", fmt::format("ffmpeg {} crf {}", c.name, crf));
  VideoPoint p;
  p.crf = crf;
  p.encodeSeconds = millisecondsSince(t0) / 1e3;
  const double seconds = static_cast<double>(o.frames) / o.fps;
  p.bytesPerSecond = static_cast<double>(fs::file_size(bitstream)) / seconds;
  const std::string decoded =
      captureOrThrow(fmt::format("{} -nostdin -hide_banner -v error -i {} -f rawvideo -pix_fmt rgb24 -",
                                 shellQuote(o.ffmpeg), shellQuote(bitstream)),
                     stem + ".decode.log", fmt::format("decoding {} crf {}", c.name, crf));
  if (decoded.size() != d.reference.size())
    throw std::runtime_error(fmt::format("bench video: {} crf {} decoded to {} bytes of frames, not {}", c.name, crf,
                                         decoded.size(), d.reference.size()));
  const auto* frames = reinterpret_cast<const uint8_t*>(decoded.data());
  p.psnrDb = psnrFromSse(squaredError(frames, d.reference.data(), decoded.size()), static_cast<double>(decoded.size()));
  if (!d.truth.empty())
    p.truthPsnrDb = psnrFromSse(squaredError(frames, d.truth.data(), decoded.size()), static_cast<double>(decoded.size()));
  if (!o.keepFiles) fs::remove(bitstream);
  return p;
}

// The sweep's bytes at `psnr` (log bytes linear between neighbouring points), and whether that is
// a bound: "at least" above the sweep's best PSNR, "at most" below its worst.
struct AtPsnr {
  double bytesPerSecond = 0.0;
  std::string bound;  // "", "at_least" or "at_most"
};

AtPsnr bytesAtPsnr(std::vector<VideoPoint> points, double psnr) {
  std::sort(points.begin(), points.end(), [](const VideoPoint& a, const VideoPoint& b) { return a.psnrDb < b.psnrDb; });
  if (psnr >= points.back().psnrDb) return {points.back().bytesPerSecond, psnr == points.back().psnrDb ? "" : "at_least"};
  if (psnr <= points.front().psnrDb) return {points.front().bytesPerSecond, psnr == points.front().psnrDb ? "" : "at_most"};
  for (size_t k = 1; k < points.size(); ++k)
    if (psnr <= points[k].psnrDb) {
      const VideoPoint& a = points[k - 1];
      const VideoPoint& b = points[k];
      const double f = b.psnrDb > a.psnrDb ? (psnr - a.psnrDb) / (b.psnrDb - a.psnrDb) : 0.0;
      const double la = std::log(std::max(a.bytesPerSecond, 1.0)), lb = std::log(std::max(b.bytesPerSecond, 1.0));
      return {std::exp(la + f * (lb - la)), ""};
    }
  return {points.back().bytesPerSecond, "at_least"};
}

void checkOptions(const VideoBenchOptions& o) {
  if (o.motions.empty()) throw std::invalid_argument("bench video: no motion to measure");
  if (o.displays.empty()) throw std::invalid_argument("bench video: no display to measure");
  if (o.codecs.empty()) throw std::invalid_argument("bench video: no video codec to measure");
  if (o.streams.empty()) throw std::invalid_argument("bench video: no stream configuration to measure");
  if (!o.grid) throw std::invalid_argument("bench video: no probe grid");
  if (!(o.hz > 0) || !(o.fps > 0) || !std::isfinite(o.hz) || !std::isfinite(o.fps) || o.hz > o.fps)
    throw std::invalid_argument("bench video: --hz and --fps must be positive, with no more probe updates than frames");
  if (o.frames < 2) throw std::invalid_argument("bench video: --frames must be at least 2");
  if (o.gop < 1) throw std::invalid_argument("bench video: --gop must be at least 1");
  for (const VideoMotion& m : o.motions)
    if (!std::isfinite(m.rate) || m.rate < 0)
      throw std::invalid_argument("bench video: motion " + m.name + " has a rate that is not finite and >= 0");
  for (const VideoDisplay& d : o.displays)
    if (d.width % 2 || d.height % 2 || d.width == 0 || d.height == 0)
      throw std::invalid_argument(fmt::format("bench video: display {} has views of {}x{}: both must be even (4:2:0)",
                                              d.name, d.width, d.height));
  for (const VideoCodec& c : o.codecs)
    if (c.crfs.empty()) throw std::invalid_argument("bench video: " + c.name + " has no CRF to sweep");
}

// ffmpeg runs and has the encoders asked for.
void checkFfmpeg(const VideoBenchOptions& o, const std::string& work) {
  const std::string log = work + "/ffmpeg-encoders.log";
  std::string encoders;
  try {
    encoders = captureOrThrow(shellQuote(o.ffmpeg) + " -hide_banner -encoders", log, "ffmpeg -encoders");
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(fmt::format("bench video: {} does not run ({}); install ffmpeg (Debian: apt install "
                                         "ffmpeg) or give its path with --ffmpeg",
                                         o.ffmpeg, e.what()));
  }
  for (const VideoCodec& c : o.codecs)
    if (encoders.find(" " + c.encoder + " ") == std::string::npos)
      throw std::runtime_error("bench video: " + o.ffmpeg + " has no " + c.encoder + " encoder (for " + c.name + ")");
}

}  // namespace

bool parseVideoCodec(const std::string& name, const std::vector<int>& x265Crfs, const std::vector<int>& av1Crfs,
                     VideoCodec& out, std::string& error) {
  static const struct {
    const char* name;
    const char* encoder;
    const char* pixFmt;
    bool hevc;
  } known[] = {{"x265-444", "libx265", "yuv444p", true},
               {"x265-420", "libx265", "yuv420p", true},
               {"av1-444", "libaom-av1", "yuv444p", false},
               {"av1-420", "libaom-av1", "yuv420p", false}};
  for (const auto& k : known)
    if (name == k.name) {
      out = {k.name, k.encoder, k.pixFmt, k.hevc ? x265Crfs : av1Crfs};
      return true;
    }
  error = "unknown video codec '" + name + "' (x265-444, x265-420, av1-444 or av1-420)";
  return false;
}

bool parseVideoDisplay(const std::string& text, VideoDisplay& out, std::string& error) {
  const size_t eq = text.find('='), at = text.find('@');
  unsigned w = 0, h = 0;
  char tail = 0;
  if (eq == std::string::npos || at == std::string::npos || at < eq || eq == 0 ||
      std::sscanf(text.c_str() + at + 1, "%ux%u%c", &w, &h, &tail) != 2) {
    error = "display '" + text + "' is not NAME=VIEWSET@WxH (e.g. quilt=lf:5x5@128x128)";
    return false;
  }
  out.name = text.substr(0, eq);
  out.viewSet = text.substr(eq + 1, at - eq - 1);
  renderer::ViewSetSpec spec;
  if (!renderer::parseViewSet(out.viewSet, spec, error)) return false;
  if (w < 8 || h < 8 || w > 4096 || h > 4096 || w % 2 || h % 2) {
    error = "display '" + text + "': views must be 8 to 4096 pixels a side, and even";
    return false;
  }
  out.width = w;
  out.height = h;
  return true;
}

namespace {

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

Sweeps sweepVideo(const VideoBenchOptions& o, const VideoMotion& m, DisplayFrames& df, const std::string& work,
                  std::vector<imaging::ChartSeries>& chart) {
  const std::string stem = (fs::path(work) / (m.name + "-" + df.display->name)).string();
  const std::string framesPath = stem + ".rgb";
  {
    std::ofstream out(framesPath, std::ios::binary);
    out.write(reinterpret_cast<const char*>(df.reference.data()), static_cast<std::streamsize>(df.reference.size()));
    if (!out) throw std::runtime_error("bench video: cannot write " + framesPath);
  }
  Sweeps sweeps;
  for (const VideoCodec& c : o.codecs) {
    std::vector<VideoPoint> points;
    nlohmann::json sweep = nlohmann::json::array();
    imaging::ChartSeries series{m.name + " " + c.name, {}, true};
    for (int crf : c.crfs) {
      sayProgress(o.progress, fmt::format("bench video: {} {}: {} crf {}", m.name, df.display->name, c.name, crf));
      const VideoPoint p = encodeAndMeasure(o, c, crf, df, framesPath, fmt::format("{}-{}-crf{}", stem, c.name, crf));
      points.push_back(p);
      sweep.push_back({{"crf", crf}, {"bytes_per_second", p.bytesPerSecond}, {"psnr_db", dbJson(p.psnrDb)},
                       {"encode_seconds", p.encodeSeconds}});
      if (!df.truth.empty()) sweep.back()["psnr_db_vs_truth"] = dbJson(p.truthPsnrDb);
      if (std::isfinite(p.psnrDb) && p.bytesPerSecond > 0) series.points.push_back({p.bytesPerSecond, p.psnrDb, ""});
    }
    sweeps.json.push_back({{"codec", c.name}, {"encoder", c.encoder}, {"pix_fmt", c.pixFmt}, {"sweep", sweep}});
    sweeps.points.push_back(std::move(points));
    std::sort(series.points.begin(), series.points.end(), [](const auto& a, const auto& b) { return a.x < b.x; });
    chart.push_back(std::move(series));
  }
  if (!o.keepFiles) fs::remove(framesPath);
  return sweeps;
}

}  // namespace

// A folder of this run's own inside `parent`: runs at the same time never share files, and nothing
// else in `parent` is touched. Removed with everything in it when the run ends (or fails) unless
// the files are kept.
struct RunFolder {
  std::string path;
  bool keep = false;
  RunFolder(const std::string& parent, bool keepFiles) : keep(keepFiles) {
    std::error_code ec;
    fs::create_directories(parent, ec);
    std::string pattern = (fs::path(parent) / "probecast-video-XXXXXX").string();
    if (ec || !mkdtemp(pattern.data()))
      throw std::runtime_error("bench video: cannot make a folder in " + parent + ": " +
                               (ec ? ec.message() : std::string(std::strerror(errno))));
    path = pattern;
  }
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;
  ~RunFolder() {
    std::error_code ec;
    if (!keep) fs::remove_all(path, ec);
  }
};

namespace {

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

// One probe update, encoded by every stream and applied by its decoder as a subscriber's would be;
// `count`: its frames count towards the stream's bytes (the warm-up's do not).
void updateProbes(MotionProbes& p, bool count) {
  p.updater.update();
  const ProbeVolume& v = p.updater.volume();
  for (StreamState& st : p.streams) {
    const uint32_t changed = st.encoder->update(v.probes.data(), v.active.data(), v.noise.empty() ? nullptr : v.noise.data(),
                                                v.stillUpdates.empty() ? nullptr : v.stillUpdates.data());
    if (changed > 0) {
      st.encoder->writeChangedFrame(p.frame);
      if (st.decoder->apply(p.frame.data(), p.frame.size()) != CodecStatus::Ok)
        throw std::runtime_error("bench video: the stream's own decoder refused a frame");
      if (count) st.bytes += p.frame.size(), ++st.frames;
    }
    st.decoded = v;
    st.decoder->copyVolume(p.grid.bounds, st.decoded);
  }
}

// The warm-up updates at scene time 0, then each stream's keyframe: what a subscriber joining then
// is sent.
void warmUp(const VideoBenchOptions& o, const VideoMotion& m, MotionProbes& p) {
  for (uint32_t k = 0; k < o.warmup; ++k) {
    updateProbes(p, false);
    sayProgress(o.progress, fmt::format("bench video: {}: warm-up update {}/{}", m.name, k + 1, o.warmup));
  }
  for (StreamState& st : p.streams) {
    st.encoder->writeKeyframeFrame(p.frame);
    st.joinBytes = p.frame.size();
  }
}

// Every display's views of the motion's scene, its renderers (one on the float probes, one per
// stream) and room for its recorded frames.
std::vector<DisplayFrames> makeDisplays(const VideoSetup& s, const MotionProbes& p) {
  const VideoBenchOptions& o = s.o;
  std::vector<DisplayFrames> displays(o.displays.size());
  for (size_t i = 0; i < o.displays.size(); ++i) {
    DisplayFrames& df = displays[i];
    df.display = &o.displays[i];
    std::string error;
    if (!renderer::parseViewSet(df.display->viewSet, df.spec, error)) throw std::invalid_argument(error);
    df.camera = renderer::CameraView::fromScene(p.current);
    df.viewOptions = session::viewSetOptions(p.current, df.display->width, df.display->height);
    df.views = renderer::makeViewSet(df.camera, df.spec, df.viewOptions);
    df.floatRaster = std::make_unique<renderer::RasterRenderer>(s.context, p.current, df.display->width,
                                                                df.display->height, o.raster);
    for (size_t k = 0; k < p.streams.size(); ++k)
      df.streamRasters.push_back(std::make_unique<renderer::RasterRenderer>(s.context, p.current, df.display->width,
                                                                            df.display->height, o.raster));
    df.sse.assign(p.streams.size(), 0.0);
    df.worstFramePsnr.assign(p.streams.size(), std::numeric_limits<double>::infinity());
    if (o.truthUpdates > 0) {
      df.truthRaster = std::make_unique<renderer::RasterRenderer>(s.context, p.current, df.display->width,
                                                                  df.display->height, o.raster);
      df.truthSse.assign(p.streams.size(), 0.0);
    }
    df.width = df.display->width * static_cast<uint32_t>(df.spec.columns);
    df.height = df.display->height * static_cast<uint32_t>(df.spec.rows);
    df.reference.reserve(static_cast<size_t>(df.width) * df.height * 3 * o.frames);
  }
  return displays;
}

// Converged truth at the scene as it stands now: its probes traced from scratch for
// truthUpdates updates, as the updater's own options say.
void convergeTruth(const VideoBenchOptions& o, const VideoMotion& m, MotionProbes& p, double sceneTime) {
  // Samples of its own: with the updater's seed its first updates would be the float probes' very
  // samples, and the truth would lean towards them.
  renderer::UpdaterOptions options = o.updater;
  options.seed ^= 0x9e3779b9u;
  renderer::ProbeUpdater truth(*p.context, p.current, p.grid, options);
  for (uint32_t k = 0; k < o.truthUpdates; ++k) truth.update();
  p.truth = truth.volume();
  p.truthTime = sceneTime;
  p.truthFresh = true;
  sayProgress(o.progress, fmt::format("bench video: {}: converged truth at scene time {:.3f} s", m.name, sceneTime));
}

// The truth's picture of the frame, and every stream's and the float probes' error against it.
void scoreAgainstTruth(const MotionProbes& p, DisplayFrames& df, bool moved, const std::vector<uint8_t>& floatRgb,
                       const std::vector<std::vector<uint8_t>>& streamRgb, float exposure) {
  if (moved) df.truthRaster->setShading(p.current);
  if (p.truthFresh) df.truthRaster->setProbes(p.truth);
  const std::vector<uint8_t> truth = toRgb8(renderQuilt(*df.truthRaster, df), exposure);
  for (size_t k = 0; k < streamRgb.size(); ++k) df.truthSse[k] += squaredError(streamRgb[k].data(), truth.data(), truth.size());
  df.floatTruthSse += squaredError(floatRgb.data(), truth.data(), truth.size());
  df.truth.insert(df.truth.end(), truth.begin(), truth.end());
}

// One display's frame at display time `t`: the float probes' picture, kept for the video, and each
// stream's, set against it. `moved`: the scene moved since the last frame; `update`: the probes did.
void renderFrame(const VideoBenchOptions& o, const MotionProbes& p, DisplayFrames& df, double t, bool moved, bool update) {
  if (moved) {
    df.floatRaster->setShading(p.current);
    for (auto& r : df.streamRasters) r->setShading(p.current);
  }
  if (o.headTrace && df.display->followsHead)
    df.views = renderer::makeViewSet(session::poseCamera(df.camera, *o.headTrace, t), df.spec, df.viewOptions);
  if (update) {
    df.floatRaster->setProbes(p.updater.volume());
    for (size_t k = 0; k < p.streams.size(); ++k) df.streamRasters[k]->setProbes(p.streams[k].decoded);
  }
  const std::vector<uint8_t> ref = toRgb8(renderQuilt(*df.floatRaster, df), o.exposure);
  std::vector<std::vector<uint8_t>> streamRgb;
  for (size_t k = 0; k < p.streams.size(); ++k) {
    streamRgb.push_back(toRgb8(renderQuilt(*df.streamRasters[k], df), o.exposure));
    const double sse = squaredError(streamRgb.back().data(), ref.data(), ref.size());
    df.sse[k] += sse;
    df.worstFramePsnr[k] = std::min(df.worstFramePsnr[k], psnrFromSse(sse, static_cast<double>(ref.size())));
  }
  if (df.truthRaster) scoreAgainstTruth(p, df, moved, ref, streamRgb, o.exposure);
  df.reference.insert(df.reference.end(), ref.begin(), ref.end());
}

// The recorded frames: the scene clock runs at the motion's rate, the probes update at --hz and
// every display draws every frame at --fps.
void recordFrames(const VideoBenchOptions& o, const VideoMotion& m, MotionProbes& p, std::vector<DisplayFrames>& displays) {
  for (uint32_t f = 0; f < o.frames; ++f) {
    const double t = f / o.fps;
    const double sceneTime = m.rate * t;
    const bool moved = p.moves && sceneTime != p.lastSceneTime;
    if (moved) {
      session::advanceScene(m.scene, sceneTime, p.current);
      p.lastSceneTime = sceneTime;
    }
    const bool update = f == 0 || std::floor(t * o.hz) != std::floor((f - 1) / o.fps * o.hz);
    if (update) {
      if (p.lastSceneTime != p.updaterSceneTime) {
        p.updater.setScene(p.current);
        p.updaterSceneTime = p.lastSceneTime;
      }
      updateProbes(p, true);
      ++p.recordedUpdates;
    }
    if (o.truthUpdates > 0 && (p.truthTime < 0.0 || (p.moves && sceneTime != p.truthTime)))
      convergeTruth(o, m, p, sceneTime);
    for (DisplayFrames& df : displays) renderFrame(o, p, df, t, moved, update);
    p.truthFresh = false;
    if (f % 10 == 9 || f + 1 == o.frames)
      sayProgress(o.progress, fmt::format("bench video: {}: frame {}/{} rendered ({} probe updates)", m.name, f + 1,
                                          o.frames, p.recordedUpdates));
  }
}

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

// One motion from start to end: the probes warmed up, the frames recorded, then every display's
// video sweeps and figures.
void measureMotion(const VideoSetup& s, const VideoMotion& m, VideoReport& report) {
  MotionProbes p(s, m);
  warmUp(s.o, m, p);
  std::vector<DisplayFrames> displays = makeDisplays(s, p);
  recordFrames(s.o, m, p, displays);
  for (size_t i = 0; i < displays.size(); ++i) reportDisplay(s, m, p, i, displays[i], report);
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

}  // namespace

VideoBenchResult runVideoBench(const VideoBenchOptions& o) {
  checkOptions(o);
  const RunFolder folder(o.workDir.empty() ? fs::temp_directory_path().string() : o.workDir, o.keepFiles);
  const std::string& work = folder.path;
  if (o.keepFiles && o.progress) o.progress("frames and bitstreams go to " + work);
  checkFfmpeg(o, work);
  renderer::VulkanContext context(o.context);
  const VideoSetup s{o, context, work, static_cast<double>(o.frames) / o.fps};

  VideoReport report;
  report.table = fmt::format("{:<10} {:<8} {:<8} {:>10} {:>7} {:>9} {:>10} {:>8}\n", "display", "motion", "stream",
                             "probes B/s", "dB", "video", "video B/s", "ratio");
  for (const VideoDisplay& d : o.displays) report.chartSeries.push_back({d.name, {}});
  for (const VideoMotion& m : o.motions) measureMotion(s, m, report);
  return videoResult(s, report);
}

}  // namespace probecast::bench
