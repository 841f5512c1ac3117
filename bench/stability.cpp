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

// Directions on a spherical Fibonacci set.
std::vector<glm::vec3> fibonacci(int n) {
  std::vector<glm::vec3> d(static_cast<size_t>(n));
  const double golden = 3.883222077450933;  // π (3 − √5)
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = golden * i;
    d[static_cast<size_t>(i)] =
        glm::vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
  }
  return d;
}

// Ambient plus a smooth lobe towards `dir`, projected to L2 with many samples.
Probe lobeProbe(const glm::vec3& dir, const glm::vec3& color) {
  Probe p(kProbeFloats, 0.0f);
  const auto dirs = fibonacci(8192);
  const float w = 4.0f * kPi / static_cast<float>(dirs.size());
  for (const glm::vec3& d : dirs) {
    const float lobe = std::pow(std::max(0.0f, glm::dot(d, dir)), 6.0f);
    const float rgb[3] = {0.1f + 2.0f * lobe * color.r, 0.1f + 2.0f * lobe * color.g, 0.1f + 2.0f * lobe * color.b};
    shAddSample(p.data(), d.x, d.y, d.z, rgb, w);
  }
  return p;
}

Probe mix(const Probe& a, const Probe& b, float w) {
  Probe out(kProbeFloats);
  for (int i = 0; i < kProbeFloats; ++i) out[i] = (1.0f - w) * a[i] + w * b[i];
  return out;
}

Probe storedZh3(const Probe& p) {  // L1 + stored zonal coefficient, expanded to SH3
  Probe out = p;
  float axis[3], zonal[3];
  zh3Axis(p.data(), axis);
  zh3Project(p.data(), axis, zonal);
  zh3ExpandToL2(out.data(), axis, zonal);
  return out;
}

Probe hallucinated(const Probe& p) {
  Probe out = p;
  zh3HallucinateInPlace(out.data());
  return out;
}

double probeError(const Probe& test, const Probe& reference) {
  return irradianceRmseRel(test.data(), reference.data(), nullptr, 1);
}

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

Zh3Blending measureZh3Blending() {
  const Probe a = lobeProbe({1, 0, 0}, {1.0f, 0.8f, 0.6f}), b = lobeProbe({0, 1, 0}, {0.6f, 0.8f, 1.0f});
  const Probe za = storedZh3(a), zb = storedZh3(b), ha = hallucinated(a), hb = hallucinated(b);
  Zh3Blending r;
  for (int k = 0; k <= 20; ++k) {
    const float w = static_cast<float>(k) / 20.0f;
    const Probe truth = mix(a, b, w);
    // Naive: blend L1 and the zonal coefficients, re-derive the axis from the blended L1.
    float axisA[3], axisB[3], zonalA[3], zonalB[3], axis[3], zonal[3];
    zh3Axis(a.data(), axisA);
    zh3Axis(b.data(), axisB);
    zh3Project(a.data(), axisA, zonalA);
    zh3Project(b.data(), axisB, zonalB);
    Probe naive = truth;
    zh3Axis(naive.data(), axis);
    for (int c = 0; c < 3; ++c) zonal[c] = (1.0f - w) * zonalA[c] + w * zonalB[c];
    zh3ExpandToL2(naive.data(), axis, zonal);
    Probe l1 = truth;
    std::fill(l1.begin() + 12, l1.end(), 0.0f);
    r.storedExpandedFirst = std::max(r.storedExpandedFirst, probeError(mix(za, zb, w), truth));
    r.storedNaive = std::max(r.storedNaive, probeError(naive, truth));
    r.hallucinatedInterpolateFirst = std::max(r.hallucinatedInterpolateFirst, probeError(hallucinated(l1), truth));
    r.hallucinatedPerProbe = std::max(r.hallucinatedPerProbe, probeError(mix(ha, hb, w), truth));
    r.l1 = std::max(r.l1, probeError(l1, truth));
  }
  return r;
}

