// Scene identity and delivery: package hashes (stable, and changed by any byte), glTF files found
// and unsafe ones refused, manifests checked, the on-disk cache, GetScene over real gRPC (auth,
// limits, pieces, reuse), and the scene state and clock a viewer receives with every frame.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "probecast/service/scene_package.h"
#include "service_test_support.h"

namespace probecast::service {
namespace {

namespace fs = std::filesystem;
namespace pb = probecast::v1;

fs::path freshDir(const std::string& name) {
  const fs::path dir = fs::path(PROBECAST_TEST_TMP) / "scene_delivery" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void writeBytes(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

// A glTF naming a buffer and two images (one with a space, percent-encoded), plus a data: URI.
fs::path writeScene(const fs::path& dir) {
  writeBytes(dir / "room.gltf",
             R"({"asset":{"version":"2.0"},"buffers":[{"uri":"room.bin","byteLength":16},)"
             R"({"uri":"data:application/octet-stream;base64,AAAA","byteLength":3}],)"
             R"("images":[{"uri":"textures/wall%20a.png"},{"uri":"textures/floor.png"}]})");
  writeBytes(dir / "room.bin", std::string(16, '\x01'));
  writeBytes(dir / "textures" / "wall a.png", "wall pixels");
  writeBytes(dir / "textures" / "floor.png", "floor pixels");
  return dir / "room.gltf";
}

ScenePackage packageOf(const fs::path& gltf, const LightingRequest& lighting = {}) {
  ScenePackage p;
  std::string error;
  EXPECT_TRUE(makeScenePackage(gltf.string(), lighting, p, error)) << error;
  return p;
}

TEST(ScenePackage, HashIsStableAndEveryByteOfEveryFileCounts) {
  const fs::path gltf = writeScene(freshDir("stable"));
  const ScenePackage a = packageOf(gltf), b = packageOf(gltf);
  EXPECT_EQ(a.hash, b.hash);
  EXPECT_EQ(a.manifest, b.manifest);
  EXPECT_EQ(a.hash, sha256(a.manifest));
  ASSERT_EQ(a.files.size(), 4u);  // the glTF, its buffer and its two images; the data: URI stays inside
  EXPECT_EQ(a.files[0].path, "room.gltf");
  EXPECT_EQ(a.files[1].path, "room.bin");
  EXPECT_EQ(a.files[2].path, "textures/wall a.png");
  EXPECT_EQ(a.totalBytes(), fs::file_size(gltf) + 16 + 11 + 12);

  // One changed byte of the buffer changes the package and the scene hash.
  std::string bin(16, '\x01');
  bin[9] = '\x02';
  writeBytes(gltf.parent_path() / "room.bin", bin);
  const ScenePackage changed = packageOf(gltf);
  EXPECT_NE(changed.hash, a.hash);
  EXPECT_NE(changed.sceneHash(), a.sceneHash());

  // Lighting is part of the package, not of the scene.
  LightingRequest sky;
  sky.sky = {0.5f, 0.5f, 0.5f};
  const ScenePackage lit = packageOf(gltf, sky);
  EXPECT_NE(lit.hash, changed.hash);
  EXPECT_EQ(lit.sceneHash(), changed.sceneHash());
  EXPECT_EQ(lit.lighting.kind, SceneLighting::Kind::Sky);

  // Built-ins are named by name; another built-in is another scene.
  ScenePackage c1, c2, hall;
  std::string error;
  ASSERT_TRUE(makeScenePackage("builtin:cornell", {}, c1, error)) << error;
  ASSERT_TRUE(makeScenePackage("builtin:cornell", {}, c2, error)) << error;
  ASSERT_TRUE(makeScenePackage("builtin:hall", {}, hall, error)) << error;
  EXPECT_EQ(c1.hash, c2.hash);
  EXPECT_NE(c1.hash, hall.hash);
  EXPECT_TRUE(c1.files.empty());
  EXPECT_EQ(c1.localSceneSpec(), "builtin:cornell");
}

TEST(ScenePackage, EnvironmentMapsTravelWithTheirParameters) {
  const fs::path dir = freshDir("environment");
  const fs::path gltf = writeScene(dir);
  writeBytes(dir / "maps" / "sky.hdr", "radiance");
  LightingRequest env;
  env.environmentFile = dir / "maps" / "sky.hdr";
  env.intensity = 2.0f;
  env.rotationDeg = 90.0f;
  const ScenePackage p = packageOf(gltf, env);
  EXPECT_EQ(p.lighting.file, "environment/sky.hdr");
  EXPECT_EQ(p.localEnvironmentFile(), dir / "maps" / "sky.hdr");
  ScenePackage back;
  std::string error;
  ASSERT_TRUE(parseManifest(p.manifest, back, error)) << error;
  EXPECT_EQ(back.lighting, p.lighting);
  EXPECT_EQ(back.hash, p.hash);
  env.rotationDeg = 91.0f;
  EXPECT_NE(packageOf(gltf, env).hash, p.hash);
}

TEST(ScenePackage, FilesOutsideTheFolderMissingFilesAndNonGltfAreRefused) {
  const fs::path dir = freshDir("refused");
  const auto refusal = [&](const std::string& json) {
    writeBytes(dir / "s.gltf", json);
    ScenePackage p;
    std::string error;
    EXPECT_FALSE(makeScenePackage((dir / "s.gltf").string(), {}, p, error));
    return error;
  };
  EXPECT_NE(refusal(R"({"buffers":[{"uri":"../secret.bin"}]})").find("leaves the glTF's folder"), std::string::npos);
  EXPECT_NE(refusal(R"({"images":[{"uri":"/etc/passwd"}]})").find("leaves the glTF's folder"), std::string::npos);
  EXPECT_NE(refusal(R"({"images":[{"uri":"a/%2e%2e/../b.png"}]})").find("leaves the glTF's folder"), std::string::npos);
  EXPECT_NE(refusal(R"({"images":[{"uri":"bad%zz.png"}]})").find("malformed uri"), std::string::npos);
  EXPECT_NE(refusal(R"({"buffers":[{"uri":"missing.bin"}]})").find("missing.bin: cannot open"), std::string::npos);
  EXPECT_NE(refusal(R"({"buffers":{"uri":"x.bin"}})").find("'buffers' is not an array"), std::string::npos);
  EXPECT_NE(refusal("not json at all").find("not glTF JSON"), std::string::npos);
  ScenePackage p;
  std::string error;
  EXPECT_FALSE(makeScenePackage((dir / "none.gltf").string(), {}, p, error));
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
}

TEST(ScenePackage, ManifestsAreCheckedBeforeAnythingIsTrusted) {
  const std::string hash(64, 'a');
  const auto refusal = [](const std::string& text) {
    ScenePackage p;
    std::string error;
    EXPECT_FALSE(parseManifest(text, p, error)) << text;
    return error;
  };
  const std::string file = R"({"bytes":1,"path":"PATH","sha256":")" + hash + R"("})";
  const auto withFile = [&](const std::string& path, const std::string& scene) {
    std::string f = file;
    f.replace(f.find("PATH"), 4, path);
    return R"({"files":[)" + f + R"(],"format":1,"lighting":{},"scene":{"gltf":")" + scene + R"("}})";
  };
  EXPECT_NE(refusal(withFile("../a.gltf", "../a.gltf")).find("unsafe path"), std::string::npos);
  EXPECT_NE(refusal(withFile("a//b.gltf", "a//b.gltf")).find("unsafe path"), std::string::npos);
  EXPECT_NE(refusal(withFile("a.gltf", "b.gltf")).find("not among its files"), std::string::npos);
  EXPECT_NE(refusal(R"({"files":[],"format":2,"lighting":{},"scene":{"builtin":"cornell"}})").find("format"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"files":[],"format":1,"lighting":{},"scene":{"builtin":"cornell"},"x":1})")
                .find("exactly files, format, lighting and scene"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"files":[],"format":1,"lighting":{"sky":[1,-1,1]},"scene":{"builtin":"cornell"}})")
                .find("sky"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"files":[],"format":1,"lighting":{"environment":{"file":"e.hdr","intensity":1,)"
                    R"("rotation_deg":0}},"scene":{"builtin":"cornell"}})")
                .find("not among its files"),
            std::string::npos);
  EXPECT_NE(refusal(std::string(kMaxManifestBytes + 1, ' ')).find("at most"), std::string::npos);
  EXPECT_NE(refusal("[1,2]").find("not a JSON object"), std::string::npos);
  std::string twice = withFile("a.gltf", "a.gltf");
  twice.insert(twice.find("]"), "," + file.substr(0, file.find("PATH")) + "a.gltf" + file.substr(file.find("PATH") + 4));
  EXPECT_NE(refusal(twice).find("twice"), std::string::npos) << twice;
}

TEST(ScenePackage, ManifestsAreCanonicalAndTheirSizesCannotWrap) {
  const std::string hash(64, 'a');
  const auto manifest = [&](const std::vector<std::pair<std::string, std::string>>& files) {
    std::string f;
    for (const auto& [path, bytes] : files)
      f += std::string(f.empty() ? "" : ",") + R"({"bytes":)" + bytes + R"(,"path":")" + path + R"(","sha256":")" + hash + R"("})";
    return R"({"files":[)" + f + R"(],"format":1,"lighting":{},"scene":{"gltf":"s.gltf"}})";
  };
  ScenePackage p;
  std::string error;
  // 7630 + (2^64 - 1) + 2 wraps to 7631 in 64 bits.
  EXPECT_FALSE(parseManifest(manifest({{"a.bin", "18446744073709551615"}, {"b.bin", "2"}, {"s.gltf", "7630"}}), p, error));
  EXPECT_NE(error.find("add up to more than 1099511627776 bytes"), std::string::npos) << error;
  EXPECT_FALSE(parseManifest(manifest({{"a.bin", "1099511627000"}, {"s.gltf", "1000"}}), p, error));
  EXPECT_NE(error.find("add up to more than"), std::string::npos) << error;
  const std::string good = manifest({{"a.bin", "1099511627000"}, {"s.gltf", "776"}});  // exactly 1 TiB
  ASSERT_TRUE(parseManifest(good, p, error)) << error;
  EXPECT_EQ(p.totalBytes(), kMaxPackageBytes);
  // The same package spelled otherwise: whitespace, keys out of order, a key twice.
  const std::vector<std::string> others = {
      std::string(" ") + good, good.substr(0, good.size() - 1) + " }",
      R"({"format":1,"files":[],"lighting":{},"scene":{"builtin":"cornell"}})",
      R"({"files":[],"format":1,"format":1,"lighting":{},"scene":{"builtin":"cornell"}})"};
  for (const std::string& other : others) {
    EXPECT_FALSE(parseManifest(other, p, error)) << other;
    EXPECT_NE(error.find("not canonical"), std::string::npos) << error;
  }
  EXPECT_FALSE(parseManifest("{\"files\":[],\"format\":1,\"lighting\":{},\"scene\":{\"builtin\":\"\xff\xfe\"}}", p, error));
  EXPECT_NE(error.find("UTF-8"), std::string::npos) << error;
  EXPECT_FALSE(parseManifest(R"({"files":[],"format":1,"lighting":{},"scene":{"builtin":"\u001b[2J"}})", p, error));
  EXPECT_NE(error.find("is not a name"), std::string::npos) << error;
  EXPECT_EQ(error.find('\x1b'), std::string::npos) << error;
}

TEST(ScenePackage, WireTextIsPrintedWithoutEscapeSequences) {
  EXPECT_EQ(printableText("plain text, ünïcode ✓"), "plain text, ünïcode ✓");
  EXPECT_EQ(printableText("\x1b[2J\x07"), "\\x1b[2J\\x07");
  EXPECT_EQ(printableText("a\xc2\x9b" "31m"), "a\\xc2\\x9b31m");  // C1 control: CSI
  EXPECT_EQ(printableText("\xff\xc3"), "\\xff\\xc3");              // not UTF-8, cut short
  EXPECT_EQ(printableText("\xed\xa0\x80"), "\\xed\\xa0\\x80");    // a surrogate
  EXPECT_EQ(printableText(std::string(1000, 'a'), 10), "aaaaaaaaaa... (cut)");
}

TEST(ScenePackage, ACachedPackageReachedThroughALinkIsNotUsed) {
  const fs::path src = freshDir("link-source"), cache = freshDir("link-cache");
  const ScenePackage p = packageOf(writeScene(src));
  const fs::path files = cache / hexOf(p.hash) / "files";
  for (const PackageFile& f : p.files) writeBytes(files / f.path, std::string(f.bytes, 'x'));
  writeBytes(cache / hexOf(p.hash) / "manifest.json", p.manifest);
  ScenePackage out;
  ASSERT_TRUE(findCachedPackage(cache, p.hash, out));  // sizes match: whole (hashes are checked on arrival)
  fs::remove(files / "room.bin");
  writeBytes(src / "outside.bin", std::string(16, 'y'));
  fs::create_symlink(src / "outside.bin", files / "room.bin");
  EXPECT_FALSE(findCachedPackage(cache, p.hash, out));
  fs::remove(files / "room.bin");
  writeBytes(files / "room.bin", std::string(16, 'x'));
  fs::rename(files / "textures", cache / "textures");
  fs::create_directory_symlink(cache / "textures", files / "textures");
  EXPECT_FALSE(findCachedPackage(cache, p.hash, out));
}

TEST(ScenePackage, TheCacheHoldsOnlyWholeCheckedPackages) {
  const fs::path src = freshDir("cache-source"), cache = freshDir("cache");
  const ScenePackage p = packageOf(writeScene(src));
  ScenePackage named, out;
  std::string error;
  ASSERT_TRUE(parseManifest(p.manifest, named, error)) << error;
  const auto feed = [&](PackageWriter& w, bool corrupt) {
    for (const PackageFile& f : p.files) {
      std::ifstream in(f.source, std::ios::binary);
      std::string bytes((std::istreambuf_iterator<char>(in)), {});
      if (corrupt && f.path == "room.bin") bytes[3] ^= 1;
      for (size_t at = 0; at < bytes.size(); at += 5)  // in pieces
        ASSERT_TRUE(w.write(f.path, at, std::string_view(bytes).substr(at, 5), error)) << error;
    }
  };
  {
    PackageWriter w(cache, named);
    ASSERT_TRUE(w.begin(error)) << error;
    feed(w, true);
    EXPECT_FALSE(w.finish(out, error));
    EXPECT_NE(error.find("room.bin arrived"), std::string::npos) << error;
  }
  EXPECT_FALSE(findCachedPackage(cache, p.hash, out));
  EXPECT_TRUE(fs::is_empty(cache));  // the partial package went with its writer
  {
    PackageWriter w(cache, named);
    ASSERT_TRUE(w.begin(error)) << error;
    EXPECT_FALSE(w.write("room.bin", 3, "x", error));  // not where the file stands
    EXPECT_NE(error.find("does not follow"), std::string::npos) << error;
    EXPECT_FALSE(w.write("other.bin", 0, "x", error));
    EXPECT_NE(error.find("does not name"), std::string::npos) << error;
    feed(w, false);
    ASSERT_TRUE(w.finish(out, error)) << error;
  }
  ScenePackage cached;
  ASSERT_TRUE(findCachedPackage(cache, p.hash, cached));
  EXPECT_EQ(cached.hash, p.hash);
  EXPECT_EQ(cached.localSceneSpec(), (cache / hexOf(p.hash) / "files" / "room.gltf").string());
  // A file cut short in the cache is not a cached package.
  fs::resize_file(cache / hexOf(p.hash) / "files" / "room.bin", 4);
  EXPECT_FALSE(findCachedPackage(cache, p.hash, cached));
}

struct SceneServer {
  ProbeHub hub{volumeConfig()};
  std::unique_ptr<ProbeServer> server;
  std::shared_ptr<const ScenePackage> package;
  explicit SceneServer(const ScenePackage& p) : package(std::make_shared<const ScenePackage>(p)) {
    SceneStamp stamp;
    stamp.hash = p.hash;
    stamp.manifest = p.manifest;
    hub.setScene(stamp);
    ServerConfig sc;
    sc.token = kToken;
    sc.plaintext = true;
    sc.scene = package;
    server = std::make_unique<ProbeServer>(sc, hub);
  }
  ClientConfig client(const std::string& token = kToken) const {
    ClientConfig cc;
    cc.address = "127.0.0.1:" + std::to_string(server->port());
    cc.token = token;
    return cc;
  }
};

TEST(SceneDelivery, GetSceneDeliversEveryFileOnceAndTheCacheServesItAfterwards) {
  const ScenePackage p = packageOf(writeScene(freshDir("deliver-source")));
  const fs::path cache = freshDir("deliver-cache");
  SceneServer s(p);
  SceneStamp stamp;
  stamp.hash = p.hash;
  stamp.manifest = p.manifest;
  ScenePackage got;
  SceneFetch fetch;
  std::string error;
  ASSERT_TRUE(fetchScene(s.client(), stamp, cache, 1 << 20, got, fetch, error)) << error;
  EXPECT_FALSE(fetch.fromCache);
  EXPECT_EQ(fetch.bytes, p.totalBytes());
  EXPECT_EQ(got.hash, p.hash);
  for (size_t i = 0; i < p.files.size(); ++i) {
    std::ifstream a(p.files[i].source, std::ios::binary), b(got.files[i].source, std::ios::binary);
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(a)), {}), std::string((std::istreambuf_iterator<char>(b)), {}))
        << p.files[i].path;
  }
  ASSERT_TRUE(fetchScene(s.client(), stamp, cache, 1 << 20, got, fetch, error)) << error;
  EXPECT_TRUE(fetch.fromCache);
  EXPECT_EQ(fetch.bytes, 0u);
}

TEST(SceneDelivery, GetSceneRefusesStrangersOversizedAsksAndUnknownScenes) {
  const ScenePackage p = packageOf(writeScene(freshDir("refuse-source")));
  const fs::path cache = freshDir("refuse-cache");
  SceneServer s(p);
  SceneStamp stamp;
  stamp.hash = p.hash;
  stamp.manifest = p.manifest;
  ScenePackage got;
  SceneFetch fetch;
  std::string error;
  EXPECT_FALSE(fetchScene(s.client("wrong"), stamp, cache, 1 << 20, got, fetch, error));
  EXPECT_NE(error.find("missing or wrong bearer token"), std::string::npos) << error;
  EXPECT_FALSE(fetchScene(s.client(), stamp, cache, p.totalBytes() - 1, got, fetch, error));
  EXPECT_NE(error.find("more than the " + std::to_string(p.totalBytes() - 1) + " this viewer accepts"),
            std::string::npos)
      << error;
  EXPECT_TRUE(fs::is_empty(cache));

  auto stub = pb::ProbeStream::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(s.server->port()), grpc::InsecureChannelCredentials()));
  const auto call = [&](const std::string& hash, uint32_t chunk, int* pieces = nullptr) {
    grpc::ClientContext ctx;
    ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
    pb::GetSceneRequest request;
    request.set_scene_hash(hash);
    request.set_chunk_bytes(chunk);
    auto reader = stub->GetScene(&ctx, request);
    pb::SceneChunk c;
    int n = 0;
    while (reader->Read(&c)) ++n;
    if (pieces) *pieces = n;
    return reader->Finish();
  };
  const std::string good(reinterpret_cast<const char*>(p.hash.data()), 32);
  EXPECT_EQ(call(good.substr(0, 31), 0).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  const grpc::Status big = call(good, 5u << 20);
  EXPECT_EQ(big.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(big.error_message().find("above the limit of 4 MiB"), std::string::npos) << big.error_message();
  EXPECT_EQ(call(std::string(32, 'x'), 0).error_code(), grpc::StatusCode::NOT_FOUND);
  int pieces = 0;
  ASSERT_TRUE(call(good, 4, &pieces).ok());
  uint64_t expected = 1;  // the manifest, then every file in pieces of 4 bytes
  for (const PackageFile& f : p.files) expected += (f.bytes + 3) / 4;
  EXPECT_EQ(static_cast<uint64_t>(pieces), expected);
}

TEST(SceneDelivery, AServerWithoutTheScenesFilesSaysSo) {
  ProbeHub hub(volumeConfig());
  ServerConfig sc;
  sc.token = kToken;
  sc.plaintext = true;
  ProbeServer server(sc, hub);
  const ScenePackage p = packageOf(writeScene(freshDir("nofiles-source")));
  SceneStamp stamp;
  stamp.hash = p.hash;
  stamp.manifest = p.manifest;
  ClientConfig cc;
  cc.address = "127.0.0.1:" + std::to_string(server.port());
  cc.token = kToken;
  ScenePackage got;
  SceneFetch fetch;
  std::string error;
  EXPECT_FALSE(fetchScene(cc, stamp, freshDir("nofiles-cache"), 1 << 20, got, fetch, error));
  EXPECT_NE(error.find("no scene to deliver"), std::string::npos) << error;
}

// An edge that has just started names its producer's scene before it holds the files: it answers
// UNAVAILABLE with a time to ask again, and fetchScene waits and asks again (a scene nobody
// names is still NOT_FOUND, as above).
TEST(SceneDelivery, AServerStillGettingTheSceneItNamesIsAskedAgain) {
  const ScenePackage p = packageOf(writeScene(freshDir("later-source")));
  SceneServer s(p);
  s.server->setScene(nullptr);
  SceneStamp stamp;
  stamp.hash = p.hash;
  stamp.manifest = p.manifest;
  auto stub = pb::ProbeStream::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(s.server->port()), grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  pb::GetSceneRequest request;
  request.set_scene_hash(reinterpret_cast<const char*>(p.hash.data()), 32);
  auto reader = stub->GetScene(&ctx, request);
  pb::SceneChunk chunk;
  EXPECT_FALSE(reader->Read(&chunk));
  const grpc::Status st = reader->Finish();
  EXPECT_EQ(st.error_code(), grpc::StatusCode::UNAVAILABLE) << st.error_message();
  EXPECT_NE(st.error_message().find("still getting the files"), std::string::npos) << st.error_message();
  EXPECT_EQ(ctx.GetServerTrailingMetadata().count(kSceneRetryMetadata), 1u);

  std::thread later([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(600));
    s.server->setScene(s.package);
  });
  ScenePackage got;
  SceneFetch fetch;
  std::string error;
  const bool fetched = fetchScene(s.client(), stamp, freshDir("later-cache"), 1 << 20, got, fetch, error);
  later.join();
  ASSERT_TRUE(fetched) << error;
  EXPECT_EQ(got.hash, p.hash);
  EXPECT_GE(fetch.ms, 500.0);  // it waited for the files
}

