// The browser's decoder: the probe codec and the bus format compiled to WebAssembly. A page hands
// it the bus messages it receives (nats-server's WebSocket listener, the producer's JetStream
// stream) and reads back the volume it holds, decoded exactly as the native client decodes it.
//
// Every function takes the handle pc_viewer_new returned. Pointers into the module's memory stay
// valid until the next pc_viewer_message call.
#ifdef __EMSCRIPTEN__
#include <emscripten/emscripten.h>
#else  // the native build of the same entry points (fuzz/web_fuzz.cpp)
#define EMSCRIPTEN_KEEPALIVE
#endif

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "probecast/codec/probe_offsets.h"
#include "probecast/codec/probe_volume.h"
#include "probecast/codec/stream.h"
#include "probecast/service/bus_format.h"

namespace {

using namespace probecast;

struct Viewer {
  bool haveVolume = false;
  bus::Volume volume;  // the producer's volume message (layout, bounds, offsets, scene)
  std::unique_ptr<StreamDecoder> decoder;
  std::vector<float> offsets;  // metres, 3 per probe, or none
  ProbeVolume decoded;         // what pc_viewer_probes and the checksum read
  bool decodedStale = true;
  bus::SceneState state;  // of the newest brick applied
  uint32_t producerFrame = 0;
  uint64_t applied = 0, stale = 0, refused = 0, waiting = 0;
  std::vector<uint8_t> frame;
  std::string error, text;
  // Brick messages that came before their epoch's volume message (a stream replayed newest per
  // subject, in the order of publication, may put the volume last), applied when it comes.
  std::vector<std::vector<uint8_t>> pending;
  size_t pendingBytes = 0;
};

constexpr size_t kMaxPendingBytes = size_t{64} << 20;

Viewer* of(void* handle) { return static_cast<Viewer*>(handle); }

void refresh(Viewer& v) {
  if (!v.decodedStale || !v.decoder) return;
  v.decoder->copyVolume(v.volume.bounds, v.decoded);
  v.decoded.offsets = v.offsets;
  v.decoded.areaLights = v.volume.areaLights;
  v.decodedStale = false;
}

// Applies one section of the brick as a frame of its own (the decoder takes frames).
bool applySection(Viewer& v, std::span<const uint8_t> section, uint32_t version) {
  const std::span<const uint8_t> sections[] = {section};
  writeFrame(v.volume.layout, version, sections, v.frame);
  return v.decoder->apply(v.frame.data(), v.frame.size()) == CodecStatus::Ok;
}

}  // namespace

