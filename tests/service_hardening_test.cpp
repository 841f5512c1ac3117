// Hostile and absurd input to the service, over real gRPC on 127.0.0.1: bytes that are no message,
// views absurdly far away, a half-closed receive-only subscriber, a budget of 2^64-1, enum and
// integer values out of range in both directions, mandatory authentication, and light-field view
// sets up to the renderer's limit. Every wait is bounded and every test stops its own threads.
#include <gtest/gtest.h>

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <cfloat>
#include <cmath>
#include <functional>
#include <optional>
#include <vector>

#include "probecast.grpc.pb.h"
#include "probecast/codec/priority.h"
#include "service_test_support.h"

namespace probecast::service {
namespace {

namespace pb = probecast::v1;

std::string address(int port) { return "127.0.0.1:" + std::to_string(port); }

std::unique_ptr<pb::ProbeStream::Stub> stubFor(int port) {
  return pb::ProbeStream::NewStub(grpc::CreateChannel(address(port), grpc::InsecureChannelCredentials()));
}

pb::ClientMessage helloMessage() {
  pb::ClientMessage m;
  m.mutable_hello()->set_protocol_version(4);
  return m;
}

// Opens Subscribe as raw bytes (the generic stub: nothing parses or checks what is sent), writes
// `messages`, reads until the server ends the stream and returns its status.
grpc::Status rawSubscribe(int port, const std::vector<std::string>& messages,
                          std::chrono::milliseconds deadline = 5s) {
  grpc::GenericStub stub(grpc::CreateChannel(address(port), grpc::InsecureChannelCredentials()));
  grpc::CompletionQueue cq;
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  ctx.set_deadline(std::chrono::system_clock::now() + deadline);
  std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call =
      stub.PrepareCall(&ctx, "/probecast.v1.ProbeStream/Subscribe", &cq);
  auto next = [&cq] {  // one operation at a time: its tag needs no checking
    void* tag = nullptr;
    bool ok = false;
    return cq.Next(&tag, &ok) && ok;
  };
  call->StartCall(nullptr);
  next();
  for (const std::string& m : messages) {
    grpc::Slice slice(m);
    grpc::ByteBuffer buffer(&slice, 1);
    call->Write(buffer, nullptr);
    if (!next()) break;
  }
  grpc::ByteBuffer in;
  do call->Read(&in, nullptr);
  while (next());
  grpc::Status status;
  call->Finish(&status, nullptr);
  next();
  cq.Shutdown();
  void* tag;
  bool ok;
  while (cq.Next(&tag, &ok)) {
  }
  return status;
}

// One request of raw bytes to `method` (unary or server-streaming: the server's status either way).
grpc::Status rawRequest(int port, const std::string& method, const std::string& bytes) {
  grpc::GenericStub stub(grpc::CreateChannel(address(port), grpc::InsecureChannelCredentials()));
  grpc::CompletionQueue cq;
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  ctx.set_deadline(std::chrono::system_clock::now() + 5s);
  grpc::Slice slice(bytes);
  const grpc::ByteBuffer request(&slice, 1);
  std::unique_ptr<grpc::GenericClientAsyncResponseReader> call = stub.PrepareUnaryCall(&ctx, method, request, &cq);
  call->StartCall();
  grpc::ByteBuffer response;
  grpc::Status status;
  call->Finish(&response, &status, nullptr);
  void* tag = nullptr;
  bool ok = false;
  cq.Next(&tag, &ok);
  cq.Shutdown();
  while (cq.Next(&tag, &ok)) {
  }
  return status;
}

// A view like viewAt's looking down −z from an eye at `eye` (finite, however far).
View viewFrom(double x, double y, double z) {
  View v{};
  v.viewProj[0] = 1.0f;
  v.viewProj[5] = 1.0f;
  v.viewProj[10] = -1.0f / 40.0f;
  v.viewProj[12] = static_cast<float>(-x);
  v.viewProj[13] = static_cast<float>(-y);
  v.viewProj[14] = static_cast<float>(z / 40.0);
  v.viewProj[15] = 1.0f;
  v.eye[0] = static_cast<float>(x);
  v.eye[1] = static_cast<float>(y);
  v.eye[2] = static_cast<float>(z);
  return v;
}

// An N×M light field's eyes on a 5 cm grid in front of the volume.
std::vector<View> lightField(int columns, int rows) {
  std::vector<View> views;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) views.push_back(viewFrom(-0.25 + 0.05 * c, 0.5 + 0.05 * r, 20.0));
  return views;
}

// Bytes that are no GetVolumeRequest or GetSceneRequest: INVALID_ARGUMENT naming the message
// (gRPC's typed handlers answered UNIMPLEMENTED, as if the method did not exist).
TEST(ServiceHardening, UnparsableVolumeAndSceneRequestsAreInvalidArgument) {
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  const std::string truncated("\x0a\x05" "ab", 4);  // field 1 claims 5 bytes, 2 follow
  for (const char* name : {"GetVolume", "GetScene"}) {
    const grpc::Status st = rawRequest(server.port(), std::string("/probecast.v1.ProbeStream/") + name, truncated);
    EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << name << ": " << st.error_message();
    EXPECT_NE(st.error_message().find(std::string("not a valid probecast.v1.") + name + "Request"), std::string::npos)
        << st.error_message();
  }
  // A well-formed empty GetVolumeRequest still gets past parsing (here: no volume yet, or the volume).
  EXPECT_NE(rawRequest(server.port(), "/probecast.v1.ProbeStream/GetVolume", "").error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

// Defect 1: bytes that are no ClientMessage used to end the stream with OK, unlogged.
TEST(ServiceHardening, UnparsableMessageIsInvalidArgumentAndLogged) {
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  const std::string truncated("\x0a\x05" "ab", 4);  // field 1 claims 5 bytes, 2 follow
  testing::internal::CaptureStderr();
  const grpc::Status first = rawSubscribe(server.port(), {truncated});
  const grpc::Status afterHello = rawSubscribe(server.port(), {helloMessage().SerializeAsString(), truncated});
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_EQ(first.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << first.error_message();
  EXPECT_NE(first.error_message().find("not a valid probecast.v1.ClientMessage"), std::string::npos);
  EXPECT_EQ(afterHello.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << afterHello.error_message();
  EXPECT_NE(log.find("not a valid probecast.v1.ClientMessage"), std::string::npos) << log;
  // A well-formed raw stream is served as before (it ends at the deadline, still subscribed).
  EXPECT_EQ(rawSubscribe(server.port(), {helloMessage().SerializeAsString()}, 300ms).error_code(),
            grpc::StatusCode::DEADLINE_EXCEEDED);
}

// Defect 2: an eye >= ~2e19 m squared past FLT_MAX, every brick scored 0 and the stream went quiet.
TEST(ServiceHardening, FarViewsScoreFinitePositive) {
  const HubConfig hc = volumeConfig();
  const uint32_t bricks = brickCount(hc.layout);
  std::vector<BrickCandidate> candidates(bricks, BrickCandidate{1.0f, 0, 100});
  candidates[3].ageFrames = 4000000000u;  // the age term at its largest
  candidates[5].change = FLT_MAX;
  const double far[] = {9.46e15, 2e19, 1e30, FLT_MAX};  // a light-year, the old overflow, absurd, the largest float
  for (double d : far)
    for (double sign : {1.0, -1.0}) {
      std::vector<View> views = {viewFrom(sign * d, 0.0, 0.0), viewFrom(0.0, sign * d, sign * d)};
      std::vector<float> scores(bricks);
      scoreBricks(hc.layout, hc.bounds, views, candidates, hc.priority, scores.data());
      for (uint32_t b = 0; b < bricks; ++b) {
        EXPECT_TRUE(std::isfinite(scores[b])) << "eye at " << sign * d << " m, brick " << b;
        EXPECT_GT(scores[b], 0.0f) << "eye at " << sign * d << " m, brick " << b;
      }
    }
  // 1000 km away, distances still order the bricks (0..3 run along x, the eye is far along +x);
  // a light-year away they differ by less than float resolves, and every brick ties.
  std::vector<float> scores(bricks);
  const View farAway = viewFrom(1e6, 0.0, 0.0);
  std::vector<BrickCandidate> same(bricks, BrickCandidate{1.0f, 0, 100});
  scoreBricks(hc.layout, hc.bounds, std::span<const View>(&farAway, 1), same, hc.priority, scores.data());
  EXPECT_GT(scores[3], scores[0]);
}

// Defect 2 over gRPC: a subscriber looking from a light-year and from 1e30 m away converges.
TEST(ServiceHardening, FarViewsStillReceiveEveryBrick) {
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 10, 10ms);
  ProbeClient lightYear(clientFor(server.port()));
  lightYear.setViews({viewFrom(9.46e15, 0.75, 20.0)});
  lightYear.start();
  ProbeClient absurd(clientFor(server.port(), 20000));  // under a budget too
  absurd.setViews({viewFrom(1e30, -1e30, 1e30), viewFrom(-FLT_MAX, FLT_MAX, FLT_MAX)});
  absurd.start();
  ASSERT_TRUE(waitFor([&] { return producer.published() == 10; }, 10s));
  EXPECT_TRUE(waitFor([&] { return matchesServer(lightYear, hub); }, 10s));
  EXPECT_TRUE(waitFor([&] { return matchesServer(absurd, hub); }, 10s));
  EXPECT_FALSE(absurd.stats().fatal) << absurd.stats().lastError;

  // Non-finite views are refused, naming the problem.
  auto stub = stubFor(server.port());
  for (float bad : {INFINITY, -INFINITY, NAN}) {
    pb::ClientMessage views;
    View v = viewFrom(0.0, 0.0, 20.0);
    v.eye[2] = bad;
    pb::View* w = views.mutable_views()->add_views();
    for (float f : v.viewProj) w->add_view_projection(f);
    w->set_eye_z(v.eye[2]);
    const pb::ClientMessage hello = helloMessage();
    const grpc::Status st = statusAfter(*stub, hello, &views);
    EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(st.error_message().find("eye position holds NaN or Inf"), std::string::npos) << st.error_message();
  }
}

// Defect 4: a receive-only viewer half-closes after its hello; its stream used to end after one
// frame. It lasts until the client cancels or the server shuts down.
TEST(ServiceHardening, HalfClosedSubscriberKeepsReceivingAndConverges) {
  ProbeHub hub(volumeConfig());
  auto server = std::make_unique<ProbeServer>(plaintextConfig(), hub);
  auto stub = stubFor(server->port());
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  ctx.set_deadline(std::chrono::system_clock::now() + 15s);
  auto stream = stub->Subscribe(&ctx);
  ASSERT_TRUE(stream->Write(helloMessage()));
  ASSERT_TRUE(stream->WritesDone());
  pb::ServerMessage msg;
  ASSERT_TRUE(stream->Read(&msg));
  ASSERT_TRUE(msg.has_volume());
  // In lockstep: every publish changes every brick, so each brings one frame (unlimited budget).
  StreamDecoder decoder(hub.layout());
  std::mt19937 rng(11);
  uint32_t frames = 0;
  for (int f = 0; f < 20; ++f) {
    hub.publish(test::movingLightFrame(1024, f, 0.01f, rng).data(), nullptr);
    bool gotFrame = false;
    while (!gotFrame && stream->Read(&msg)) {
      if (!msg.has_frame()) continue;  // a Stats message
      const std::string& p = msg.frame().payload();
      ASSERT_EQ(decoder.apply(reinterpret_cast<const uint8_t*>(p.data()), p.size()), CodecStatus::Ok);
      gotFrame = true;
      ++frames;
    }
    ASSERT_TRUE(gotFrame) << "the stream ended after " << frames << " frames";
  }
  ProbeVolume got;
  decoder.copyVolume(hub.bounds(), got);
  const ProbeVolume want = hub.reconstruction();
  EXPECT_EQ(got.probes, want.probes);
  EXPECT_EQ(got.active, want.active);
  // The server shutting down ends the half-closed stream.
  server->shutdown();
  while (stream->Read(&msg)) {
  }
  EXPECT_NE(stream->Finish().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);

  // A stream closed before any hello has nothing to wait for: it is refused.
  ProbeServer again(plaintextConfig(), hub);
  auto stub2 = stubFor(again.port());
  grpc::ClientContext ctx2;
  ctx2.AddMetadata("authorization", std::string("Bearer ") + kToken);
  ctx2.set_deadline(std::chrono::system_clock::now() + 5s);
  auto silent = stub2->Subscribe(&ctx2);
  silent->WritesDone();
  while (silent->Read(&msg)) {
  }
  const grpc::Status st = silent->Finish();
  EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(st.error_message().find("before a hello"), std::string::npos) << st.error_message();
}

// Defect 5: 2^64-1 bytes per second overflowed to a zero allowance (one brick per frame).
TEST(ServiceHardening, BudgetsTooLargeToBindActAsUnlimited) {
  for (uint64_t huge : {UINT64_MAX, uint64_t{1} << 63, UINT64_MAX - 4096}) {
    ProbeHub hub(volumeConfig());
    const uint64_t unlimited = hub.addSubscriber(0, 0, {}, [] {});
    const uint64_t large = hub.addSubscriber(huge, 0, {}, [] {});
    std::mt19937 rng(3);
    uint32_t frames[2] = {0, 0}, bricks[2] = {0, 0};
    for (int f = 0; f < 6; ++f) {
      hub.publish(test::movingLightFrame(1024, f, 0.01f, rng).data(), nullptr);
      int k = 0;
      for (uint64_t id : {unlimited, large}) {
        for (int guard = 0; guard < 100; ++guard) {
          const std::optional<OutgoingFrame> frame = hub.nextFrame(id);
          if (!frame) break;
          frames[k] += 1;
          bricks[k] += frame->keyframes + frame->deltas;
        }
        ++k;
      }
    }
    EXPECT_EQ(frames[1], frames[0]) << "budget " << huge;
    EXPECT_EQ(bricks[1], bricks[0]) << "budget " << huge;
    EXPECT_EQ(hub.stats(large).bricksBehind, 0u);
  }
}

// Defect 6: a representation of 260 was read as 4 (l2) and accepted.
TEST(ServiceHardening, UnknownRepresentationIsRefusedByNumber) {
  HubConfig hc = volumeConfig();
  hc.layout.repr = Representation::L2;
  ProbeHub hub(hc);
  ProbeServer server(plaintextConfig(), hub);
  auto stub = stubFor(server.port());
  for (int value : {260, 4 + 256 * 1000, -252, 6}) {
    pb::ClientMessage hello = helloMessage();
    hello.mutable_hello()->set_representation(static_cast<pb::Representation>(value));
    const grpc::Status st = statusAfter(*stub, hello);
    EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << value;
    EXPECT_NE(st.error_message().find("representation " + std::to_string(value)), std::string::npos)
        << st.error_message();
  }
  pb::ClientMessage l2 = helloMessage();  // the served one is still accepted (the deadline ends it)
  l2.mutable_hello()->set_representation(pb::REPRESENTATION_L2);
  EXPECT_EQ(statusAfter(*stub, l2, nullptr, 300ms).error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
}

// A server that answers every subscription with one fixed volume description, whatever it says.
class FixedVolumeServer final : public pb::ProbeStream::Service {
 public:
  explicit FixedVolumeServer(const pb::VolumeDescription& volume) : volume_(volume) {
    grpc::ServerBuilder builder;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port_);
    builder.RegisterService(this);
    server_ = builder.BuildAndStart();
  }
  ~FixedVolumeServer() override { server_->Shutdown(std::chrono::system_clock::now() + 100ms); }
  int port() const { return port_; }

  grpc::Status Subscribe(grpc::ServerContext* ctx,
                         grpc::ServerReaderWriter<pb::ServerMessage, pb::ClientMessage>* stream) override {
    pb::ClientMessage in;
    stream->Read(&in);
    pb::ServerMessage out;
    *out.mutable_volume() = volume_;
    stream->Write(out);
    const auto end = std::chrono::steady_clock::now() + 5s;
    while (!ctx->IsCancelled() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(5ms);
    return grpc::Status::OK;
  }

 private:
  pb::VolumeDescription volume_;
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
};

// Defect 6, client side: a bad server's numbers are range-checked before narrowing, not wrapped.
TEST(ServiceHardening, ClientRefusesOutOfRangeVolumeDescription) {
  pb::VolumeDescription good;
  good.set_protocol_version(4);
  good.set_codec_format_version(kFormatVersion);
  good.set_grid_x(16);
  good.set_grid_y(4);
  good.set_grid_z(16);
  good.set_brick_size(4);
  good.set_representation(pb::REPRESENTATION_L2);
  for (int a = 0; a < 3; ++a) {
    good.add_bounds_min(0.0f);
    good.add_bounds_max(1.0f);
  }
  struct Case {
    std::function<void(pb::VolumeDescription&)> spoil;
    std::string error;
  };
  const Case cases[] = {
      {[](pb::VolumeDescription& v) { v.set_brick_size(260); }, "brick size 260"},  // 260 = 4 mod 256
      {[](pb::VolumeDescription& v) { v.set_grid_y(70000); }, "volume grid 16x70000x16"},  // 70000 = 4464 mod 65536
      {[](pb::VolumeDescription& v) { v.set_grid_x(65536 + 16); }, "volume grid 65552x4x16"},  // 16 mod 65536
      {[](pb::VolumeDescription& v) { v.set_representation(static_cast<pb::Representation>(260)); },
       "representation 260"},
      {[](pb::VolumeDescription& v) { v.set_representation(pb::REPRESENTATION_UNSPECIFIED); }, "representation 0"},
      // Probe offsets: 3 bytes per probe (16 × 4 × 16 probes) or none, each within ±127 steps.
      {[](pb::VolumeDescription& v) { v.set_probe_offsets(std::string(16 * 4 * 16 * 3 - 1, '\0')); },
       "3071 bytes for 1024 probes"},
      {[](pb::VolumeDescription& v) { v.set_probe_offsets(std::string(5, '\0')); }, "5 bytes for 1024 probes"},
      {[](pb::VolumeDescription& v) {
         std::string q(16 * 4 * 16 * 3, '\0');
         q[3 * 17 + 1] = static_cast<char>(-128);  // probe 17's y: -128 steps, beyond the symmetric range
         v.set_probe_offsets(q);
       },
       "probe 17 y offset of -128 steps"},
      // Client area lights: a rule this build does not know, a threshold that is no power share,
      // a threshold with the rule off.
      {[](pb::VolumeDescription& v) { v.set_area_light_rule(2); }, "area light rule version 2 is unknown"},
      {[](pb::VolumeDescription& v) {
         v.set_area_light_rule(1);
         v.set_area_light_min(std::nanf(""));
       },
       "threshold is not a power share"},
      {[](pb::VolumeDescription& v) {
         v.set_area_light_rule(1);
         v.set_area_light_min(-0.25f);
       },
       "threshold is not a power share"},
      {[](pb::VolumeDescription& v) { v.set_area_light_min(0.05f); }, "off but a threshold"},
      // The scene: a hash that is no SHA-256, a hash without its manifest, a manifest that is not
      // the hash's, a manifest that is not one, and an old peer.
      {[](pb::VolumeDescription& v) {
         v.set_scene_hash(std::string(31, 'x'));
         v.set_scene_manifest("{}");
       },
       "hash of 31 bytes"},
      {[](pb::VolumeDescription& v) { v.set_scene_hash(std::string(32, 'x')); }, "with a manifest of 0"},
      {[](pb::VolumeDescription& v) {
         v.set_scene_hash(std::string(32, 'x'));
         v.set_scene_manifest(R"({"files":[],"format":1,"lighting":{},"scene":{"builtin":"cornell"}})");
       },
       "manifest does not match its hash"},
      {[](pb::VolumeDescription& v) {
         const std::string manifest = R"({"files":[],"format":1,"lighting":{},"scene":{"gltf":"../x.gltf"}})";
         const SceneHash h = sha256(manifest);
         v.set_scene_hash(std::string(h.begin(), h.end()));
         v.set_scene_manifest(manifest);
       },
       "is not among its files"},
      {[](pb::VolumeDescription& v) { v.set_protocol_version(3); }, "protocol version 3, not 4"},
  };
  for (const Case& c : cases) {
    pb::VolumeDescription bad = good;
    c.spoil(bad);
    FixedVolumeServer server(bad);
    ClientConfig cc = clientFor(server.port());
    cc.reconnectMaxMs = 100;
    ProbeClient client(cc);
    client.start();
    EXPECT_TRUE(waitFor([&] { return client.stats().lastError.find(c.error) != std::string::npos; }, 5s))
        << "wanted '" << c.error << "', last error: " << client.stats().lastError;
    VolumeSnapshot snap;
    EXPECT_FALSE(client.snapshot(snap));
    EXPECT_FALSE(client.stats().connected);
    client.stop();
  }
  // The unspoilt description is taken, so the refusals above are the numbers' doing.
  FixedVolumeServer server(good);
  ProbeClient client(clientFor(server.port()));
  client.start();
  EXPECT_TRUE(waitFor([&] { return client.stats().connects >= 1; }, 5s)) << client.stats().lastError;
  VolumeSnapshot snap;
  EXPECT_TRUE(client.snapshot(snap));
  EXPECT_TRUE(snap.volume.offsets.empty());
  // And with good offsets: probe 17 moved 100 steps along +x (100/256 of the 1/15 m spacing).
  pb::VolumeDescription moved = good;
  std::string q(16 * 4 * 16 * 3, '\0');
  q[3 * 17] = 100;
  moved.set_probe_offsets(q);
  FixedVolumeServer movedServer(moved);
  ProbeClient movedClient(clientFor(movedServer.port()));
  movedClient.start();
  EXPECT_TRUE(waitFor([&] { return movedClient.stats().connects >= 1; }, 5s)) << movedClient.stats().lastError;
  ASSERT_TRUE(movedClient.snapshot(snap));
  ASSERT_EQ(snap.volume.offsets.size(), 16u * 4 * 16 * 3);
  EXPECT_FLOAT_EQ(snap.volume.offsets[3 * 17], (1.0f / 15.0f) * (100.0f / 256.0f));
  EXPECT_EQ(snap.volume.offsets[3 * 17 + 1], 0.0f);
  std::string error;
  EXPECT_TRUE(checkProbeVolume(snap.volume, error)) << error;
}

// Defect 7: a server without a token used to serve anyone; now only when asked for explicitly.
TEST(ServiceHardening, AuthenticationIsOffOnlyWhenAskedFor) {
  ProbeHub hub(volumeConfig());
  ServerConfig none;
  none.plaintext = true;
  try {
    ProbeServer server(none, hub);
    ADD_FAILURE() << "a server without a token or noAuth started";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("without authentication"), std::string::npos) << e.what();
  }
  ServerConfig both = plaintextConfig();
  both.noAuth = true;
  EXPECT_THROW(ProbeServer(both, hub), std::runtime_error);

  ServerConfig open;
  open.plaintext = true;
  open.noAuth = true;
  ProbeServer server(open, hub);
  Producer producer(hub, 5, 10ms);
  ClientConfig cc = clientFor(server.port());
  cc.token.clear();
  ProbeClient client(cc);
  client.start();
  ASSERT_TRUE(waitFor([&] { return producer.published() == 5; }, 10s));
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, hub); }, 10s)) << client.stats().lastError;
}