bus::SceneState playingState() {
  bus::SceneState st;
  st.time = 3.25;
  st.rate = 0.5;
  st.clockUs = wallClockUs();
  bus::LightState l;
  l.position[1] = 1.8f;
  l.intensity = 12.0f;
  st.lights = {l};
  return st;
}

TEST(SceneDelivery, EveryFrameCarriesTheSceneStateAndTheClientLocksItsClock) {
  ScenePackage p;
  std::string error;
  ASSERT_TRUE(makeScenePackage("builtin:cornell", {}, p, error)) << error;
  SceneServer s(p);
  SceneStamp described;
  ASSERT_TRUE(describeScene(s.client(), described, error)) << error;
  EXPECT_EQ(described.hash, p.hash);
  EXPECT_EQ(described.manifest, p.manifest);

  const bus::SceneState st = playingState();
  s.hub.setSceneState(st);
  std::mt19937 rng(1);
  s.hub.publish(test::movingLightFrame(1024, 0, 0.01f, rng).data(), nullptr);
  ProbeClient client(s.client());
  client.start();
  VolumeSnapshot snap;
  ASSERT_TRUE(waitFor([&] { return client.snapshot(snap) && snap.hasState; }, 5s)) << client.stats().lastError;
  EXPECT_EQ(snap.state, st);
  EXPECT_EQ(snap.volume.scene.hash, p.hash);
  EXPECT_EQ(snap.volume.scene.time, 3.25);
  EXPECT_LT(std::abs(snap.clockOffsetUs), 1'000'000);  // one machine: the offset is the delivery delay
  // The server's scene time moves on at the state's rate from its clock.
  const double now = serverSceneTime(snap, st.clockUs + static_cast<uint64_t>(snap.clockOffsetUs) + 2'000'000);
  EXPECT_NEAR(now, 3.25 + 0.5 * 2.0, 1e-9);

  // A state the server may not send is refused by the hub, not passed on.
  bus::SceneState bad = st;
  bad.lights[0].direction[0] = 1.0f;  // (1, -1, 0): not unit length
  EXPECT_THROW(s.hub.setSceneState(bad), std::invalid_argument);
  client.stop();
}