Ringing measureRinging(double capDeg) {
  Ringing r;
  r.capDeg = capDeg;
  const double alpha = capDeg * 3.14159265358979 / 180.0, ca = std::cos(alpha), sa2 = 1.0 - ca * ca;
  const double radiance = 1.0 / (3.14159265358979 * sa2);  // irradiance facing the cap = 1
  // The cap around +z in SH, exactly: c_l0 = 2π L ∫_{cos α}^1 Y_l0(t) dt.
  Probe p(kProbeFloats, 0.0f);
  const double c00 = 2.0 * 3.14159265358979 * radiance * kY00 * (1.0 - ca);
  const double c10 = 3.14159265358979 * radiance * kY1 * sa2;
  const double c20 = 2.0 * 3.14159265358979 * radiance * kY20 * ca * sa2;
  for (int c = 0; c < 3; ++c) {
    p[0 * 3 + c] = static_cast<float>(c00);
    p[2 * 3 + c] = static_cast<float>(c10);
    p[6 * 3 + c] = static_cast<float>(c20);
  }
  // Exact irradiance: the cap integrated on a fine (cos θ, φ) grid.
  const int nt = 64, np = 128;
  std::vector<glm::dvec3> capDirs;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      const double ct = 1.0 - (1.0 - ca) * (i + 0.5) / nt, st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
      const double phi = 2.0 * 3.14159265358979 * (j + 0.5) / np;
      capDirs.emplace_back(st * std::cos(phi), st * std::sin(phi), ct);
    }
  const double dOmega = 2.0 * 3.14159265358979 * (1.0 - ca) / static_cast<double>(capDirs.size());
  const auto normals = fibonacci(4096);
  double maxExact = 0, minL2 = std::numeric_limits<double>::max(), err = 0, errClamped = 0, energy = 0;
  int negative = 0;
  for (const glm::vec3& nf : normals) {
    const glm::dvec3 n(nf);
    double exact = 0;
    for (const glm::dvec3& d : capDirs) exact += std::max(0.0, glm::dot(n, d));
    exact *= radiance * dOmega;
    float rgb[3];
    shEvalIrradiance(p.data(), nf.x, nf.y, nf.z, rgb);
    const double l2 = rgb[0];
    maxExact = std::max(maxExact, exact);
    minL2 = std::min(minL2, l2);
    negative += l2 < 0.0;
    err += (l2 - exact) * (l2 - exact);
    errClamped += (std::max(l2, 0.0) - exact) * (std::max(l2, 0.0) - exact);
    energy += exact * exact;
  }
  r.minIrradianceRel = minL2 / maxExact;
  r.negativeFraction = static_cast<double>(negative) / static_cast<double>(normals.size());
  r.rmseRelUnclamped = std::sqrt(err / energy);
  r.rmseRelClamped = std::sqrt(errClamped / energy);
  return r;
}