// Issue 11: the server took at most 64 views, so lf:9x8 and lf:9x9 failed over gRPC although the
// raster client renders up to kMaxViewsPerSet.
TEST(ServiceHardening, LightFieldViewSetsUpToTheRendererLimit) {
  EXPECT_EQ(ServerConfig{}.maxViews, kMaxViewsPerSet);
  // The largest view update fits the message limit with room to spare: every float non-zero, the
  // client clock at its widest varint.
  pb::ClientMessage largest;
  largest.mutable_views()->set_client_time_us(UINT64_MAX);
  for (uint32_t k = 0; k < kMaxViewsPerSet; ++k) {
    pb::View* w = largest.mutable_views()->add_views();
    for (int i = 0; i < 16; ++i) w->add_view_projection(-FLT_MAX);
    w->set_eye_x(-FLT_MAX);
    w->set_eye_y(-FLT_MAX);
    w->set_eye_z(-FLT_MAX);
  }
  EXPECT_LE(largest.ByteSizeLong(), ServerConfig{}.maxMessageBytes / 2);

  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 10, 10ms);
  ProbeClient lf8x6(clientFor(server.port()));
  lf8x6.setViews(lightField(8, 6));
  lf8x6.start();
  ProbeClient lf9x9(clientFor(server.port(), 30000));
  lf9x9.setViews(lightField(9, 9));
  lf9x9.start();
  ASSERT_TRUE(waitFor([&] { return producer.published() == 10; }, 10s));
  EXPECT_TRUE(waitFor([&] { return matchesServer(lf8x6, hub); }, 10s)) << lf8x6.stats().lastError;
  EXPECT_TRUE(waitFor([&] { return matchesServer(lf9x9, hub); }, 10s)) << lf9x9.stats().lastError;
  EXPECT_FALSE(lf9x9.stats().fatal);

  // One more than the limit is refused, naming both numbers.
  ProbeClient tooMany(clientFor(server.port()));
  tooMany.setViews(lightField(kMaxViewsPerSet + 1, 1));
  tooMany.start();
  EXPECT_TRUE(waitFor([&] { return tooMany.stats().fatal; }, 5s));
  EXPECT_NE(tooMany.stats().lastError.find(std::to_string(kMaxViewsPerSet + 1) + " views exceed the limit of " +
                                           std::to_string(kMaxViewsPerSet)),
            std::string::npos)
      << tooMany.stats().lastError;
}

}  // namespace
}  // namespace probecast::service