TEST(DisplayClock, FollowsTheServerHoldsSmallStepsBackAndRewindsLargeOnes) {
  VolumeSnapshot s;
  s.hasState = true;
  s.state.time = 10.0;
  s.state.rate = 0.5;
  s.state.clockUs = 1'000'000'000;
  s.clockOffsetUs = 2'000;  // our clock is 2 ms ahead of the server's
  DisplayClock clock;
  EXPECT_NEAR(clock.at(s, 1'000'002'000), 10.0, 1e-9);
  EXPECT_NEAR(clock.at(s, 1'001'002'000), 10.5, 1e-9);  // one second later
  EXPECT_NEAR(clock.probeAge(), 0.5, 1e-9);
  // A better offset estimate that would step back 0.1 s of playback: held, never backwards.
  s.clockOffsetUs = 202'000;
  EXPECT_NEAR(clock.at(s, 1'001'002'000), 10.5, 1e-9);
  EXPECT_NEAR(clock.at(s, 1'001'402'000), 10.6, 1e-9);  // caught up: followed again
  // The stream restarted at an earlier time (more than a second of playback back): rewound.
  s.state.time = 2.0;
  s.state.clockUs = 1'001'200'000;
  EXPECT_NEAR(clock.at(s, 1'001'402'000), 2.0, 1e-9);
  // A still stream: its time, however the clocks stand.
  s.state.rate = 0.0;
  s.state.time = 0.75;
  EXPECT_NEAR(clock.at(s, 9'000'000'000), 0.75, 1e-9);
  // Stalled: no new frames, the estimate runs on at the last rate and the probes age.
  s.state = {4.0, 1.0, 1'000'000'000, {}};
  s.clockOffsetUs = 0;
  EXPECT_NEAR(clock.at(s, 1'003'000'000), 7.0, 1e-9);
  EXPECT_NEAR(clock.probeAge(), 3.0, 1e-9);
}

}  // namespace
}  // namespace probecast::service
