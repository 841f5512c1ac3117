#include "live_window.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>

#include "dynamic_resolution.h"
#include "probecast/renderer/window.h"
#include "probecast/session/head_trace.h"

namespace probecast::app {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A camera the user flies: the mouse turns it about the starting up axis and its own right axis,
// W/A/S/D/Q/E move it at a speed set by the scene's size.
class FlyCamera {
 public:
  FlyCamera(const renderer::CameraView& start, float sceneSize) : start_(start), speed_(0.4f * sceneSize) {}

  // True when it moved.
  bool apply(const renderer::WindowInput& in, double dt) {
    if (in.reset) {
      yaw_ = pitch_ = 0.0f;
      offset_ = glm::vec3(0.0f);
      return true;
    }
    const bool turned = in.look != glm::vec2(0.0f), moved = in.move != glm::vec3(0.0f);
    yaw_ -= 0.004f * in.look.x;
    pitch_ = std::clamp(pitch_ - 0.004f * in.look.y, -1.5f, 1.5f);
    const renderer::CameraView c = camera();
    const glm::vec3 right = glm::normalize(glm::cross(c.forward, c.up));
    const float step = speed_ * (in.fast ? 4.0f : 1.0f) * static_cast<float>(dt);
    offset_ += step * (in.move.x * right + in.move.y * c.up + in.move.z * c.forward);
    return turned || moved;
  }

  renderer::CameraView camera() const {
    renderer::CameraView c = start_;
    const glm::vec3 up0 = glm::normalize(start_.up);
    const glm::vec3 f0 = glm::normalize(start_.forward);
    const glm::quat yaw = glm::angleAxis(yaw_, up0);
    const glm::vec3 f1 = yaw * f0;
    const glm::vec3 right = glm::normalize(glm::cross(f1, up0));
    const glm::quat pitch = glm::angleAxis(pitch_, right);
    c.forward = glm::normalize(pitch * f1);
    c.up = glm::normalize(glm::cross(right, c.forward));
    c.position = start_.position + offset_;
    return c;
  }

