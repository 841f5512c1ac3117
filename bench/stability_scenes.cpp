// The stability suite's cases on the GPU and over the network: flicker and lag of the blend rules,
// network faults, and what each scene needs.
#include "stability.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "probecast/codec/record.h"
#include "probecast/codec/sh.h"
#include "probecast/codec/stream.h"
#include "probecast/codec/zh3.h"
#include "probecast/renderer/probe_updater.h"
#include "probecast/renderer/raster_client.h"
#include "probecast/service/client.h"
#include "probecast/service/server.h"
#include "probecast/session/probe_producer.h"
#include "probecast/session/scene_loading.h"
#include "probecast/session/stats.h"
#include "probecast/session/volumes.h"
#include "harness.h"
#include "stream_bench.h"
#include "update_bench.h"

namespace probecast::bench {
namespace {

using Probe = std::vector<float>;
using Clock = std::chrono::steady_clock;

scene::Scene builtin(const std::string& name, float t) { return session::loadSceneOrThrow("builtin:" + name, t); }

template <typename Pred>
double waitSeconds(Pred done, double limit) {
  const auto t0 = Clock::now();
  while (!done()) {
    if (std::chrono::duration<double>(Clock::now() - t0).count() > limit) return -1.0;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

bool holdsServerVolume(const service::ProbeClient& client, const service::ProbeHub& hub) {
  service::VolumeSnapshot snap;
  if (!client.snapshot(snap)) return false;
  return session::holdsVolume(snap.volume, hub.reconstruction());
}

}  // namespace

std::vector<FlickerLag> measureFlickerLag(renderer::VulkanContext& context, const std::vector<BlendRule>& rules,
                                          uint32_t samplesPerProbe, uint32_t updatesAfterJump) {
  const scene::Scene before = builtin("cornell", 0.0f), after = builtin("cornell", 0.5f);
  const ProbeGrid grid = renderer::sceneGrid(before, {4, 4, 4});
  const uint32_t n = grid.count();
  const auto converged = [&](const scene::Scene& s) {
    renderer::UpdaterOptions o;
    o.samplesPerProbe = 512;
    o.minBlendWeight = 0.0f;
    o.rejectSigmas = 0.0f;
    o.seed = 99;
    renderer::ProbeUpdater u(context, s, grid, o);
    for (int k = 0; k < 16; ++k) u.update();
    return std::make_pair(u.volume().probes, u.volume().active);
  };
  const auto [ref0, active] = converged(before);
  const auto ref1 = converged(after).first;
  std::vector<FlickerLag> out;
  for (const BlendRule& rule : rules) {
    FlickerLag r;
    r.wMin = rule.wMin;
    r.rejectSigmas = rule.rejectSigmas;
    renderer::UpdaterOptions o;
    o.samplesPerProbe = samplesPerProbe;
    o.minBlendWeight = rule.wMin;
    o.rejectSigmas = rule.rejectSigmas;
    renderer::ProbeUpdater u(context, before, grid, o);
    renderer::UpdaterOptions freshOptions = o;
    freshOptions.seed = o.seed + 1;
    renderer::ProbeUpdater fresh(context, after, grid, freshOptions);
    std::vector<float> previous;
    std::vector<double> changes;
    const uint32_t settle = 48;
    for (uint32_t k = 0; k < settle; ++k) {
      u.update();
      if (k >= settle / 2) changes.push_back(irradianceRmseRel(u.volume().probes.data(), previous.data(), active.data(), n));
      previous.assign(u.volume().probes.data(), u.volume().probes.data() + n * 27);
    }
    r.flickerRel = session::median(changes);
    r.errorBeforeJump = irradianceRmseRel(u.volume().probes.data(), ref0.data(), active.data(), n);
    u.setScene(after);
    for (uint32_t k = 1; k <= updatesAfterJump; ++k) {
      u.update();
      r.errorAfterJump.push_back(irradianceRmseRel(u.volume().probes.data(), ref1.data(), active.data(), n));
      if (r.updatesToRecover < 0 && r.errorAfterJump.back() <= 1.5 * r.errorBeforeJump)
        r.updatesToRecover = static_cast<int>(k);
      fresh.update();
      r.freshError.push_back(irradianceRmseRel(fresh.volume().probes.data(), ref1.data(), active.data(), n));
      if (r.updatesToFollow < 0 && r.errorAfterJump.back() <= 1.5 * r.freshError.back())
        r.updatesToFollow = static_cast<int>(k);
    }
    out.push_back(std::move(r));
  }
  return out;
}

NetworkFaults measureNetworkFaults() {
  session::ProbeProducer producer(service::hubConfigFor(
      session::unitGrid({kLightingGrid[0], kLightingGrid[1], kLightingGrid[2]}), Representation::Zh3, 4, 1));
  const service::ProbeHub& hub = producer.hub();
  service::ServerConfig sc;
  sc.plaintext = true;
  sc.token = "stability";
  const int port = producer.serve(sc);
  producer.generate([](uint32_t frame, std::vector<float>& probes) { lightingFrame(static_cast<int>(frame), probes); });
  session::Pacing pacing;
  pacing.mode = session::Pacing::Mode::FixedSleep;
  pacing.sleepMs = 20.0;
  producer.start(pacing);
  const auto config = [&](uint64_t budget) {
    service::ClientConfig cc;
    cc.address = "127.0.0.1:" + std::to_string(port);
    cc.token = sc.token;
    cc.budgetBytesPerSecond = budget;
    cc.reconnectMaxMs = 200;
    return cc;
  };
  NetworkFaults r;
  service::ProbeClient client(config(0));
  client.start();
  waitSeconds([&] { return client.stats().framesApplied >= 50; }, 20.0);
  const auto percentileMs = [](const std::vector<uint32_t>& us, double p) { return 1e-3 * session::percentile(us, p); };
  r.latencyP50Ms = percentileMs(client.latenciesUs(), 0.5);
  r.latencyP99Ms = percentileMs(client.latenciesUs(), 0.99);
  // The outage: the link is gone for 2 s while the lighting keeps changing.
  client.stop();
  service::VolumeSnapshot before, during;
  client.snapshot(before);
  std::this_thread::sleep_for(std::chrono::seconds(2));
  client.snapshot(during);
  double energy = 0;
  for (float v : during.volume.probes) energy += std::fabs(v);
  r.lightingKeptDuringOutage = during.volume.probes == before.volume.probes && energy > 0;
  const uint64_t bytesBefore = client.stats().bytesReceived;
  producer.setMoving(false);  // freeze so both clients can finish; the hub holds the lighting of the outage
  // A frame the producer was making when it was frozen still reaches the hub: let it land (ten
  // frame intervals) so the resuming client and the newcomer start from the same hub state.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  client.start();
  service::ProbeClient newcomer(config(0));
  newcomer.start();
  // Each client's bytes counted at the moment it holds the server's volume (what the hub sends
  // after that, to either, is not the cost of catching up).
  uint64_t resumedAt = 0, newcomerAt = 0;
  const auto caughtUp = [&](service::ProbeClient& c, uint64_t& bytes) {
    if (!holdsServerVolume(c, hub)) return false;
    bytes = c.stats().bytesReceived;
    return true;
  };
  r.secondsToBitExact = waitSeconds([&] { return caughtUp(client, resumedAt); }, 20.0);
  r.bitExactAfterResume = r.secondsToBitExact >= 0;
  waitSeconds([&] { return caughtUp(newcomer, newcomerAt); }, 20.0);
  if (!resumedAt) resumedAt = client.stats().bytesReceived;  // never caught up: what it took so far
  if (!newcomerAt) newcomerAt = newcomer.stats().bytesReceived;
  r.resumeBytes = static_cast<double>(resumedAt - bytesBefore);
  r.newcomerBytes = static_cast<double>(newcomerAt);
  // A slow link next to a fast one, joining together after the light moved again.
  producer.setMoving(true);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  producer.setMoving(false);
  r.slowLinkBudget = 0.25 * r.newcomerBytes;  // four seconds for a full volume
  service::ProbeClient slow(config(static_cast<uint64_t>(r.slowLinkBudget))), fast(config(0));
  slow.start();
  fast.start();
  const auto t0 = Clock::now();
  waitSeconds([&] { return holdsServerVolume(fast, hub); }, 30.0);
  r.fastSecondsToBitExact = std::chrono::duration<double>(Clock::now() - t0).count();
  waitSeconds([&] { return holdsServerVolume(slow, hub); }, 30.0);
  r.slowLinkSecondsToBitExact = std::chrono::duration<double>(Clock::now() - t0).count();
  r.slowLinkLatencyP50Ms = percentileMs(slow.latenciesUs(), 0.5);
  producer.stop();
  for (service::ProbeClient* c : {&client, &newcomer, &slow, &fast}) c->stop();
  return r;
}

std::vector<SceneNeeds> measureSceneNeeds(renderer::VulkanContext& context, const std::vector<double>& maxErrors) {
  const scene::Scene s = builtin("cornell", 0.0f);
  const ProbeGrid grid = renderer::sceneGrid(s, {8, 8, 8});
  renderer::UpdaterOptions o;
  o.samplesPerProbe = 128;
  renderer::ProbeUpdater u(context, s, grid, o);
  for (int k = 0; k < 4; ++k) u.update();
  const ProbeVolume v = u.volume();
  // Per active probe, the irradiance error of its l1, zh3 and l2 records.
  constexpr Representation kTried[3] = {Representation::L1, Representation::Zh3, Representation::L2};
  std::vector<std::array<double, 3>> errors;
  uint8_t record[kMaxRecordBytes];
  float decoded[kProbeFloats];
  for (uint32_t p = 0; p < grid.count(); ++p) {
    if (!v.active[p]) continue;
    const float* probe = &v.probes[static_cast<size_t>(p) * kProbeFloats];
    std::array<double, 3>& e = errors.emplace_back();
    for (int k = 0; k < 3; ++k) {
      encodeProbeRecord(kTried[k], probe, record);
      decodeProbeRecord(kTried[k], record, decoded);
      e[static_cast<size_t>(k)] = irradianceRmseRel(decoded, probe, nullptr, 1);
    }
  }
  SceneNeeds r;
  const StreamLayout layout = streamLayoutFor(grid, Representation::L2, 4);
  StreamEncoder encoder(layout);
  std::vector<uint8_t> frame;
  encoder.update(v.probes.data(), v.active.data());
  encoder.writeChangedFrame(frame);
  r.firstFrameBytes = static_cast<double>(frame.size());
  encoder.update(v.probes.data(), v.active.data());  // the same lighting again
  encoder.writeChangedFrame(frame);
  r.staticFrameBytes = static_cast<double>(frame.size());
  // The live stream once the blend weight has reached w_min, light still and then moving
  // (t += 0.004 per update).
  for (int k = 0; k < 16; ++k) u.update();
  StreamLayout live = layout;
  live.repr = Representation::Zh3;
  EncoderOptions eo;
  eo.deadzone = 1;
  for (int moving = 0; moving < 2; ++moving) {
    StreamEncoder stream(live, eo);
    stream.update(u.volume().probes.data(), u.volume().active.data());
    double bytes = 0;
    const int frames = 8;
    for (int f = 1; f <= frames; ++f) {
      if (moving) u.setScene(builtin("cornell", 0.004f * static_cast<float>(f)));
      u.update();
      stream.update(u.volume().probes.data(), u.volume().active.data());
      stream.writeChangedFrame(frame);
      bytes += static_cast<double>(frame.size());
    }
    (moving ? r.liveMovingBytesPerProbe : r.liveStillBytesPerProbe) = bytes / frames / grid.count();
  }
  // The smallest record under each error bound.
  std::vector<SceneNeeds> out;
  for (double maxError : maxErrors) {
    SceneNeeds n = r;
    n.maxError = maxError;
    n.probes = static_cast<uint32_t>(errors.size());
    for (const std::array<double, 3>& e : errors) {
      const auto k =
          static_cast<size_t>(std::find_if(e.begin(), e.end(), [&](double x) { return x <= maxError; }) - e.begin());
      const Representation chosen = k < 3 ? kTried[k] : Representation::Fp16;
      n.needL1 += chosen == Representation::L1;
      n.needZh3 += chosen == Representation::Zh3;
      n.needL2 += chosen == Representation::L2;
      n.needMore += chosen == Representation::Fp16;
      n.bytesSmallest += static_cast<double>(recordSize(chosen));
      n.bytesAllL2 += static_cast<double>(recordSize(Representation::L2));
    }
    out.push_back(n);
  }
  return out;
}

}  // namespace probecast::bench