WallLeak measureWallLeak(renderer::VulkanContext& context) {
  const scene::Scene s = builtin("thin-wall", 0.0f);
  const ProbeGrid grid = renderer::sceneGrid(s, {9, 5, 5});  // 9 along x: one plane inside the wall
  const auto traced = [&](bool classify) {
    renderer::UpdaterOptions o;
    o.samplesPerProbe = 128;
    o.classify = classify;
    o.relocate = false;  // classification alone: probes in the wall switch off rather than move
    o.surfaceProbesOnly = false;  // and only the probes inside geometry: the idle ones count as traced
    renderer::ProbeUpdater u(context, s, grid, o);
    u.update();
    u.update();
    return u.volume();
  };
  const ProbeVolume on = traced(true), off = traced(false);
  WallLeak r;
  r.probes = grid.count();
  for (uint8_t a : on.active) r.inactiveProbes += a == 0;
  r.raySavings = static_cast<double>(r.inactiveProbes) / r.probes;
  const uint32_t w = 48, h = 32;
  // Classification alone: visibility (on by default) also keeps probes inside the wall out.
  renderer::RasterOptions plain = singleSampleRaster();
  plain.visibility = false;
  renderer::RasterRenderer raster(context, s, w, h, plain);
  const renderer::CameraView cam = renderer::CameraView::fromScene(s);
  const auto mean = [](const renderer::Image& img) {
    double sum = 0;
    for (float v : img.rgb) sum += v;
    return sum / static_cast<double>(img.rgb.size());
  };
  renderer::ReferenceOptions ro;
  ro.width = w;
  ro.height = h;
  ro.samplesPerPixel = 256;
  const double reference = mean(renderer::renderReference(context, s, cam, ro));
  raster.setProbes(on);
  r.meanErrorRelClassified =
      std::abs(mean(raster.render(raster.viewProjection(cam), cam.position)) - reference) / reference;
  raster.setProbes(off);
  r.meanErrorRelUnclassified =
      std::abs(mean(raster.render(raster.viewProjection(cam), cam.position)) - reference) / reference;
  return r;
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

ExtremeInputs measureExtremeInputs() {
  ExtremeInputs r;
  r.allFinite = true;
  uint8_t record[kMaxRecordBytes];
  float decoded[kProbeFloats];
  const auto roundTrip = [&](Representation repr, const Probe& p) {
    encodeProbeRecord(repr, p.data(), record);
    decodeProbeRecord(repr, record, decoded);
    for (float v : decoded) r.allFinite = r.allFinite && std::isfinite(v);
    return Probe(decoded, decoded + kProbeFloats);
  };
  for (Representation repr : kAllRepresentations) {
    for (float v : roundTrip(repr, Probe(kProbeFloats, 0.0f)))
      r.blackMaxAbs = std::max(r.blackMaxAbs, static_cast<double>(std::fabs(v)));
    Probe nan = lobeProbe({0, 0, 1}, {1, 1, 1});
    nan[4] = std::numeric_limits<float>::quiet_NaN();
    nan[13] = std::numeric_limits<float>::infinity();
    for (float v : roundTrip(repr, nan))
      r.nanDecodedMaxAbs = std::max(r.nanDecodedMaxAbs, static_cast<double>(std::fabs(v)));
  }
  for (float scale : {1e2f, 1e3f, 1e4f, 1e5f, 1e6f}) {
    Probe bright = lobeProbe({0.6f, 0.8f, 0.0f}, {1.0f, 0.5f, 0.25f});
    for (float& v : bright) v *= scale;
    r.brightRelError.emplace_back(scale, probeError(roundTrip(Representation::L2, bright), bright));
  }
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

namespace {

// Each case's report: its figures in the JSON and its section of the markdown.

void reportFlickerLag(const std::vector<FlickerLag>& fl, StabilityResult& out) {
  out.markdown +=
      "### Temporal flicker against lag (builtin:cornell, 4³ probes, 32 samples per probe per update)\n\n"
      "| w_min | flicker per update | error before the jump | updates to recover after the light jumps "
      "|\n|---|---|---|---|\n";
  for (const FlickerLag& f : fl) {
    out.json["flicker_lag"].push_back({{"w_min", f.wMin},
                                       {"flicker_rel", f.flickerRel},
                                       {"error_before_jump", f.errorBeforeJump},
                                       {"error_after_jump", f.errorAfterJump},
                                       {"updates_to_recover", f.updatesToRecover}});
    out.markdown += fmt::format("| {:g} | {:.2f}% | {:.2f}% | {} |\n", f.wMin, 100 * f.flickerRel,
                                100 * f.errorBeforeJump,
                                f.updatesToRecover < 0 ? std::string("> 48") : std::to_string(f.updatesToRecover));
  }
}

void reportZh3Blending(const Zh3Blending& zb, StabilityResult& out) {
  out.json["zh3_blending"] = {{"stored_expanded_first", zb.storedExpandedFirst},
                              {"stored_naive", zb.storedNaive},
                              {"hallucinated_interpolate_first", zb.hallucinatedInterpolateFirst},
                              {"hallucinated_per_probe", zb.hallucinatedPerProbe},
                              {"l1", zb.l1}};
  out.markdown += fmt::format(
      "\n### ZH3 blended across probes with competing axes (worst irradiance error over the blend)\n\n"
      "| stored ZH3, expanded to SH3 first | stored ZH3, naive | hallucinated, interpolate first | "
      "hallucinated per probe | L1 alone |\n|---|---|---|---|---|\n| {:.2f}% | {:.2f}% | {:.2f}% | {:.2f}% | {:.2f}% "
      "|\n",
      100 * zb.storedExpandedFirst, 100 * zb.storedNaive, 100 * zb.hallucinatedInterpolateFirst,
      100 * zb.hallucinatedPerProbe, 100 * zb.l1);
}

void reportRinging(const std::vector<Ringing>& ringing, StabilityResult& out) {
  out.markdown +=
      "\n### SH ringing under a small strong light (L2 irradiance of a cap against the exact one)\n\n"
      "| cap half-angle | most negative / peak | normals negative | error unclamped | error clamped at 0 "
      "|\n|---|---|---|---|---|\n";
  for (const Ringing& rg : ringing) {
    out.json["ringing"].push_back({{"cap_deg", rg.capDeg},
                                   {"min_irradiance_rel", rg.minIrradianceRel},
                                   {"negative_fraction", rg.negativeFraction},
                                   {"rmse_rel_unclamped", rg.rmseRelUnclamped},
                                   {"rmse_rel_clamped", rg.rmseRelClamped}});
    out.markdown += fmt::format("| {:g}° | {:.2f}% | {:.1f}% | {:.2f}% | {:.2f}% |\n", rg.capDeg,
                                100 * rg.minIrradianceRel, 100 * rg.negativeFraction, 100 * rg.rmseRelUnclamped,
                                100 * rg.rmseRelClamped);
  }
}

void reportWallLeak(const WallLeak& wl, StabilityResult& out) {
  out.json["wall_leak"] = {{"probes", wl.probes},
                           {"inactive_probes", wl.inactiveProbes},
                           {"mean_error_rel_classified", wl.meanErrorRelClassified},
                           {"mean_error_rel_unclassified", wl.meanErrorRelUnclassified},
                           {"ray_savings", wl.raySavings}};
  out.markdown += fmt::format(
      "\n### Probes inside walls (builtin:thin-wall, 9×5×5 probes, seen from the lit room)\n\n"
      "Classification marks {} of {} probes inactive ({:.0f}% of probe rays not traced). Mean radiance "
      "against the reference: {:.1f}% off with classification, {:.1f}% off without (the dark leak).\n",
      wl.inactiveProbes, wl.probes, 100 * wl.raySavings, 100 * wl.meanErrorRelClassified,
      100 * wl.meanErrorRelUnclassified);
}

void reportNetworkFaults(const NetworkFaults& nf, StabilityResult& out) {
  out.json["network_faults"] = {{"lighting_kept_during_outage", nf.lightingKeptDuringOutage},
                                {"bit_exact_after_resume", nf.bitExactAfterResume},
                                {"seconds_to_bit_exact", nf.secondsToBitExact},
                                {"resume_bytes", nf.resumeBytes},
                                {"newcomer_bytes", nf.newcomerBytes},
                                {"slow_link_budget", nf.slowLinkBudget},
                                {"slow_link_seconds_to_bit_exact", nf.slowLinkSecondsToBitExact},
                                {"fast_seconds_to_bit_exact", nf.fastSecondsToBitExact},
                                {"latency_ms_p50", nf.latencyP50Ms},
                                {"latency_ms_p99", nf.latencyP99Ms},
                                {"slow_link_latency_ms_p50", nf.slowLinkLatencyP50Ms}};
  out.markdown += fmt::format(
      "\n### Network faults (loopback gRPC, 32×8×32 probes, zh3)\n\n"
      "A 2 s outage while the light moves: the viewer kept its last volume ({}); after the link came "
      "back it held the server's volume bit for bit ({}) in {:.2f} s, receiving {:.0f} bytes where a "
      "newcomer needed {:.0f}. A subscriber on a {:.0f} B/s link reached the same volume in {:.1f} s "
      "while an unlimited one took {:.2f} s. Produce → decoded latency with the light moving (50 updates/s): "
      "p50 {:.1f} ms, p99 {:.1f} ms unlimited; {:.0f} ms p50 on the slow link (versions wait for budget, "
      "and stale ones are skipped, not queued).\n",
      nf.lightingKeptDuringOutage ? "yes" : "no", nf.bitExactAfterResume ? "yes" : "no", nf.secondsToBitExact,
      nf.resumeBytes, nf.newcomerBytes, nf.slowLinkBudget, nf.slowLinkSecondsToBitExact, nf.fastSecondsToBitExact,
      nf.latencyP50Ms, nf.latencyP99Ms, nf.slowLinkLatencyP50Ms);
}

void reportExtremeInputs(const ExtremeInputs& ex, StabilityResult& out) {
  out.json["extreme_inputs"] = {
      {"black_max_abs", ex.blackMaxAbs}, {"nan_decoded_max_abs", ex.nanDecodedMaxAbs}, {"all_finite", ex.allFinite}};
  std::string bright;
  for (const auto& [scale, err] : ex.brightRelError) {
    out.json["extreme_inputs"]["bright_rel_error"].push_back({{"scale", scale}, {"rel_error", err}});
    bright += fmt::format("{}{:g}: {:.2f}%", bright.empty() ? "" : ", ", scale, 100 * err);
  }
  out.markdown += fmt::format(
      "\n### Extreme inputs through the codec\n\nBlack probes decode to at most {:g}. NaN and Inf "
      "radiance decode to finite values (largest {:g}); every decoded value finite: {}. Bright probes "
      "(l2 records, irradiance error by radiance scale) — {}: past the RGB9E5 ceiling of 65408 on the "
      "DC the error is bounded but large, so scenes brighter than that should be exposure-scaled "
      "before encoding.\n",
      ex.blackMaxAbs, ex.nanDecodedMaxAbs, ex.allFinite ? "yes" : "no", bright);
}

void reportSceneNeeds(const std::vector<SceneNeeds>& needs, StabilityResult& out) {
  std::string& md = out.markdown;
  for (const SceneNeeds& sn : needs) {
    out.json["scene_needs"].push_back({{"max_error", sn.maxError},
                                       {"probes", sn.probes},
                                       {"need_l1", sn.needL1},
                                       {"need_zh3", sn.needZh3},
                                       {"need_l2", sn.needL2},
                                       {"need_more", sn.needMore},
                                       {"bytes_all_l2", sn.bytesAllL2},
                                       {"bytes_smallest", sn.bytesSmallest},
                                       {"first_frame_bytes", sn.firstFrameBytes},
                                       {"static_frame_bytes", sn.staticFrameBytes},
                                       {"live_still_bytes_per_probe", sn.liveStillBytesPerProbe},
                                       {"live_moving_bytes_per_probe", sn.liveMovingBytesPerProbe}});
    if (sn.maxError == 0.05) md += "\n### No more than the scene needs (builtin:cornell, 8³ probes)\n";
    md += fmt::format(
        "\nFor an irradiance error of at most {:.0f}% per probe, {} active probes need: l1 {}, zh3 {}, l2 {}, more "
        "than l2 {} — {:.0f} "
        "bytes of records instead of {:.0f} for all-l2. A frame after publishing unchanged lighting is "
        "{:.0f} bytes (the first was {:.0f}).\n",
        100 * sn.maxError, sn.probes, sn.needL1, sn.needZh3, sn.needL2, sn.needMore, sn.bytesSmallest, sn.bytesAllL2,
        sn.staticFrameBytes, sn.firstFrameBytes);
    if (sn.maxError == 0.05)
      md += fmt::format(
          "\nThe live stream (zh3, dead-zone 1, every update published, headers included) costs {:.2f} bytes per "
          "probe per frame with the light still (Monte Carlo noise above the dead-zone) and {:.2f} with it moving, "
          "against 56 for a raw fp16 grid sent every frame.\n",
          sn.liveStillBytesPerProbe, sn.liveMovingBytesPerProbe);
  }
}

}  // namespace

StabilityResult runStabilitySuite(const StabilityOptions& o) {
  const auto say = [&](const std::string& line) { sayProgress(o.progress, line); };
  renderer::VulkanContext context{renderer::ContextOptions{}};
  StabilityResult out;
  out.json["command"] = o.command;
  out.json["codec_format_version"] = kFormatVersion;
  out.json["device"] = context.deviceName();
  say("stability: flicker and lag against w_min");
  reportFlickerLag(measureFlickerLag(context, {{0.02f, 0}, {0.05f, 0}, {0.1f, 0}, {0.25f, 0}}, 32, 48), out);
  say("stability: ZH3 blending");
  reportZh3Blending(measureZh3Blending(), out);
  say("stability: SH ringing");
  std::vector<Ringing> ringing;
  for (double cap : {2.0, 10.0, 30.0}) ringing.push_back(measureRinging(cap));
  reportRinging(ringing, out);
  say("stability: probes inside a thin wall");
  reportWallLeak(measureWallLeak(context), out);
  say("stability: network faults");
  reportNetworkFaults(measureNetworkFaults(), out);
  say("stability: extreme inputs");
  reportExtremeInputs(measureExtremeInputs(), out);
  say("stability: what the scene needs");
  reportSceneNeeds(measureSceneNeeds(context, {0.05, 0.10}), out);
  out.table = out.markdown;
  return out;
}

}  // namespace probecast::bench