namespace probecast::service {
namespace {

// A resuming Hello lists every brick it holds; the message limit grows with the volume's bricks,
// so a client holding a large volume can resume (it was refused above about 8k bricks).
TEST(ServiceHardening, ResumingHelloOfManyBricksIsAccepted) {
  HubConfig hc = volumeConfig();
  hc.layout.grid[0] = 32;
  hc.layout.grid[1] = 8;
  hc.layout.grid[2] = 32;
  hc.layout.brickDim = 1;  // 8192 bricks
  ProbeHub hub(hc);
  ProbeServer server(plaintextConfig(), hub);
  auto stub = stubFor(server.port());
  auto helloHolding = [](uint32_t entries) {
    pb::ClientMessage hello = helloMessage();
    for (uint32_t i = 0; i < entries; ++i) {
      pb::BrickVersion* held = hello.mutable_hello()->add_held();
      held->set_brick(i % 8192);
      held->set_version(0x7fffffffu - i);
    }
    return hello;
  };
  const pb::ClientMessage holdsAll = helloHolding(8192);
  ASSERT_GT(holdsAll.ByteSizeLong(), plaintextConfig().maxMessageBytes);
  EXPECT_EQ(statusAfter(*stub, holdsAll, nullptr, 300ms).error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // Far more entries than bricks is still refused, by size.
  const grpc::Status tooLong = statusAfter(*stub, helloHolding(8192 * 3));
  EXPECT_EQ(tooLong.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(tooLong.error_message().find("exceeds the limit"), std::string::npos) << tooLong.error_message();
}

}  // namespace
}  // namespace probecast::service
