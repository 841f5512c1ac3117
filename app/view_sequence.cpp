// `probecast view --head-trace T` without --window: a sequence of pictures along a recorded head's
// motion or a scripted camera path, every one drawn from the same local probes.
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "progress.h"
#include "probecast/imaging/image_io.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/session/head_trace.h"
#include "view.h"

namespace probecast::app {

void addViewSequenceOptions(CLI::App* cmd, ViewOptions& o) {
  cmd->add_option("--frames", o.frames,
                  "--head-trace without --window: this many pictures along the trace or path, --fps apart "
                  "(frame_NNNN.png in --out)")
      ->check(CLI::Range(1u, 100000u))
      ->capture_default_str();
  cmd->add_option("--fps", o.fps, "--head-trace without --window: pictures per second of the trace's time")
      ->check(CLI::Range(0.01, 1000.0))
      ->capture_default_str();
}

void checkSequenceOptions(const ViewOptions& o) {
  if (o.window.enabled || o.window.headTrace.empty()) {
    if (o.frames != 1) throw std::runtime_error("--frames: pictures along a --head-trace (without --window)");
    return;
  }
  if (!o.connection.connect.empty())
    throw std::runtime_error("--head-trace without --window draws local probes (--probes FILE or live), not a --connect stream");
  if (!o.lookingGlass.empty()) throw std::runtime_error("--head-trace without --window: not with --looking-glass");
}

namespace {

// One picture of the sequence: the quilt tone-mapped to frame_NNNN.png, and linear with --exr.
void writeFrame(const ViewOptions& o, uint32_t i, const std::vector<renderer::Image>& images,
                const std::vector<renderer::ViewInfo>& views, const renderer::ViewSetSpec& spec) {
  const renderer::Image quilt = renderer::composeQuilt(images, views, spec.columns, spec.rows);
  const auto w = static_cast<int>(quilt.width), h = static_cast<int>(quilt.height);
  const std::string stem = fmt::format("{}/frame_{:04}", o.out, i);
  std::string error;
  if (!imaging::writePngPreview(stem + ".png", quilt.rgb, w, h, o.exposure, error, toneMapOf(o)) ||
      (o.exr && !imaging::writeExr(stem + ".exr", quilt.rgb, w, h, error)))
    throw std::runtime_error(error);
}

}  // namespace

void writeSequence(const ViewOptions& o, renderer::VulkanContext& context, const scene::Scene& s,
                   const renderer::ViewSetSpec& spec, const renderer::ViewSetOptions& vso,
                   const renderer::RasterOptions& ro) {
  session::HeadTrace trace;
  std::string error;
  if (!session::loadHeadTrace(o.window.headTrace, trace, error)) throw std::runtime_error("--head-trace " + error);
  const std::unique_ptr<renderer::RasterRenderer> raster = localRaster(o, context, s, ro);
  std::filesystem::create_directories(o.out);
  const renderer::CameraView start = renderer::CameraView::fromScene(s);
  Progress progress("view", /*bar=*/true);
  double viewsMs = 0.0;
  size_t viewCount = 0;
  for (uint32_t i = 0; i < o.frames; ++i) {
    const double t = static_cast<double>(i) / o.fps;
    const std::vector<renderer::ViewInfo> views = renderer::makeViewSet(session::poseCamera(start, trace, t), spec, vso);
    writeFrame(o, i, raster->renderViews(views), views, spec);
    viewsMs += raster->timings().viewsMs;
    viewCount += views.size();
    progress.update(static_cast<double>(i + 1) / o.frames, fmt::format("frame {}/{}", i + 1, o.frames));
  }
  progress.finish();
  fmt::print("view: {} frames along {} ({:.2f} s at {:g} a second), {} views of {}x{} each on {}: {:.1f} ms per view; "
             "wrote {}/frame_0000.png to frame_{:04}.png\n",
             o.frames, o.window.headTrace, static_cast<double>(o.frames - 1) / o.fps, o.fps, o.views, o.size[0],
             o.size[1], context.deviceName(), viewsMs / static_cast<double>(viewCount), o.out, o.frames - 1);
}

}  // namespace probecast::app
