// Writes the seed corpus for client_fuzz into a folder: a description (with and without a glTF
// scene package) followed by real frames of every representation, and the package's pieces.
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "client_fuzz_common.h"
#include "codec_fuzz_common.h"
#include "probecast.pb.h"
#include "probecast/service/scene_package.h"

using namespace probecast;

namespace {

// A package of one small glTF file and a buffer, with its canonical manifest.
service::ScenePackage samplePackage(std::string& gltf, std::string& bin) {
  gltf = R"({"asset":{"version":"2.0"},"buffers":[{"uri":"b.bin","byteLength":4}]})";
  bin = "abcd";
  const nlohmann::json files = nlohmann::json::array(
      {{{"bytes", bin.size()}, {"path", "b.bin"}, {"sha256", service::hexOf(service::sha256(bin))}},
       {{"bytes", gltf.size()}, {"path", "s.gltf"}, {"sha256", service::hexOf(service::sha256(gltf))}}});
  const std::string manifest = nlohmann::json{{"files", files}, {"format", 1}, {"lighting", nlohmann::json::object()},
                                              {"scene", {{"gltf", "s.gltf"}}}}.dump();
  service::ScenePackage p;
  std::string error;
  if (!service::parseManifest(manifest, p, error)) std::fprintf(stderr, "seed manifest: %s\n", error.c_str());
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: client_fuzz_seeds OUTDIR\n");
    return 2;
  }
  std::string gltf, bin;
  const service::ScenePackage package = samplePackage(gltf, bin);
  int k = 0;
  for (Representation repr : kAllRepresentations)
    for (bool withScene : {false, true}) {
      const StreamLayout layout = fuzz::fuzzLayout(repr);
      v1::ServerMessage description;
      v1::VolumeDescription& v = *description.mutable_volume();
      v.set_protocol_version(4);
      v.set_codec_format_version(kFormatVersion);
      v.set_grid_x(layout.grid[0]);
      v.set_grid_y(layout.grid[1]);
      v.set_grid_z(layout.grid[2]);
      v.set_brick_size(layout.brickDim);
      v.set_representation(static_cast<v1::Representation>(repr));
      for (float x : {-1.0f, 0.0f, -1.0f}) v.add_bounds_min(x);
      for (float x : {1.0f, 0.5f, 1.0f}) v.add_bounds_max(x);
      v.set_stream_epoch(7);
      if (withScene) {
        v.set_scene_hash(reinterpret_cast<const char*>(package.hash.data()), package.hash.size());
        v.set_scene_manifest(package.manifest);
      }
      std::vector<uint8_t> keyframe, delta;
      fuzz::baseFrames(repr, keyframe, delta);
      std::string input;
      fuzz::appendRecord(input, fuzz::kServerMessage, description.SerializeAsString());
      for (const auto* payload : {&keyframe, &delta}) {
        v1::ServerMessage frame;
        frame.mutable_frame()->set_payload(payload->data(), payload->size());
        FrameHeader header;
        if (readFrameHeader(payload->data(), payload->size(), &header) == CodecStatus::Ok)
          (payload == &keyframe ? frame.mutable_frame()->set_keyframes(header.sectionCount)
                                : frame.mutable_frame()->set_deltas(header.sectionCount));
        frame.mutable_frame()->mutable_scene_state()->set_time_s(0.25);
        fuzz::appendRecord(input, fuzz::kServerMessage, frame.SerializeAsString());
      }
      if (withScene)
        for (const auto& [path, bytes] : {std::pair<std::string, std::string>{"s.gltf", gltf}, {"b.bin", bin}}) {
          v1::SceneChunk c;
          c.set_path(path);
          c.set_data(bytes);
          fuzz::appendRecord(input, fuzz::kSceneChunk, c.SerializeAsString());
        }
      std::ofstream(std::string(argv[1]) + "/client-" + std::to_string(k++), std::ios::binary) << input;
    }
  return 0;
}
