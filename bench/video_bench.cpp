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
#include "video_parts.h"

namespace probecast::bench {

using namespace video;

namespace {

namespace fs = std::filesystem;

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

// One motion from start to end: the probes warmed up, the frames recorded, then every display's
// video sweeps and figures.
void measureMotion(const VideoSetup& s, const VideoMotion& m, VideoReport& report) {
  MotionProbes p(s, m);
  warmUp(s.o, m, p);
  std::vector<DisplayFrames> displays = makeDisplays(s, p);
  recordFrames(s.o, m, p, displays);
  for (size_t i = 0; i < displays.size(); ++i) reportDisplay(s, m, p, i, displays[i], report);
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
