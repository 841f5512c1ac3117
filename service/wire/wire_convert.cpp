#include "wire_convert.h"

#include <cmath>
#include <cstring>

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/wire_format_lite.h>

#include "probecast/codec/probe_offsets.h"
#include "probecast/service/scene_package.h"

namespace probecast::service {

const char* const kShConvention =
    "real SH L0-L2 without the Condon-Shortley phase, index l(l+1)+m, 27 floats per probe coefficient-major "
    "(RGB per coefficient), incident radiance";

void volumeToWire(const bus::Volume& v, v1::VolumeDescription& out) {
  const StreamLayout& layout = v.layout;
  const GridBounds& bounds = v.bounds;
  out.set_protocol_version(kProtocolVersion);
  out.set_codec_format_version(kFormatVersion);
  out.set_grid_x(layout.grid[0]);
  out.set_grid_y(layout.grid[1]);
  out.set_grid_z(layout.grid[2]);
  out.set_brick_size(layout.brickDim);
  out.set_representation(static_cast<v1::Representation>(layout.repr));
  out.clear_bounds_min();
  out.clear_bounds_max();
  for (int a = 0; a < 3; ++a) {
    out.add_bounds_min(bounds.min[a]);
    out.add_bounds_max(bounds.max[a]);
  }
  out.set_sh_convention(kShConvention);
  out.set_stream_epoch(v.epoch);
  out.set_probe_offsets(reinterpret_cast<const char*>(v.offsets.data()), v.offsets.size());
  out.set_area_light_rule(v.areaLights.version);
  out.set_area_light_min(v.areaLights.minPowerFraction);
  if (v.hasScene()) {
    out.set_scene_hash(reinterpret_cast<const char*>(v.sceneHash.data()), v.sceneHash.size());
    out.set_scene_manifest(v.sceneManifest);
  } else {
    out.clear_scene_hash();
    out.clear_scene_manifest();
  }
}

bool volumeFromWire(const v1::VolumeDescription& in, StreamLayout& layout, GridBounds& bounds,
                    std::vector<float>& offsets, AreaLightRule& areaLights, SceneStamp& scene, std::string& why) {
  if (in.protocol_version() != kProtocolVersion)
    return why = "server speaks protocol version " + std::to_string(in.protocol_version()) + ", not " +
                 std::to_string(kProtocolVersion), false;
  // A resumed description's held parts are put back by the client that holds them; one that comes
  // with them left out to anyone else is incomplete.
  if (in.held_parts()) return why = "the description leaves out probe offsets and a manifest this client does not hold", false;
  if (in.codec_format_version() != kFormatVersion)
    return why = "server sends codec format version " + std::to_string(in.codec_format_version()) + ", not " +
                 std::to_string(kFormatVersion), false;
  // Range-check every number before narrowing it: 70000 must not wrap to a small grid.
  const uint32_t grid[3] = {in.grid_x(), in.grid_y(), in.grid_z()};
  const auto gridText = [&] {
    return "volume grid " + std::to_string(grid[0]) + "x" + std::to_string(grid[1]) + "x" + std::to_string(grid[2]);
  };
  for (uint32_t g : grid)
    if (g < 1 || g > static_cast<uint32_t>(kMaxGridDim))
      return why = gridText() + " is outside 1.." + std::to_string(kMaxGridDim) + " per axis", false;
  if (in.brick_size() < static_cast<uint32_t>(kMinBrickDim) || in.brick_size() > static_cast<uint32_t>(kMaxBrickDim))
    return why = "brick size " + std::to_string(in.brick_size()) + " is outside " + std::to_string(kMinBrickDim) +
                 ".." + std::to_string(kMaxBrickDim), false;
  const int repr = in.representation();  // an open enum: any int32 may arrive
  if (!v1::Representation_IsValid(repr) || !isValidRepresentation(static_cast<uint8_t>(repr)))  // 0 is not one
    return why = "representation " + std::to_string(repr) + " is not one the client decodes", false;
  StreamLayout l;
  for (int a = 0; a < 3; ++a) l.grid[a] = static_cast<uint16_t>(grid[a]);
  l.brickDim = static_cast<uint8_t>(in.brick_size());
  l.repr = static_cast<Representation>(repr);
  if (!isValidLayout(l))
    return why = gridText() + " holds more than " + std::to_string(kMaxProbes) + " probes", false;
  if (in.bounds_min_size() != 3 || in.bounds_max_size() != 3) return why = "volume bounds need 3 values each", false;
  for (int a = 0; a < 3; ++a) {
    bounds.min[a] = in.bounds_min(a);
    bounds.max[a] = in.bounds_max(a);
    if (!std::isfinite(bounds.min[a]) || !std::isfinite(bounds.max[a])) return why = "volume bounds not finite", false;
  }
  const AreaLightRule rule{in.area_light_rule(), in.area_light_min()};
  if (!checkAreaLightRule(rule, why)) return false;
  const std::string& q = in.probe_offsets();
  if (!dequantizeProbeOffsets(gridOf(l, bounds), reinterpret_cast<const int8_t*>(q.data()), q.size(), offsets, why))
    return false;
  SceneStamp named;
  if (!in.scene_hash().empty() || !in.scene_manifest().empty()) {
    if (in.scene_hash().size() != named.hash.size() || in.scene_manifest().empty())
      return why = "the scene is named by a hash of " + std::to_string(in.scene_hash().size()) +
                   " bytes (32) with a manifest of " + std::to_string(in.scene_manifest().size()), false;
    if (in.scene_manifest().size() > kMaxSceneManifestBytes) return why = "the scene manifest is over 256 KiB", false;
    std::memcpy(named.hash.data(), in.scene_hash().data(), named.hash.size());
    named.manifest = in.scene_manifest();
  }
  layout = l;
  areaLights = rule;
  scene = std::move(named);
  return true;
}

bool viewsFromWire(const v1::ViewUpdate& in, uint32_t maxViews, std::vector<View>& out, std::string& why) {
  if (static_cast<uint32_t>(in.views_size()) > maxViews)
    return why = std::to_string(in.views_size()) + " views exceed the limit of " + std::to_string(maxViews), false;
  out.clear();
  for (const v1::View& v : in.views()) {
    if (v.view_projection_size() != 16) return why = "a view_projection must have 16 floats", false;
    View view{};
    for (int i = 0; i < 16; ++i) {
      view.viewProj[i] = v.view_projection(i);
      if (!std::isfinite(view.viewProj[i])) return why = "a view_projection holds NaN or Inf", false;
    }
    view.eye[0] = v.eye_x();
    view.eye[1] = v.eye_y();
    view.eye[2] = v.eye_z();
    for (float e : view.eye)
      if (!std::isfinite(e)) return why = "an eye position holds NaN or Inf", false;
    out.push_back(view);
  }
  return true;
}

void viewsToWire(const std::vector<View>& views, v1::ViewUpdate& out) {
  out.clear_views();
  for (const View& v : views) {
    v1::View* w = out.add_views();
    for (float f : v.viewProj) w->add_view_projection(f);
    w->set_eye_x(v.eye[0]);
    w->set_eye_y(v.eye[1]);
    w->set_eye_z(v.eye[2]);
  }
}

namespace {

using google::protobuf::io::CodedOutputStream;
using google::protobuf::internal::WireFormatLite;

size_t varintFieldBytes(uint64_t v) { return v == 0 ? 0 : 1 + CodedOutputStream::VarintSize64(v); }

uint8_t* putVarintField(int field, uint64_t v, uint8_t* out) {
  if (v == 0) return out;  // proto3 leaves zero scalars out
  out = CodedOutputStream::WriteTagToArray(WireFormatLite::MakeTag(field, WireFormatLite::WIRETYPE_VARINT), out);
  return CodedOutputStream::WriteVarint64ToArray(v, out);
}

// The scene_state field (a present message is written even when empty).
size_t stateFieldBytes(const FrameFields& f) {
  return f.sceneState ? 1 + CodedOutputStream::VarintSize64(f.sceneState->size()) + f.sceneState->size() : 0;
}

// The Frame message's own size (without the ServerMessage field that holds it).
size_t frameMessageBytes(const FrameFields& f) {
  const size_t payload = f.payloadBytes == 0 ? 0 : 1 + CodedOutputStream::VarintSize64(f.payloadBytes) + f.payloadBytes;
  return varintFieldBytes(f.sequence) + varintFieldBytes(f.serverTimeUs) + payload + varintFieldBytes(f.keyframes) +
         varintFieldBytes(f.deltas) + stateFieldBytes(f) + varintFieldBytes(f.sentUs);
}

}  // namespace

size_t framePrefixBytes(const FrameFields& f) {
  const size_t frame = frameMessageBytes(f);
  return 1 + CodedOutputStream::VarintSize64(frame) + varintFieldBytes(f.sequence) + varintFieldBytes(f.serverTimeUs) +
         (f.payloadBytes == 0 ? 0 : 1 + CodedOutputStream::VarintSize64(f.payloadBytes));
}

size_t frameSuffixBytes(const FrameFields& f) {
  return varintFieldBytes(f.keyframes) + varintFieldBytes(f.deltas) + stateFieldBytes(f) + varintFieldBytes(f.sentUs);
}

uint8_t* writeFramePrefix(const FrameFields& f, uint8_t* out) {
  out = CodedOutputStream::WriteTagToArray(
      WireFormatLite::MakeTag(v1::ServerMessage::kFrameFieldNumber, WireFormatLite::WIRETYPE_LENGTH_DELIMITED), out);
  out = CodedOutputStream::WriteVarint64ToArray(frameMessageBytes(f), out);
  out = putVarintField(v1::Frame::kSequenceFieldNumber, f.sequence, out);
  out = putVarintField(v1::Frame::kServerTimeUsFieldNumber, f.serverTimeUs, out);
  if (f.payloadBytes == 0) return out;
  out = CodedOutputStream::WriteTagToArray(
      WireFormatLite::MakeTag(v1::Frame::kPayloadFieldNumber, WireFormatLite::WIRETYPE_LENGTH_DELIMITED), out);
  return CodedOutputStream::WriteVarint64ToArray(f.payloadBytes, out);
}

uint8_t* writeFrameSuffix(const FrameFields& f, uint8_t* out) {
  out = putVarintField(v1::Frame::kKeyframesFieldNumber, f.keyframes, out);
  out = putVarintField(v1::Frame::kDeltasFieldNumber, f.deltas, out);
  if (f.sceneState) {
    out = CodedOutputStream::WriteTagToArray(
        WireFormatLite::MakeTag(v1::Frame::kSceneStateFieldNumber, WireFormatLite::WIRETYPE_LENGTH_DELIMITED), out);
    out = CodedOutputStream::WriteVarint64ToArray(f.sceneState->size(), out);
    out = CodedOutputStream::WriteRawToArray(f.sceneState->data(), static_cast<int>(f.sceneState->size()), out);
  }
  return putVarintField(v1::Frame::kSentUsFieldNumber, f.sentUs, out);
}

void stateToWire(const bus::SceneState& in, v1::SceneState& out) {
  out.Clear();
  out.set_time_s(in.time);
  out.set_rate(in.rate);
  out.set_clock_us(in.clockUs);
  for (const bus::LightState& l : in.lights) {
    v1::Light* w = out.add_lights();
    w->set_type(l.type);
    for (int a = 0; a < 3; ++a) {
      w->add_position(l.position[a]);
      w->add_direction(l.direction[a]);
      w->add_color(l.color[a]);
    }
    w->set_intensity(l.intensity);
    w->set_range(l.range);
    w->set_inner_cone(l.innerCone);
    w->set_outer_cone(l.outerCone);
  }
}

bool stateFromWire(const v1::SceneState& in, bus::SceneState& out, std::string& why) {
  if (static_cast<uint32_t>(in.lights_size()) > bus::kMaxStateLights)
    return why = "scene state with " + std::to_string(in.lights_size()) + " lights (at most 64)", false;
  bus::SceneState st;
  st.time = in.time_s();
  st.rate = in.rate();
  st.clockUs = in.clock_us();
  for (const v1::Light& w : in.lights()) {
    if (w.position_size() != 3 || w.direction_size() != 3 || w.color_size() != 3)
      return why = "a scene light needs 3 floats of position, direction and colour", false;
    bus::LightState l;
    l.type = w.type();
    for (int a = 0; a < 3; ++a) {
      l.position[a] = w.position(a);
      l.direction[a] = w.direction(a);
      l.color[a] = w.color(a);
    }
    l.intensity = w.intensity();
    l.range = w.range();
    l.innerCone = w.inner_cone();
    l.outerCone = w.outer_cone();
    st.lights.push_back(l);
  }
  if (!bus::checkSceneState(st, why)) return false;
  out = std::move(st);
  return true;
}

std::string descriptionDigest(const std::string& probeOffsets, const std::string& sceneManifest) {
  std::string bytes;
  bytes.reserve(16 + probeOffsets.size() + sceneManifest.size());
  for (const std::string* part : {&probeOffsets, &sceneManifest}) {
    const uint64_t n = part->size();
    for (int k = 0; k < 8; ++k) bytes.push_back(static_cast<char>((n >> (8 * k)) & 0xff));
    bytes += *part;
  }
  const SceneHash h = sha256(bytes);
  return std::string(reinterpret_cast<const char*>(h.data()), h.size());
}

}  // namespace probecast::service
