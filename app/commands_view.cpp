// `probecast view`: render mono, stereo or light-field views of a scene lit by a probe volume.
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>
#include <filesystem>

#include <fmt/format.h>

#include "commands.h"
#include "probecast/imaging/image_io.h"
#include "probecast/codec/probe_file.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/renderer/view_sets.h"
#include "probecast/service/client.h"
#include "scene_options.h"
#include "view_support.h"

namespace probecast::app {

renderer::ViewSetOptions viewSetOptions(const scene::Scene& s, uint32_t width, uint32_t height) {
  const renderer::CameraView camera = renderer::CameraView::fromScene(s);
  renderer::ViewSetOptions vo;
  vo.aspect = static_cast<float>(width) / static_cast<float>(height);
  vo.displayDistance = std::max(0.1f, glm::length(0.5f * (s.boundsMin + s.boundsMax) - camera.position));
  return vo;
}

std::vector<View> priorityViews(const std::vector<renderer::ViewInfo>& views) {
  std::vector<View> out(views.size());
  for (size_t k = 0; k < views.size(); ++k) {
    std::memcpy(out[k].viewProj, &views[k].viewProj[0][0], sizeof out[k].viewProj);
    for (int i = 0; i < 3; ++i) out[k].eye[i] = views[k].eye[i];
  }
  return out;
}

void addViewCommand(CLI::App& app, int& exitCode) {
  CLI::App* cmd = app.add_subcommand("view", "render views (mono, stereo, lf:NxM quilt) lit by probes");
  auto tr = std::make_shared<TracingOptions>();
  struct Options {
    std::string probes = "live", views = "lf:5x5", out = "out/view", connect, token, tlsCa, tlsName;
    std::string repr = "float", passes = "per-view", toneMap = "filmic";
    uint32_t shadowMap = 1024;
    double waitSeconds = 3.0;
    std::vector<uint32_t> size{320, 200};
    uint32_t updates = 4;
    float exposure = 1.0f;
    bool exr = false;
  };
  auto o = std::make_shared<Options>();
  tr->add(cmd);
  cmd->add_option("--probes", o->probes, "probe volume file, or 'live' to trace it now");
  cmd->add_option("--updates", o->updates, "live: updates to accumulate")->check(CLI::Range(1, 100000));
  cmd->add_option("--connect", o->connect, "take the probes from a probecast server (host:port) instead");
  cmd->add_option("--token", o->token, "bearer token for --connect");
  cmd->add_option("--tls-ca", o->tlsCa, "PEM root certificate to trust (TLS)")->check(CLI::ExistingFile);
  cmd->add_option("--tls-name", o->tlsName, "server name to check in its certificate");
  cmd->add_option("--wait", o->waitSeconds, "--connect: seconds to receive the stream before rendering")
      ->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--views", o->views, "mono, stereo, lf:NxM (full parallax) or lfh:NxM (horizontal, Looking Glass quilt)");
  cmd->add_option("--size", o->size, "size of each view WxH")->delimiter('x')->expected(2)->check(CLI::Range(1, 8192));
  cmd->add_option("--out", o->out, "output folder");
  cmd->add_option("--exposure", o->exposure, "scale for the PNG only")->check(CLI::Range(1e-6f, 1e6f));
  cmd->add_flag("--exr", o->exr, "also write every view as a linear EXR");
  cmd->add_option("--repr", o->repr, "local probes: pass them through the codec first (float = as traced)")
      ->check(CLI::IsMember({"float", "l1", "zh3h", "zh3", "l2", "fp16"}));
  cmd->add_option("--passes", o->passes, "per-view (one pass per view) or multiview (chunks of views per pass)")
      ->check(CLI::IsMember({"per-view", "multiview"}));
  cmd->add_option("--shadow-map", o->shadowMap, "shadow map texels per side")->check(CLI::Range(16, 8192));
  cmd->add_option("--tonemap", o->toneMap, "PNG tone map: filmic or gamma")->check(CLI::IsMember({"filmic", "gamma"}));
  cmd->callback([=, &exitCode] {
    renderer::ViewSetSpec spec;
    std::string error;
    if (!renderer::parseViewSet(o->views, spec, error)) throw std::runtime_error(error);
    const scene::Scene s = tr->scene.load();
    const std::vector<renderer::ViewInfo> viewSet =
        renderer::makeViewSet(renderer::CameraView::fromScene(s), spec, viewSetOptions(s, o->size[0], o->size[1]));
    renderer::VulkanContext context(tr->gpu.context());
    ProbeVolume volume;
    if (!o->connect.empty()) {
      service::ClientConfig cc;
      cc.address = o->connect;
      cc.token = o->token;
      cc.name = "probecast-view";
      if (!o->tlsCa.empty()) {
        std::ifstream in(o->tlsCa);
        std::stringstream ss;
        ss << in.rdbuf();
        cc.tls = true;
        cc.rootCertPem = ss.str();
        cc.tlsServerName = o->tlsName;
      }
      cc.zh3PerPixel = true;
      service::ProbeClient client(cc);
      client.setViews(priorityViews(viewSet));
      client.start();
      const auto start = std::chrono::steady_clock::now();
      while (std::chrono::steady_clock::now() - start < std::chrono::duration<double>(o->waitSeconds) &&
             !client.stats().fatal)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      client.stop();
      service::VolumeSnapshot snap;
      if (!client.snapshot(snap))
        throw std::runtime_error("no probe volume from " + o->connect + ": " + client.stats().lastError);
      volume = std::move(snap.volume);
      fmt::print("view: {} frames ({} bytes) from {}\n", client.stats().framesApplied, client.stats().bytesReceived,
                 o->connect);
    } else if (o->probes == "live") {
      const ProbeGrid g = tr->grid.resolve(s);
      renderer::ProbeUpdater updater(context, s, g, tr->tracer.options());
      for (uint32_t u = 0; u < o->updates; ++u) {
        updater.update();
        fmt::print(stderr, "\rview: probe update {}/{}", u + 1, o->updates);
      }
      fmt::print(stderr, "\n");
      volume = updater.volume();
    } else {
      if (!readProbeFile(o->probes, volume, error)) throw std::runtime_error(error);
    }
    if (o->repr != "float") {
      if (!o->connect.empty()) throw std::runtime_error("--repr applies to local probes; the server chooses for --connect");
      volume = decodeAs(volume, *parseRepresentation(o->repr));
    }
    renderer::RasterOptions ro;
    ro.passes = o->passes == "multiview" ? renderer::ViewPasses::Multiview : renderer::ViewPasses::PerView;
    ro.shadowMapSize = o->shadowMap;
    renderer::RasterRenderer raster(context, s, o->size[0], o->size[1], ro);
    raster.setProbes(volume);
    const auto& views = viewSet;
    std::vector<renderer::Image> images = raster.renderViews(views);
    const double ms = raster.timings().viewsMs;
    std::filesystem::create_directories(o->out);
    const renderer::Image quilt = renderer::composeQuilt(images, views, spec.columns, spec.rows);
    const auto w = static_cast<int>(quilt.width), h = static_cast<int>(quilt.height);
    imaging::ToneMap toneMap = imaging::ToneMap::Filmic;
    imaging::parseToneMap(o->toneMap, toneMap);
    if (!imaging::writePngPreview(o->out + "/quilt.png", quilt.rgb, w, h, o->exposure, error, toneMap) ||
        !imaging::writeExr(o->out + "/quilt.exr", quilt.rgb, w, h, error))
      throw std::runtime_error(error);
    if (o->exr)
      for (size_t k = 0; k < images.size(); ++k)
        if (!imaging::writeExr(fmt::format("{}/view_{:02}.exr", o->out, k), images[k].rgb, static_cast<int>(o->size[0]),
                             static_cast<int>(o->size[1]), error))
          throw std::runtime_error(error);
    fmt::print("view: {} {} views of {}x{} on {}: {:.1f} ms per view; wrote {}/quilt.png and quilt.exr\n", o->views,
               views.size(), o->size[0], o->size[1], context.deviceName(), ms / static_cast<double>(views.size()), o->out);
    exitCode = 0;
  });
}

}  // namespace probecast::app
