#include "environment_bench.h"

#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "envmap.h"
#include "probecast/imaging/svg_chart.h"

namespace probecast::bench {

scene::Scene sunlitYard(renderer::CameraView& camera) {
  scene::Scene s;
  s.name = "sunlit-yard";
  scene::Material ground, box;
  ground.baseColor = glm::vec3(0.5f);
  box.baseColor = glm::vec3(0.8f);
  box.roughness = 0.5f;
  s.materials = {ground, box};
  scene::addQuad(s, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, {-10, 0, -10}, 0);
  scene::addBox(s, {0, 0.5f, 0}, {0.5f, 0.5f, 0.5f}, 0.4f, 1);
  scene::finalizeScene(s);
  camera.position = {0.0f, 1.5f, 4.0f};
  camera.forward = glm::normalize(glm::vec3(0.0f, 0.5f, 0.0f) - camera.position);
  camera.up = {0, 1, 0};
  camera.yfov = 0.7f;
  return s;
}

std::shared_ptr<renderer::Environment> builtinSunSky() {
  const EnvMap sky = builtinEnvMaps().front();
  auto env = std::make_shared<renderer::Environment>();
  env->name = sky.name;
  env->width = sky.width;
  env->height = sky.height;
  env->rgb = sky.rgb;
  return env;
}

EnvironmentBenchResult runEnvironmentBench(const EnvironmentBenchOptions& o) {
  const auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
  renderer::VulkanContext context(o.context);
  renderer::ReferenceOptions ro;
  ro.width = o.width;
  ro.height = o.height;
  ro.maxBounces = o.maxBounces;
  ro.environment = o.environment;
  ro.samplesPerPixel = o.referenceSpp;
  ro.seed = 1;
  say(fmt::format("environment bench: reference, {} spp with importance sampling", o.referenceSpp));
  const renderer::Image reference = renderer::renderReference(context, o.scene, o.camera, ro);

  EnvironmentBenchResult r;
  nlohmann::json& j = r.json;
  j["command"] = o.command;
  j["scene"] = o.scene.name;
  j["environment"] = o.environment ? o.environment->name : "none";
  j["device"] = context.deviceName();
  j["size"] = {o.width, o.height};
  j["max_bounces"] = o.maxBounces;
  j["reference_spp"] = o.referenceSpp;
  j["metric"] = "RMS error of linear radiance over all pixels and channels against the reference";
  r.table = fmt::format("environment bench: {} under {} at {}x{}, {} bounces, on {}\n{:>6} {:>14} {:>14} {:>7}\n",
                        o.scene.name, j["environment"].get<std::string>(), o.width, o.height, o.maxBounces,
                        context.deviceName(), "spp", "RMS env IS+MIS", "RMS BSDF only", "ratio");
  std::vector<imaging::ChartSeries> series = {{"environment importance sampling + MIS", {}, true},
                                              {"BSDF sampling only", {}, true}};
  for (uint32_t spp : o.spps) {
    double rms[2] = {0, 0}, seconds[2] = {0, 0};
    for (int way = 0; way < 2; ++way) {
      ro.samplesPerPixel = spp;
      ro.seed = 1000 + spp;  // independent of the reference's samples
      ro.environmentSampling = way == 0;
      const auto t0 = std::chrono::steady_clock::now();
      const renderer::Image img = renderer::renderReference(context, o.scene, o.camera, ro);
      seconds[way] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      double sum = 0;
      for (size_t i = 0; i < img.rgb.size(); ++i) {
        const double d = static_cast<double>(img.rgb[i]) - reference.rgb[i];
        sum += d * d;
      }
      rms[way] = std::sqrt(sum / static_cast<double>(img.rgb.size()));
      series[static_cast<size_t>(way)].points.push_back({static_cast<double>(spp), rms[way], ""});
    }
    j["runs"].push_back({{"spp", spp},
                         {"rms_importance", rms[0]},
                         {"rms_bsdf_only", rms[1]},
                         {"seconds_importance", seconds[0]},
                         {"seconds_bsdf_only", seconds[1]}});
    r.table += fmt::format("{:>6} {:>14.5f} {:>14.5f} {:>7.2f}\n", spp, rms[0], rms[1], rms[1] / rms[0]);
    say(fmt::format("environment bench: {} spp: {:.5f} against {:.5f}", spp, rms[0], rms[1]));
  }
  imaging::ChartSpec spec;
  spec.title = "Convergence under a small bright sun: RMS error against samples per pixel";
  spec.xLabel = "samples per pixel";
  spec.yLabel = "RMS error (linear radiance)";
  spec.logX = true;
  spec.logY = true;
  spec.footnote = o.command;
  r.svg = imaging::renderSvgChart(spec, series);
  return r;
}

}  // namespace probecast::bench
