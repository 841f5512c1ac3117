// bench video: the recording. One motion's probes traced and streamed, every display's frames
// drawn from the float probes (for the video) and from each stream's decoder (set against them),
// and converged truth where asked.
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

}  // namespace

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

}  // namespace probecast::bench::video
