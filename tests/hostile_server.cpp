// A hostile ProbeStream server for the viewer's trust tests: it relays a real `probecast serve`
// (GetVolume, Subscribe) and attacks in one way, chosen by name. Scene attacks serve a package of
// their own (a one-triangle glTF whose files are hashed correctly, so only the viewer's own rules
// can refuse it); stream attacks rewrite the relayed descriptions and frames.
//
//   probecast_hostile_server UPSTREAM LISTEN TOKEN ATTACK DECOY_DIR
//
// DECOY_DIR receives decoy.bin and decoy.png: files outside any scene cache that a viewer that
// obeyed the package would read (the test checks that it never opens them). The server prints
// "hostile: listening" once it serves and runs until killed.
#include <grpcpp/grpcpp.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "gltf_test_files.h"
#include "probecast.grpc.pb.h"
#include "probecast/service/scene_package.h"

namespace {

namespace pb = probecast::v1;
namespace fs = std::filesystem;
using nlohmann::json;
using probecast::service::hexOf;
using probecast::service::sha256;

// One triangle's positions (three vec3), the buffer a decoy stands in for.
std::string triangleBuffer() {
  const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  return std::string(reinterpret_cast<const char*>(p), sizeof p);
}

// A glTF drawing one triangle from `bufferUri`, textured by `imageUri` when it is not empty.
std::string triangleGltf(const std::string& bufferUri, const std::string& imageUri) {
  json g = {{"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", {{{"nodes", {0}}}}},
            {"nodes", {{{"mesh", 0}}}},
            {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"material", 0}}}}}}},
            {"materials", {{{"pbrMetallicRoughness", json::object()}}}},
            {"buffers", {{{"uri", bufferUri}, {"byteLength", 36}}}},
            {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
            {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"},
                            {"min", {0, 0, 0}}, {"max", {1, 1, 0}}}}}};
  if (!imageUri.empty()) {
    g["images"] = {{{"uri", imageUri}}};
    g["textures"] = {{{"source", 0}}};
    g["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  }
  return g.dump();
}

struct Package {
  std::map<std::string, std::string> files;  // path → bytes
  std::string manifest;
  std::string hash;  // 32 bytes
};

// A canonical manifest of `files` with the glTF `scene`, each file's size `sizes` when given.
Package makePackage(std::map<std::string, std::string> files, const std::string& scene,
                    const std::map<std::string, uint64_t>& sizes = {}) {
  Package p;
  p.files = std::move(files);
  json list = json::array();
  for (const auto& [path, bytes] : p.files) {
    const auto size = sizes.count(path) ? sizes.at(path) : bytes.size();
    list.push_back({{"bytes", size}, {"path", path}, {"sha256", hexOf(sha256(bytes))}});
  }
  p.manifest = json{{"files", list}, {"format", 1}, {"lighting", json::object()}, {"scene", {{"gltf", scene}}}}.dump();
  const auto h = sha256(p.manifest);
  p.hash.assign(reinterpret_cast<const char*>(h.data()), h.size());
  return p;
}

// The package each scene attack serves (none: the upstream's scene is kept).
std::optional<Package> packageFor(const std::string& attack, const fs::path& decoys) {
  const std::string up = [] {
    std::string s;
    for (int i = 0; i < 24; ++i) s += "../";
    return s;
  }();
  const std::string decoyBin = fs::absolute(decoys / "decoy.bin").string();
  const std::string decoyPng = fs::absolute(decoys / "decoy.png").string();
  const std::string bin = triangleBuffer();
  if (attack == "gltf-dotdot") return makePackage({{"scene.gltf", triangleGltf(up + decoyBin.substr(1), "")}}, "scene.gltf");
  if (attack == "gltf-percent") {
    std::string uri;
    for (int i = 0; i < 24; ++i) uri += "%2E%2E/";
    return makePackage({{"scene.gltf", triangleGltf(uri + decoyBin.substr(1), "")}}, "scene.gltf");
  }
  if (attack == "gltf-absolute") return makePackage({{"scene.gltf", triangleGltf(decoyBin, "")}}, "scene.gltf");
  if (attack == "gltf-file-uri") return makePackage({{"scene.gltf", triangleGltf("file://" + decoyBin, "")}}, "scene.gltf");
  // A plain name the package does not hold: found only in the viewer's working folder.
  if (attack == "gltf-unlisted") return makePackage({{"scene.gltf", triangleGltf("decoy.bin", "")}}, "scene.gltf");
  if (attack == "image-dotdot")
    return makePackage({{"scene.gltf", triangleGltf("tri.bin", up + decoyPng.substr(1))}, {"tri.bin", bin}}, "scene.gltf");
  if (attack == "image-unlisted")
    return makePackage({{"scene.gltf", triangleGltf("tri.bin", "decoy.png")}, {"tri.bin", bin}}, "scene.gltf");
  // Sizes that wrap a 64-bit sum: 7630 + (2^64 - 1) + 2.
  if (attack == "size-overflow")
    return makePackage({{"scene.gltf", triangleGltf("a.bin", "")}, {"a.bin", bin}, {"b.bin", bin}}, "scene.gltf",
                       {{"scene.gltf", 7630}, {"a.bin", std::numeric_limits<uint64_t>::max()}, {"b.bin", 2}});
  // The same package with its manifest spelled with whitespace (hashed as sent).
  if (attack == "noncanonical") {
    Package p = makePackage({{"scene.gltf", triangleGltf("tri.bin", "")}, {"tri.bin", bin}}, "scene.gltf");
    p.manifest = json::parse(p.manifest).dump(1);
    const auto h = sha256(p.manifest);
    p.hash.assign(reinterpret_cast<const char*>(h.data()), h.size());
    return p;
  }
  if (attack == "bad-utf8") {
    Package p = makePackage({{"scene.gltf", triangleGltf("tri.bin", "")}, {"tri.bin", bin}}, "scene.gltf");
    p.manifest.insert(p.manifest.find("scene.gltf"), "\xff\xfe");
    const auto h = sha256(p.manifest);
    p.hash.assign(reinterpret_cast<const char*>(h.data()), h.size());
    return p;
  }
  // A well-formed package (GetVolume names it; Subscribe names the upstream's), and one whose
  // transfer stalls after the manifest.
  if (attack == "scene-switch" || attack == "scene-stall")
    return makePackage({{"scene.gltf", triangleGltf("tri.bin", "")}, {"tri.bin", bin}}, "scene.gltf");
  return std::nullopt;
}

void writeDecoys(const fs::path& dir) {
  fs::create_directories(dir);
  std::ofstream(dir / "decoy.bin", std::ios::binary) << triangleBuffer();
  std::ofstream(dir / "decoy.png", std::ios::binary)
      << probecast::test::pngFile(1, 1, 3, 8, std::vector<uint16_t>{255, 0, 255});
}

class Hostile final : public pb::ProbeStream::Service {
 public:
  Hostile(const std::string& upstream, std::string token, std::string attack, std::optional<Package> package)
      : stub_(pb::ProbeStream::NewStub(grpc::CreateChannel(upstream, grpc::InsecureChannelCredentials()))),
        token_(std::move(token)), attack_(std::move(attack)), package_(std::move(package)) {}

  grpc::Status GetVolume(grpc::ServerContext*, const pb::GetVolumeRequest* request, pb::VolumeDescription* out) override {
    grpc::ClientContext up;
    up.AddMetadata("authorization", "Bearer " + token_);
    const grpc::Status status = stub_->GetVolume(&up, *request, out);
    if (status.ok()) describe(*out, /*subscribe=*/false);
    return status;
  }

  grpc::Status Subscribe(grpc::ServerContext* ctx,
                         grpc::ServerReaderWriter<pb::ServerMessage, pb::ClientMessage>* down) override {
    if (attack_ == "escape-text")
      return {grpc::StatusCode::INTERNAL, "upstream failed \x1b]0;owned\x07\x1b[2J\x1b[31m red \x9b" "31m"};
    grpc::ClientContext up;
    up.AddMetadata("authorization", "Bearer " + token_);
    auto stream = stub_->Subscribe(&up);
    std::thread relay([&] {  // the viewer's messages go up unchanged
      pb::ClientMessage m;
      while (down->Read(&m))
        if (!stream->Write(m)) break;
      stream->WritesDone();
    });
    pb::ServerMessage m;
    while (!ctx->IsCancelled() && stream->Read(&m)) {
      if (m.has_volume()) describe(*m.mutable_volume(), /*subscribe=*/true);
      if (m.has_frame()) attackFrame(*m.mutable_frame());
      if (!down->Write(m)) break;
    }
    ctx->TryCancel();  // ends the relay's read
    up.TryCancel();
    relay.join();
    return grpc::Status::OK;
  }

  grpc::Status GetScene(grpc::ServerContext* ctx, const pb::GetSceneRequest* request,
                        grpc::ServerWriter<pb::SceneChunk>* writer) override {
    std::printf("hostile: GetScene asked\n");
    std::fflush(stdout);
    if (!package_ || request->scene_hash() != package_->hash) return {grpc::StatusCode::NOT_FOUND, "no such scene"};
    pb::SceneChunk first;
    first.set_manifest(package_->manifest);
    writer->Write(first);
    if (attack_ == "scene-stall") {  // say nothing more, for as long as the viewer waits
      while (!ctx->IsCancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      return grpc::Status::OK;
    }
    // Every file as the manifest has it. The overflow attack's a.bin (said to hold 2^64 - 1 bytes)
    // goes on with 1 MiB pieces, up to 64 MiB: what a viewer that trusted the sum would write.
    for (const auto& [path, bytes] : package_->files) {
      pb::SceneChunk c;
      c.set_path(path);
      c.set_data(bytes);
      if (!writer->Write(c)) return grpc::Status::OK;
      for (uint64_t offset = bytes.size(); attack_ == "size-overflow" && path == "a.bin" && !ctx->IsCancelled() &&
                                           offset < (uint64_t{64} << 20);
           offset += c.data().size()) {
        c.set_offset(offset);
        c.mutable_data()->assign(1 << 20, 'x');
        if (!writer->Write(c)) return grpc::Status::OK;
      }
    }
    return grpc::Status::OK;
  }

 private:
  // Rewrites a description as the attack asks: a scene package of its own, an absurd grid.
  void describe(pb::VolumeDescription& v, bool subscribe) const {
    if (package_ && !(attack_ == "scene-switch" && subscribe)) {
      v.set_scene_hash(package_->hash);
      v.set_scene_manifest(package_->manifest);
    }
    if (attack_ == "huge-grid") {  // 2^24 probes: the protocol's largest volume
      v.set_grid_x(256);
      v.set_grid_y(256);
      v.set_grid_z(256);
      v.clear_probe_offsets();
    }
  }

  void attackFrame(pb::Frame& f) const {
    if (attack_ == "garbage-frames") f.set_payload(std::string(f.payload().size(), '\x5a'));
    if (attack_ == "huge-frames") f.set_payload(std::string(64 << 20, '\x5a'));
    if (attack_ == "nan-time" && f.has_scene_state()) f.mutable_scene_state()->set_time_s(std::nan(""));
    if (attack_ == "nan-lights" && f.has_scene_state() && f.scene_state().lights_size() > 0)
      f.mutable_scene_state()->mutable_lights(0)->set_intensity(std::numeric_limits<float>::quiet_NaN());
    if (attack_ == "counts") {
      f.set_keyframes(UINT32_MAX);
      f.set_deltas(UINT32_MAX);
    }
  }

  std::unique_ptr<pb::ProbeStream::Stub> stub_;
  std::string token_, attack_;
  std::optional<Package> package_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: %s UPSTREAM LISTEN TOKEN ATTACK DECOY_DIR\n", argv[0]);
    return 2;
  }
  writeDecoys(argv[5]);
  Hostile service(argv[1], argv[3], argv[4], packageFor(argv[4], argv[5]));
  grpc::ServerBuilder builder;
  builder.AddListeningPort(argv[2], grpc::InsecureServerCredentials());
  builder.RegisterService(&service);
  builder.SetMaxSendMessageSize(128 << 20);
  // The viewer's keepalive pings are welcome: a stalled transfer must stall, not end in GOAWAY.
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, 1000);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PING_STRIKES, 0);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server) {
    std::fprintf(stderr, "hostile: cannot listen on %s\n", argv[2]);
    return 1;
  }
  std::printf("hostile: listening on %s, attack %s\n", argv[2], argv[4]);
  std::fflush(stdout);
  server->Wait();
}
