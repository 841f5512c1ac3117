// bench video: the video side. The recorded frames encoded with ffmpeg at each CRF, decoded and
// compared, and the bytes a codec needs at a given PSNR.
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

}  // namespace

double psnrFromSse(double sse, double samples) {
  if (samples <= 0) return 0.0;
  if (sse <= 0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 * samples / sse);
}

nlohmann::json dbJson(double db) { return std::isfinite(db) ? nlohmann::json(db) : nlohmann::json("identical"); }

double squaredError(const uint8_t* a, const uint8_t* b, size_t n) {
  double s = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double e = static_cast<double>(a[i]) - static_cast<double>(b[i]);
    s += e * e;
  }
  return s;
}

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

}  // namespace probecast::bench::video