 private:
  renderer::CameraView start_;
  float speed_;
  float yaw_ = 0.0f, pitch_ = 0.0f;
  glm::vec3 offset_{0.0f};
};

// --head-trace's trace, read (or refused by name) before anything else starts.
std::shared_ptr<const session::HeadTrace> loadWindowTrace(const std::string& spec) {
  if (spec.empty()) return nullptr;
  auto trace = std::make_shared<session::HeadTrace>();
  std::string error;
  if (!session::loadHeadTrace(spec, *trace, error)) throw std::runtime_error("--head-trace " + error);
  fmt::print("window: the camera {} ({:.1f} s, looping)\n",
             trace->isPath() ? "follows " + spec : "turns as " + spec + " turned", trace->duration());
  return trace;
}

// Writes the screenshot: what was presented (PNG, the window's pixels) and what was drawn (EXR).
void writeScreenshot(const std::string& base, const renderer::Window& window, const std::vector<uint8_t>& presented,
                     const renderer::Image& shown) {
  std::string error;
  if (!imaging::writePngRgba(base + ".png", presented, static_cast<int>(window.width()), static_cast<int>(window.height()),
                             error) ||
      !imaging::writeExr(base + ".exr", shown.rgb, static_cast<int>(shown.width), static_cast<int>(shown.height), error))
    fmt::print(stderr, "window: screenshot not written: {}\n", error);
  else
    fmt::print("window: screenshot {}.png (as presented) and {}.exr (linear)\n", base, base);
}

// The window for `wanted` pixels: that size, or, when it is larger than the screen and the window
// is not full screen, 1/k of it each side (k the smallest whole factor that fits), the picture
// shown box-averaged by k.
struct WindowFit {
  renderer::WindowOptions options;
  uint32_t shrink = 1;
};
WindowFit fitWindow(uint32_t wantedW, uint32_t wantedH, bool fullscreen) {
  WindowFit f;
  f.options.width = wantedW;
  f.options.height = wantedH;
  f.options.fullscreen = fullscreen;
  const glm::uvec2 screen = fullscreen ? glm::uvec2(0) : renderer::Window::screenWorkArea();
  if (screen.x == 0 || screen.y == 0) return f;
  while ((wantedW + f.shrink - 1) / f.shrink > screen.x || (wantedH + f.shrink - 1) / f.shrink > screen.y) ++f.shrink;
  f.options.width = wantedW / f.shrink;
  f.options.height = wantedH / f.shrink;
  if (f.shrink > 1)
    fmt::print("window: {}x{} is larger than the screen ({}x{}): shown at 1/{} (--fullscreen shows it whole)\n", wantedW,
               wantedH, screen.x, screen.y, f.shrink);
  return f;
}

// `image` box-averaged by k each side (the last partial rows and columns dropped).
renderer::Image shrink(const renderer::Image& image, uint32_t k) {
  if (k <= 1) return image;
  renderer::Image out;
  out.width = image.width / k;
  out.height = image.height / k;
  out.rgb.assign(static_cast<size_t>(out.width) * out.height * 3, 0.0f);
  const float w = 1.0f / static_cast<float>(k * k);
  for (uint32_t y = 0; y < out.height * k; ++y)
    for (uint32_t x = 0; x < out.width * k; ++x)
      for (uint32_t c = 0; c < 3; ++c)
        out.rgb[(static_cast<size_t>(y / k) * out.width + x / k) * 3 + c] +=
            w * image.rgb[(static_cast<size_t>(y) * image.width + x) * 3 + c];
  return out;
}

// The views as the window shows them: composed (a quilt, or the source's own image) and shrunk
// to the window.
renderer::Image composed(const FrameSource& source, const std::vector<renderer::Image>& images,
                         const std::vector<renderer::ViewInfo>& views, const renderer::ViewSetSpec& spec,
                         const WindowFit& fit) {
  return shrink(source.compose ? source.compose(images, views)
                               : renderer::composeQuilt(images, views, spec.columns, spec.rows),
                fit.shrink);
}

// The status line's right part: the source's, and the scale the views are drawn at when reduced.
std::string statusOf(const FrameSource& source, const DynamicResolution& resolution) {
  if (resolution.scale() >= 1.0f) return source.status();
  return fmt::format("{} | drawn at {:.0f} %", source.status(), 100.0f * resolution.scale());
}

renderer::Image black(uint32_t width, uint32_t height) {
  renderer::Image out;
  out.width = width;
  out.height = height;
  out.rgb.assign(size_t{width} * height * 3, 0.0f);
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

void LiveWindowOptions::add(CLI::App* cmd) {
  CLI::Option* window =
      cmd->add_flag("--window", enabled,
                    "show the views live in a window (GLFW + Vulkan swapchain): drag to look, W/A/S/D/Q/E to move, "
                    "Shift faster, R resets, F12 or P writes a screenshot to --out, Escape closes");
  cmd->add_flag("--fullscreen", fullscreen,
                "--window: full screen, on the monitor whose mode is the window's size (a Looking Glass panel's) "
                "when there is one, else the primary")
      ->needs(window);
  cmd->add_option("--window-seconds", seconds, "--window: close after this many seconds (0: when closed)")
      ->check(CLI::Range(0.0, 1e7))
      ->needs(window);
  cmd->add_option("--screenshot-after", screenshotAfter, "--window: write one screenshot this many seconds in")
      ->check(CLI::Range(0.0, 1e7))
      ->needs(window);
  cmd->add_option("--overlay", overlay, "--window: the status line (frame ms, probe age, bytes/s, connection)")
      ->capture_default_str()
      ->needs(window);
  cmd->add_option("--window-fps", fps,
                  "--window: the frame rate to hold on a device too slow for the full size, by drawing the views "
                  "smaller and scaling them up (down to 1/4 a side; 0: always full size)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1000.0))
      ->needs(window);
  cmd->add_option("--head-trace", headTrace,
                  "the camera turns as a recorded head turned (a file of timestamp viewpoint w x y z lines, the "
                  "MMSys'18 format, or builtin:mmsys18-user1), with a neck model, or follows a camera path (a file "
                  "starting probecast-camera-path 1, or builtin:walk-1m): in a --window from its opening, looping, "
                  "the mouse and keys still moving it; without, --frames pictures --fps apart")
      ->check([](const std::string& spec) {
        session::HeadTrace trace;
        std::string error;
        return session::loadHeadTrace(spec, trace, error) ? std::string() : error;
      });
}

renderer::ContextOptions LiveWindowOptions::presenting(renderer::ContextOptions options) {
  options.instanceExtensions = renderer::Window::instanceExtensions();
  options.swapchain = true;
  return options;
}

LiveWindowResult runLiveWindow(const LiveWindowOptions& o, renderer::VulkanContext& context,
                               const renderer::CameraView& start, const renderer::ViewSetSpec& spec,
                               const renderer::ViewSetOptions& viewSetOptions, uint32_t viewWidth,
                               uint32_t viewHeight, float sceneSize, FrameSource& source, const std::string& outDir,
                               float exposure, imaging::ToneMap toneMap) {
  const WindowFit fit =
      fitWindow(source.displayWidth ? source.displayWidth : viewWidth * static_cast<uint32_t>(spec.columns),
                source.displayHeight ? source.displayHeight : viewHeight * static_cast<uint32_t>(spec.rows), o.fullscreen);
  const renderer::WindowOptions& wo = fit.options;
  renderer::Window window(context, wo);
  fmt::print("window: {}x{} on {}, present mode {}\n", window.width(), window.height(), context.deviceName(),
             window.presentMode());
  std::fflush(stdout);

  FlyCamera camera(start, sceneSize);
  const std::shared_ptr<const session::HeadTrace> trace = loadWindowTrace(o.headTrace);
  LiveWindowResult result;
  const Clock::time_point begin = Clock::now();
  Clock::time_point lastFrame = begin, lastReport = begin;
  std::vector<double> frameMs, secondMs;  // all frames; frames since the last report
  std::vector<renderer::Image> images;
  std::vector<renderer::ViewInfo> views;
  renderer::Image shown;
  bool screenshotDone = false, first = true;
  DynamicResolution resolution(source.setRenderScale ? o.fps : 0.0);
  while (window.isOpen() && (o.seconds <= 0.0 || secondsSince(begin) < o.seconds)) {
    const Clock::time_point frameStart = Clock::now();
    const double dt = std::chrono::duration<double>(frameStart - lastFrame).count();
    lastFrame = frameStart;
    const renderer::WindowInput in = window.poll();
    const bool moved = camera.apply(in, dt) || first || trace;
    first = false;
    if (moved)
      views = renderer::makeViewSet(
          trace ? session::poseCamera(camera.camera(), *trace, secondsSince(begin)) : camera.camera(), spec,
          viewSetOptions);
    if (source.render(views, moved, images)) {
      for (renderer::Image& image : images) image = upscale(image, viewWidth, viewHeight);
      shown = composed(source, images, views, spec, fit);
    } else {
      shown = black(wo.width, wo.height);  // nothing to draw yet
    }
    std::vector<unsigned char> rgba = imaging::toneMapRgba8(shown.rgb, exposure, toneMap);
    const double lastMs = frameMs.empty() ? 0.0 : frameMs.back();
    const std::string status = statusOf(source, resolution);
    if (o.overlay)
      imaging::drawTextLine(rgba, static_cast<int>(shown.width), static_cast<int>(shown.height), 6, 0,
                            fmt::format("{:.1f} ms | {}", lastMs, status), shown.width >= 1280 ? 2 : 1);
    const bool screenshot =
        in.screenshot || (!screenshotDone && o.screenshotAfter >= 0.0 && secondsSince(begin) >= o.screenshotAfter);
    std::vector<uint8_t> readback;
    window.present(rgba.data(), shown.width, shown.height, screenshot ? &readback : nullptr);
    if (screenshot) {
      screenshotDone = true;
      std::filesystem::create_directories(outDir);
      const std::string base = fmt::format("{}/screenshot_{:03}", outDir, result.screenshots.size());
      writeScreenshot(base, window, readback, shown);
      result.screenshots.push_back(base);
    }
    const double ms = 1e3 * secondsSince(frameStart);
    if (resolution.update(ms)) source.setRenderScale(resolution.scale());
    frameMs.push_back(ms);
    secondMs.push_back(ms);
    if (secondsSince(lastReport) >= 1.0) {
      fmt::print("window: {:.1f} s, {} frames presented, {:.1f} ms a frame, {}\n", secondsSince(begin),
                 window.framesPresented(), median(secondMs), status);
      std::fflush(stdout);
      secondMs.clear();
      lastReport = Clock::now();
    }
  }
  result.frames = window.framesPresented();
  result.seconds = secondsSince(begin);
  result.medianFrameMs = median(frameMs);
  fmt::print("window: closed after {:.1f} s, {} frames presented, median {:.1f} ms a frame\n", result.seconds,
             result.frames, result.medianFrameMs);
  return result;
}

}  // namespace probecast::app
