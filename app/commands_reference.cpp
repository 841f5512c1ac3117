// `probecast render-reference`: ground-truth camera path tracing to EXR.
#include <chrono>

#include <fmt/format.h>

#include "commands.h"
#include "progress.h"
#include "probecast/imaging/image_io.h"
#include "probecast/renderer/reference_camera.h"
#include "scene_options.h"

namespace probecast::app {

void addReferenceCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("render-reference", "ground-truth camera path tracer (EXR out)");
  auto scene = std::make_shared<SceneOptions>();
  auto device = std::make_shared<DeviceOptions>();
  struct Options {
    std::vector<uint32_t> size{320, 240};
    uint32_t spp = 256, bounces = 8, seed = 1;
    std::vector<float> eye, target;
    float yfovDeg = 0.0f;
    std::string out, png;
    float exposure = 1.0f;
  };
  auto o = std::make_shared<Options>();
  scene->add(cmd);
  device->add(cmd);
  addSizeOption(cmd, o->size, "image size WxH", 1, 8192);
  addSppOption(cmd, o->spp, "samples per pixel", 1u << 20);
  cmd->add_option("--bounces", o->bounces, "surface interactions per path")->check(CLI::Range(1, 16));
  cmd->add_option("--seed", o->seed, "random seed");
  cmd->add_option("--eye", o->eye, "camera position X,Y,Z (default: the scene's camera)")->delimiter(',')->expected(3);
  cmd->add_option("--target", o->target, "point the camera looks at X,Y,Z")->delimiter(',')->expected(3);
  cmd->add_option("--yfov", o->yfovDeg, "vertical field of view, degrees")->check(CLI::Range(1.0f, 179.0f));
  cmd->add_option("--out", o->out, "EXR file to write (linear radiance)")->required();
  cmd->add_option("--png", o->png, "also write a PNG preview (filmic tone map)");
  cmd->add_option("--exposure", o->exposure, "scale applied to the PNG preview only")->check(CLI::Range(1e-6f, 1e6f));
  cmd->callback([=] {
    const scene::Scene s = scene->load();
    const auto environment = scene->environment.load();  // before the device: bad input fails fast
    renderer::CameraView camera = renderer::CameraView::fromScene(s);
    if (o->eye.size() == 3) camera.position = {o->eye[0], o->eye[1], o->eye[2]};
    if (o->target.size() == 3) {
      const glm::vec3 dir = glm::vec3(o->target[0], o->target[1], o->target[2]) - camera.position;
      if (glm::length(dir) <= 0.0f) throw std::runtime_error("--target equals the camera position");
      camera.forward = glm::normalize(dir);
      if (std::fabs(glm::dot(camera.forward, camera.up)) > 0.999f) camera.up = glm::vec3(0, 0, -1);
    }
    if (o->yfovDeg > 0) camera.yfov = glm::radians(o->yfovDeg);
    renderer::VulkanContext context(device->context());
    renderer::ReferenceOptions ro;
    ro.width = o->size[0];
    ro.height = o->size[1];
    ro.samplesPerPixel = o->spp;
    ro.maxBounces = o->bounces;
    ro.seed = o->seed;
    ro.environment = environment;
    auto progress = std::make_shared<Progress>("render-reference", /*bar=*/false);
    ro.progress = [progress](uint32_t done, uint32_t total) {
      progress->update(static_cast<double>(done) / total,
                       fmt::format("{}/{} spp ({:.0f}%)", done, total, 100.0 * done / total));
      if (done == total) progress->finish();
    };
    fmt::print("render-reference: {} on {}, {}x{}, {} spp, environment {}\n", s.name, context.deviceName(), ro.width,
               ro.height, ro.samplesPerPixel, ro.environment ? ro.environment->name : "none");
    const auto t0 = std::chrono::steady_clock::now();
    renderer::ReferenceStats stats;
    const renderer::Image image = renderer::renderReference(context, s, camera, ro, &stats);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    fmt::print("render-reference: {:.1f} s, {} samples, {} non-finite dropped\n", seconds, stats.samples,
               stats.droppedSamples);
    std::string error;
    if (!imaging::writeExr(o->out, image.rgb, static_cast<int>(image.width), static_cast<int>(image.height), error))
      throw std::runtime_error(error);
    fmt::print("wrote {}\n", o->out);
    if (!o->png.empty()) {
      if (!imaging::writePngPreview(o->png, image.rgb, static_cast<int>(image.width), static_cast<int>(image.height), o->exposure,
                                  error))
        throw std::runtime_error(error);
      fmt::print("wrote {}\n", o->png);
    }
  });
}

}  // namespace probecast::app