extern "C" {

EMSCRIPTEN_KEEPALIVE void* pc_viewer_new() { return new Viewer(); }
EMSCRIPTEN_KEEPALIVE void pc_viewer_free(void* handle) { delete of(handle); }
EMSCRIPTEN_KEEPALIVE uint8_t* pc_alloc(uint32_t bytes) { return static_cast<uint8_t*>(std::malloc(bytes ? bytes : 1)); }
EMSCRIPTEN_KEEPALIVE void pc_free(uint8_t* p) { std::free(p); }

// One bus message. Returns 1 for a volume message taken (a new epoch or layout starts afresh),
// 2 for a brick version applied, 3 for a brick that changed nothing (a version already held, or a
// brick before its volume message: kept until that comes),
// 0 for a message refused (pc_viewer_error says why; what the viewer held is kept).
EMSCRIPTEN_KEEPALIVE int pc_viewer_message(void* handle, const uint8_t* data, uint32_t size);
EMSCRIPTEN_KEEPALIVE int pc_viewer_message(void* handle, const uint8_t* data, uint32_t size) {
  Viewer& v = *of(handle);
  bus::Message m;
  std::string why;
  if (!bus::readMessage(data, size, m, why)) {
    ++v.refused;
    v.error = "bus message refused: " + why;
    return 0;
  }
  if (m.kind == bus::Kind::Volume) {
    const StreamLayout &a = m.volume.layout, &h = v.volume.layout;
    const bool same = v.haveVolume && m.volume.epoch == v.volume.epoch && a.grid[0] == h.grid[0] &&
                      a.grid[1] == h.grid[1] && a.grid[2] == h.grid[2] && a.repr == h.repr && a.brickDim == h.brickDim;
    std::vector<float> offsets;
    if (m.volume.hasOffsets) {
      const ProbeGrid grid = gridOf(m.volume.layout, m.volume.bounds);
      if (!dequantizeProbeOffsets(grid, m.volume.offsets.data(), m.volume.offsets.size(), offsets, why)) {
        ++v.refused;
        v.error = "volume message refused: " + why;
        return 0;
      }
    }
    if (!same) v.decoder = std::make_unique<StreamDecoder>(m.volume.layout);
    v.volume = std::move(m.volume);
    v.offsets = std::move(offsets);
    v.haveVolume = true;
    v.decodedStale = true;
    std::vector<std::vector<uint8_t>> waiting;
    waiting.swap(v.pending);
    v.pendingBytes = 0;
    for (const std::vector<uint8_t>& w : waiting) {  // this epoch's bricks apply; older ones are dropped
      bus::Message early;
      if (bus::readMessage(w.data(), w.size(), early, why) && early.volume.epoch == v.volume.epoch)
        pc_viewer_message(handle, w.data(), static_cast<uint32_t>(w.size()));
    }
    return 1;
  }
  if (!v.haveVolume || m.volume.epoch != v.volume.epoch) {
    ++v.waiting;  // a brick of an epoch whose volume message has not come (yet)
    if (v.pendingBytes + size <= kMaxPendingBytes) {
      v.pending.emplace_back(data, data + size);
      v.pendingBytes += size;
    }
    return 3;
  }
  const bus::Brick& b = m.brick;
  const uint32_t held = v.decoder->brickVersion(b.brick);
  if (b.version <= held) {
    ++v.stale;
    return 3;
  }
  // One version ahead: the delta, checked by the decoder; otherwise (or if it fails) the keyframe.
  bool ok = held + 1 == b.version && !b.delta.empty() && applySection(v, b.delta, b.version);
  if (!ok) ok = applySection(v, b.keyframe, b.version);
  if (!ok) {
    ++v.refused;
    v.error = "brick " + std::to_string(b.brick) + " version " + std::to_string(b.version) + " does not decode";
    return 0;
  }
  ++v.applied;
  v.state = b.state;
  v.producerFrame = b.producerFrame;
  v.decodedStale = true;
  return 2;
}

EMSCRIPTEN_KEEPALIVE const char* pc_viewer_error(void* handle) { return of(handle)->error.c_str(); }
EMSCRIPTEN_KEEPALIVE int pc_viewer_has_volume(void* handle) { return of(handle)->haveVolume ? 1 : 0; }
EMSCRIPTEN_KEEPALIVE uint32_t pc_viewer_dim(void* handle, int axis) {
  return of(handle)->haveVolume && axis >= 0 && axis < 3 ? of(handle)->volume.layout.grid[axis] : 0;
}
// bounds: 0..2 the first probe's position, 3..5 the last's (metres).
EMSCRIPTEN_KEEPALIVE float pc_viewer_bound(void* handle, int i) {
  const Viewer& v = *of(handle);
  if (!v.haveVolume || i < 0 || i > 5) return 0.0f;
  return i < 3 ? v.volume.bounds.min[i] : v.volume.bounds.max[i - 3];
}
EMSCRIPTEN_KEEPALIVE uint32_t pc_viewer_probe_count(void* handle) {
  return of(handle)->haveVolume ? probeCount(of(handle)->volume.layout) : 0;
}
EMSCRIPTEN_KEEPALIVE uint32_t pc_viewer_bricks(void* handle) {
  return of(handle)->haveVolume ? brickCount(of(handle)->volume.layout) : 0;
}
// Bricks holding some version (0 until every brick has arrived once: the volume is partial).
EMSCRIPTEN_KEEPALIVE uint32_t pc_viewer_bricks_held(void* handle) {
  const Viewer& v = *of(handle);
  if (!v.decoder) return 0;
  uint32_t n = 0;
  for (uint32_t b = 0; b < brickCount(v.volume.layout); ++b) n += v.decoder->brickVersion(b) > 0 ? 1 : 0;
  return n;
}
// 27 floats per probe (sh.h: L2 SH of incident radiance, coefficient-major RGB), 0 where inactive.
EMSCRIPTEN_KEEPALIVE const float* pc_viewer_probes(void* handle) {
  Viewer& v = *of(handle);
  refresh(v);
  return v.decoder ? v.decoded.probes.data() : nullptr;
}
EMSCRIPTEN_KEEPALIVE const uint8_t* pc_viewer_active(void* handle) {
  Viewer& v = *of(handle);
  refresh(v);
  return v.decoder ? v.decoded.active.data() : nullptr;
}
// 3 floats per probe (metres added to the grid position), or null when the probes sit on the grid.
EMSCRIPTEN_KEEPALIVE const float* pc_viewer_offsets(void* handle) {
  Viewer& v = *of(handle);
  return v.offsets.empty() ? nullptr : v.offsets.data();
}
EMSCRIPTEN_KEEPALIVE uint32_t pc_viewer_checksum(void* handle) {
  Viewer& v = *of(handle);
  if (!v.decoder) return 0;
  refresh(v);
  return volumeChecksum(v.decoded);
}
EMSCRIPTEN_KEEPALIVE double pc_viewer_scene_time(void* handle) { return of(handle)->state.time; }
EMSCRIPTEN_KEEPALIVE double pc_viewer_scene_rate(void* handle) { return of(handle)->state.rate; }
EMSCRIPTEN_KEEPALIVE double pc_viewer_scene_clock_us(void* handle) {
  return static_cast<double>(of(handle)->state.clockUs);
}
EMSCRIPTEN_KEEPALIVE double pc_viewer_published_us(void* handle) {
  return static_cast<double>(of(handle)->volume.publishedUs);
}
EMSCRIPTEN_KEEPALIVE double pc_viewer_count(void* handle, int which) {
  const Viewer& v = *of(handle);
  const uint64_t c[4] = {v.applied, v.stale, v.refused, v.waiting};
  return which >= 0 && which < 4 ? static_cast<double>(c[which]) : 0.0;
}
// The scene's package hash (64 hex digits; empty when the stream names none) and its manifest.
EMSCRIPTEN_KEEPALIVE const char* pc_viewer_scene_hash(void* handle) {
  Viewer& v = *of(handle);
  v.text.clear();
  if (v.haveVolume && v.volume.hasScene())
    for (uint8_t byte : v.volume.sceneHash) {
      char hex[3];
      std::snprintf(hex, sizeof hex, "%02x", byte);
      v.text += hex;
    }
  return v.text.c_str();
}
EMSCRIPTEN_KEEPALIVE const char* pc_viewer_scene_manifest(void* handle) {
  return of(handle)->volume.sceneManifest.c_str();
}
// The stream's client area light rule (probe_volume.h AreaLightRule): 0 when the probes hold every
// emitter, else the rule's version (the viewer must draw those emitters' direct light itself).
EMSCRIPTEN_KEEPALIVE uint32_t pc_viewer_area_light_rule(void* handle) {
  return of(handle)->haveVolume ? of(handle)->volume.areaLights.version : 0;
}
// Its threshold: the share of the scene's emitted power a material needs to be client-lit.
EMSCRIPTEN_KEEPALIVE float pc_viewer_area_light_share(void* handle) {
  return of(handle)->haveVolume ? of(handle)->volume.areaLights.minPowerFraction : 0.0f;
}

// The representation's name as the CLI spells it (l1, zh3h, zh3, l2, fp16, float).
EMSCRIPTEN_KEEPALIVE const char* pc_viewer_representation(void* handle) {
  const Viewer& v = *of(handle);
  return v.haveVolume ? representationName(v.volume.layout.repr) : "";
}

}  // extern "C"
