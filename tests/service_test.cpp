// ProbeStream over real gRPC on 127.0.0.1: convergence of many subscribers, late join, network
// faults and resume, a stalled subscriber, authentication, malformed input, TLS. Every wait is
// bounded and every test stops its own threads.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <grpcpp/grpcpp.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/health_check_service_interface.h>

#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <chrono>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "probecast.grpc.pb.h"
#include "probecast/codec/probe_offsets.h"
#include "probecast/service/client.h"
#include "probecast/service/scene_package.h"
#include "probecast/service/server.h"
#include "service_test_support.h"
#include "test_probes.h"
#include "wire_convert.h"

namespace probecast::service {
namespace {

namespace pb = probecast::v1;
using namespace std::chrono_literals;

TEST(Service, TwentySubscribersConvergeBitIdentical) {
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 30, 20ms);
  std::vector<std::unique_ptr<ProbeClient>> clients;
  for (int i = 0; i < 20; ++i) {
    const uint64_t budget = i % 3 == 0 ? 0 : 40000u + 10000u * static_cast<uint64_t>(i);
    clients.push_back(std::make_unique<ProbeClient>(clientFor(server.port(), budget)));
    clients.back()->setViews({viewAt(-2.0f + 0.2f * static_cast<float>(i), 0.0f)});
    clients.back()->start();
  }
  ASSERT_TRUE(waitFor([&] { return producer.published() == 30; }, 10s));
  for (size_t i = 0; i < clients.size(); ++i)
    EXPECT_TRUE(waitFor([&] { return matchesServer(*clients[i], hub); }, 20s)) << "client " << i;
  for (auto& c : clients) {
    EXPECT_EQ(c->stats().framesRejected, 0u);
    EXPECT_EQ(c->stats().connects, 1u);
  }
}

TEST(Service, BudgetLimitedSubscriberFinishesWhenNothingMoreIsPublished) {
  // One frame of lighting, then silence: nobody calls hub.tick(). The server's own ticker must
  // refill the budget and wake the subscriber until it holds everything.
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  std::mt19937 rng(8);
  hub.publish(test::movingLightFrame(1024, 0, 0.01f, rng).data(), nullptr);
  ProbeClient client(clientFor(server.port(), 4000));  // a few seconds for the whole volume
  client.start();
  ASSERT_TRUE(waitFor([&] { return client.stats().framesApplied >= 1; }, 10s));
  EXPECT_FALSE(matchesServer(client, hub));  // the first burst cannot hold it all
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, hub); }, 20s));
  EXPECT_GE(client.stats().framesApplied, 2u);
}

TEST(Service, LateJoinerGetsKeyframesAndConverges) {
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 40, 15ms);
  ASSERT_TRUE(waitFor([&] { return producer.published() >= 20; }, 10s));
  ProbeClient late(clientFor(server.port()));
  late.start();
  ASSERT_TRUE(waitFor([&] { return producer.published() == 40; }, 10s));
  EXPECT_TRUE(waitFor([&] { return matchesServer(late, hub); }, 10s));
}

// Acks feed the server's statistics only, so a client sends them at most every ackIntervalMs:
// with an interval longer than the test, the server hears of the first frame alone; with 0, of
// later ones too.
TEST(Service, AcksGoAtMostOncePerIntervalAndEveryFrameWithout) {
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 1000000, 5ms);
  ClientConfig rare = clientFor(server.port()), every = clientFor(server.port());
  rare.ackIntervalMs = 3600 * 1000;
  rare.linkPacing = false;  // a paced client acks every frame (below)
  every.ackIntervalMs = 0;
  ProbeClient rareClient(rare), everyClient(every);
  rareClient.start();
  everyClient.start();
  // Stats come every 16 frames; by the third, the second frame's ack would long have arrived.
  ASSERT_TRUE(waitFor([&] { return rareClient.stats().statsReceived >= 3 && everyClient.stats().statsReceived >= 3; },
                      10s));
  EXPECT_EQ(rareClient.stats().serverFramesAcked, 1u);
  EXPECT_TRUE(waitFor([&] { return everyClient.stats().serverFramesAcked > 16; }, 5s))
      << everyClient.stats().serverFramesAcked;
  // The unpaced stream reports no link; the paced one its estimate of loopback.
  EXPECT_EQ(rareClient.stats().serverLinkWindow, 0u);
  EXPECT_GE(everyClient.stats().serverLinkWindow, LinkEstimator::kMinWindow);
  EXPECT_GT(everyClient.stats().serverLinkRate, 0u);
}

TEST(Service, APacedClientAcksEveryFrameWhateverItsInterval) {
  // Paced, a client given an ack interval of an hour still acks every frame: the window keeps
  // opening and the stream never stalls.
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 1000000, 5ms);
  ClientConfig cc = clientFor(server.port());
  cc.ackIntervalMs = 3600 * 1000;
  ProbeClient client(cc);
  client.start();
  ASSERT_TRUE(waitFor([&] { return client.stats().statsReceived >= 3; }, 10s));
  const uint32_t applied = client.stats().framesApplied;
  EXPECT_TRUE(waitFor([&] { return client.stats().framesApplied > applied + 32; }, 5s));
  EXPECT_GT(client.stats().serverFramesAcked, applied);
  EXPECT_GT(client.stats().serverLinkWindow, 0u);
}

TEST(Service, APacedSubscriberHearsStatsBeforeTheDescriptionAnUnpacedOneTheDescriptionFirst) {
  // A paced subscriber's first message is a small Stats with the heartbeat promise, so its silence
  // watchdog hears a fresh connection within a round trip however long the description takes;
  // then the description, then frames. Others get the description first.
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 5, 10ms);
  auto stub = pb::ProbeStream::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(server.port()), grpc::InsecureChannelCredentials()));
  for (const bool paced : {true, false}) {
    SCOPED_TRACE(paced ? "paced" : "unpaced");
    grpc::ClientContext ctx;
    ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
    ctx.set_deadline(std::chrono::system_clock::now() + 10s);
    auto stream = stub->Subscribe(&ctx);
    pb::ClientMessage hello;
    hello.mutable_hello()->set_protocol_version(4);
    hello.mutable_hello()->set_acks_every_frame(paced);
    ASSERT_TRUE(stream->Write(hello));
    pb::ServerMessage msg;
    ASSERT_TRUE(stream->Read(&msg));
    if (paced) {
      ASSERT_TRUE(msg.has_stats());
      EXPECT_GT(msg.stats().heartbeat_ms(), 0u);
      ASSERT_TRUE(stream->Read(&msg));
    }
    EXPECT_TRUE(msg.has_volume());
    bool frame = false;
    while (!frame && stream->Read(&msg)) {
      EXPECT_FALSE(msg.has_volume()) << "a second description";
      frame = msg.has_frame();
    }
    EXPECT_TRUE(frame);
    ctx.TryCancel();
    stream->Finish();
  }
}

// A port that takes no new connections and refuses none: a listener whose queue is full, so
// that the kernel drops every further SYN (as a link outage does) and a connect hangs.
struct BlackHole {
  int listener = -1;
  std::vector<int> queued;
  explicit BlackHole(int port) {
    listener = socket(AF_INET, SOCK_STREAM, 0);
    const int one = 1;
    setsockopt(listener, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bound = bind(listener, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 && listen(listener, 0) == 0;
    for (int i = 0; bound && i < 2; ++i) {  // fill the accept queue (not waiting: the second hangs)
      const int c = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
      connect(c, reinterpret_cast<sockaddr*>(&a), sizeof a);
      queued.push_back(c);
    }
  }
  // Whether a further connection hangs, as it must for the test (Linux drops the SYN).
  bool swallows() const {
    const int c = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
    sockaddr_in a{};
    socklen_t n = sizeof a;
    getsockname(listener, reinterpret_cast<sockaddr*>(&a), &n);
    const bool hangs = connect(c, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 && errno == EINPROGRESS;
    fd_set w;
    FD_ZERO(&w);
    FD_SET(c, &w);
    timeval t{0, 200000};
    const bool answered = hangs && select(c + 1, nullptr, &w, nullptr, &t) > 0;
    close(c);
    return hangs && !answered;
  }
  // The link comes back: what reaches the port from now on is accepted and relayed to `port`.
  void relayTo(int port) {
    relaying = true;
    relay = std::thread([this, port] { relayLoop(port); });
  }
  ~BlackHole() {
    relaying = false;
    if (relay.joinable()) relay.join();
    for (int c : queued) close(c);
    if (listener >= 0) close(listener);
  }
  bool bound = false;

 private:
  void relayLoop(int port) {
    std::vector<std::pair<int, int>> pairs;  // accepted, connected to the server
    for (int c : queued) close(c);  // the queue's own
    queued.clear();
    while (relaying) {
      std::vector<pollfd> fds{{listener, POLLIN, 0}};
      for (auto [a, b] : pairs) {
        fds.push_back({a, POLLIN, 0});
        fds.push_back({b, POLLIN, 0});
      }
      if (poll(fds.data(), fds.size(), 20) <= 0) continue;
      if (fds[0].revents & POLLIN) {
        const int a = accept(listener, nullptr, nullptr);
        const int b = socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in to{};
        to.sin_family = AF_INET;
        to.sin_port = htons(static_cast<uint16_t>(port));
        to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (a >= 0 && connect(b, reinterpret_cast<sockaddr*>(&to), sizeof to) == 0) pairs.push_back({a, b});
        else close(a), close(b);
      }
      std::vector<std::pair<int, int>> open;
      for (size_t i = 0; i < pairs.size(); ++i) {
        bool ended = false;
        for (int side = 0; side < 2 && !ended; ++side) {
          if (!(fds[1 + 2 * i + side].revents & (POLLIN | POLLHUP | POLLERR))) continue;
          char buf[65536];
          const int from = side ? pairs[i].second : pairs[i].first, to = side ? pairs[i].first : pairs[i].second;
          const ssize_t n = read(from, buf, sizeof buf);
          ended = n <= 0 || send(to, buf, static_cast<size_t>(n), MSG_NOSIGNAL) != n;
        }
        if (ended) close(pairs[i].first), close(pairs[i].second);
        else open.push_back(pairs[i]);
      }
      pairs = std::move(open);
    }
    for (auto [a, b] : pairs) close(a), close(b);
  }
  std::atomic<bool> relaying{false};
  std::thread relay;
};

// A reconnect whose SYNs are lost (a link outage): the attempt is cut, and then fresh connections
// overlap, a bounded number, and the first that comes up once the link is back is taken, instead
// of waiting on one attempt's SYN retransmissions (1, 3, 7 s after it began, on Linux).
TEST(Service, AReconnectThroughLostSynsTakesTheFirstAttemptThatComesUp) {
  ProbeHub hub(volumeConfig());
  auto server = std::make_unique<ProbeServer>(plaintextConfig(), hub);
  const int port = server->port();
  Producer producer(hub, 3, 20ms);
  ClientConfig cc = clientFor(port);
  cc.reconnectSilenceMs = 1000;  // the first attempt is cut after a second; then they overlap
  cc.connectRaceMs = 50;
  ProbeClient client(cc);
  client.start();
  ASSERT_TRUE(waitFor([&] { return client.stats().framesApplied >= 1; }, 10s));
  const uint64_t connects = client.stats().connects;
  server.reset();
  BlackHole hole(port);
  ASSERT_TRUE(hole.bound);
  if (!hole.swallows()) GTEST_SKIP() << "this kernel answers connections past a full accept queue";
  const uint64_t before = client.stats().connectAttempts;
  server = std::make_unique<ProbeServer>(plaintextConfig(), hub);  // on another port, behind the hole
  std::this_thread::sleep_for(3500ms);
  // The first attempt alone for a second, then one every 50 ms (a fresh race every 1 or 2 s).
  const uint64_t begun = client.stats().connectAttempts - before;
  EXPECT_GE(begun, 20u) << client.stats().lastError;
  EXPECT_LE(begun, 3500u / 50 + 2);
  // The same port lets connections through again (the link is back): the next attempt comes up.
  hole.relayTo(server->port());
  EXPECT_TRUE(waitFor([&] { return client.stats().connects > connects; }, 1500ms))
      << "not connected 1.5 s after the link came back; " << client.stats().connectAttempts << " attempts, last error "
      << client.stats().lastError;
  client.stop();
}

// A reconnect whose connection cannot be made (SYNs lost) is given up after reconnectSilenceMs and
// tried afresh, not left waiting for TCP: opening the call and racing attempts are under the
// allowance too, and the message names it.
TEST(Service, AReconnectThatCannotConnectIsCutAndTriedAfresh) {
  ProbeHub hub(volumeConfig());
  auto server = std::make_unique<ProbeServer>(plaintextConfig(), hub);
  const int port = server->port();
  Producer producer(hub, 3, 20ms);
  ClientConfig cc = clientFor(port);
  cc.reconnectSilenceMs = 300;
  ProbeClient client(cc);
  client.start();
  ASSERT_TRUE(waitFor([&] { return client.stats().statsReceived >= 1 && client.stats().framesApplied >= 1; }, 10s));
  server.reset();
  BlackHole hole(port);
  ASSERT_TRUE(hole.bound);
  if (!hole.swallows()) GTEST_SKIP() << "this kernel answers connections past a full accept queue";
  const uint32_t before = client.stats().silences;
  EXPECT_TRUE(waitFor([&] { return client.stats().silences >= before + 3; }, 5s))
      << "silences " << client.stats().silences << ", last error " << client.stats().lastError;
  // Every other attempt is given twice as long (a link slower than the allowance still gets through).
  const std::string last = client.stats().lastError;
  EXPECT_TRUE(last.find("no answer within 300 ms of connecting") != std::string::npos ||
              last.find("no answer within 600 ms of connecting") != std::string::npos)
      << last;
  client.stop();
}

TEST(Service, NetworkFaultKeepsLightingAndResumesWithWhatIsLacking) {
  ProbeHub hub(volumeConfig());
  auto server = std::make_unique<ProbeServer>(plaintextConfig(), hub);
  const int port = server->port();
  Producer producer(hub, 1000000, 20ms);  // lighting keeps changing throughout
  ClientConfig cc = clientFor(port);
  cc.reconnectMaxMs = 200;
  ProbeClient client(cc);
  client.start();
  ASSERT_TRUE(waitFor([&] { return client.stats().framesApplied >= 20; }, 10s));
  // Every 16 frames the server reports what it sent; it matches what arrived.
  ASSERT_TRUE(waitFor([&] { return client.stats().statsReceived >= 1; }, 5s));
  EXPECT_GT(client.stats().serverBytesSent, 0u);
  EXPECT_LE(client.stats().serverBytesSent, client.stats().bytesReceived);

  // The server goes away: lighting stays the last volume, it never goes black.
  server.reset();
  ASSERT_TRUE(waitFor([&] { return !client.stats().connected; }, 5s));
  VolumeSnapshot during;
  ASSERT_TRUE(client.snapshot(during));
  double energy = 0;
  for (float v : during.volume.probes) energy += std::fabs(v);
  EXPECT_GT(energy, 0.0);
  std::this_thread::sleep_for(300ms);  // a few reconnect attempts fail meanwhile
  VolumeSnapshot later;
  ASSERT_TRUE(client.snapshot(later));
  EXPECT_EQ(later.volume.probes, during.volume.probes);

  // It comes back on the same port with the same hub (epoch): the client resumes.
  ServerConfig again = plaintextConfig();
  again.listen = "127.0.0.1:" + std::to_string(port);
  server = std::make_unique<ProbeServer>(again, hub);
  ASSERT_TRUE(waitFor([&] { return client.stats().connects >= 2; }, 10s));
  const uint64_t bytesAtResume = client.stats().bytesReceived;
  ProbeClient fresh(clientFor(port));  // joins at the same moment, holding nothing
  fresh.start();
  producer.stop();  // freeze the lighting so both can finish
  hub.tick();
  ASSERT_TRUE(waitFor([&] { return matchesServer(client, hub); }, 10s));
  ASSERT_TRUE(waitFor([&] { return matchesServer(fresh, hub); }, 10s));
  // The resumed client sent its held versions: it needed no more than a newcomer (who got every
  // brick as a keyframe) and usually much less.
  EXPECT_LE(client.stats().bytesReceived - bytesAtResume, fresh.stats().bytesReceived);
  EXPECT_EQ(client.stats().framesRejected, 0u);
}

TEST(Service, StalledSubscriberDoesNotDelayOthers) {
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  // A subscriber that says hello and then never reads: flow control stops its stream only.
  auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(server.port()), grpc::InsecureChannelCredentials());
  auto stub = pb::ProbeStream::NewStub(channel);
  grpc::ClientContext stalledCtx;
  stalledCtx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  auto stalled = stub->Subscribe(&stalledCtx);
  pb::ClientMessage hello;
  hello.mutable_hello()->set_protocol_version(4);
  ASSERT_TRUE(stalled->Write(hello));

  Producer producer(hub, 60, 10ms);
  std::vector<std::unique_ptr<ProbeClient>> clients;
  for (int i = 0; i < 4; ++i) {
    clients.push_back(std::make_unique<ProbeClient>(clientFor(server.port())));
    clients.back()->start();
  }
  ASSERT_TRUE(waitFor([&] { return producer.published() == 60; }, 10s));
  for (auto& c : clients) EXPECT_TRUE(waitFor([&] { return matchesServer(*c, hub); }, 10s));
  // Frame age of the others: their newest lighting is the last published frame.
  std::this_thread::sleep_for(100ms);
  for (auto& c : clients) EXPECT_EQ(c->stats().framesRejected, 0u);
  stalledCtx.TryCancel();
  stalled->Finish();
}

TEST(Service, WrongTokenIsUnauthenticatedAndGetsNoPayload) {
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 5, 10ms);
  auto stub = pb::ProbeStream::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(server.port()), grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", "Bearer nope");
  auto stream = stub->Subscribe(&ctx);
  pb::ClientMessage hello;
  hello.mutable_hello()->set_protocol_version(4);
  stream->Write(hello);
  pb::ServerMessage msg;
  EXPECT_FALSE(stream->Read(&msg));
  EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::UNAUTHENTICATED);

  grpc::ClientContext unary;
  pb::VolumeDescription volume;
  EXPECT_EQ(stub->GetVolume(&unary, pb::GetVolumeRequest(), &volume).error_code(), grpc::StatusCode::UNAUTHENTICATED);

  ClientConfig bad = clientFor(server.port());
  bad.token = "wrong";
  ProbeClient client(bad);
  client.start();
  EXPECT_TRUE(waitFor([&] { return client.stats().fatal; }, 5s));
  VolumeSnapshot snap;
  EXPECT_FALSE(client.snapshot(snap));
}

TEST(Service, MalformedMessagesAreInvalidArgumentAndOthersCarryOn) {
  ProbeHub hub(volumeConfig());
  ServerConfig sc = plaintextConfig();
  sc.maxViews = 8;
  ProbeServer server(sc, hub);
  Producer producer(hub, 30, 15ms);
  ProbeClient good(clientFor(server.port()));
  good.start();
  auto stub = pb::ProbeStream::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(server.port()), grpc::InsecureChannelCredentials()));

  pb::ClientMessage hello;
  hello.mutable_hello()->set_protocol_version(4);
  pb::ClientMessage views;  // a first message that is not hello
  views.mutable_views()->add_views()->add_view_projection(1.0f);
  EXPECT_EQ(statusAfter(*stub, views).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  pb::ClientMessage v2 = hello;
  for (uint32_t old : {1u, 2u, 3u}) {  // before the probe offsets; the area light rule; the scene
    v2.mutable_hello()->set_protocol_version(old);
    const grpc::Status wrongVersion = statusAfter(*stub, v2);
    EXPECT_EQ(wrongVersion.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(wrongVersion.error_message().find("protocol version " + std::to_string(old)), std::string::npos);
  }

  pb::ClientMessage shortMatrix;  // 15 floats
  for (int i = 0; i < 15; ++i) shortMatrix.mutable_views()->mutable_views()->Add()->add_view_projection(0.0f);
  shortMatrix.mutable_views()->clear_views();
  pb::View* v = shortMatrix.mutable_views()->add_views();
  for (int i = 0; i < 15; ++i) v->add_view_projection(1.0f);
  EXPECT_EQ(statusAfter(*stub, hello, &shortMatrix).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  pb::ClientMessage nan;
  pb::View* w = nan.mutable_views()->add_views();
  for (int i = 0; i < 16; ++i) w->add_view_projection(i == 5 ? std::nanf("") : 1.0f);
  EXPECT_EQ(statusAfter(*stub, hello, &nan).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  pb::ClientMessage many;
  for (int k = 0; k < 9; ++k) {
    pb::View* m = many.mutable_views()->add_views();
    for (int i = 0; i < 16; ++i) m->add_view_projection(1.0f);
  }
  EXPECT_EQ(statusAfter(*stub, hello, &many).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  pb::ClientMessage oversized = hello;
  oversized.mutable_hello()->set_client_name(std::string(100 * 1024, 'x'));
  EXPECT_EQ(statusAfter(*stub, oversized).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  pb::ClientMessage bogusAck;  // acknowledges a frame the server never sent
  bogusAck.mutable_ack()->set_frame_sequence(1000000);
  const grpc::Status ackStatus = statusAfter(*stub, hello, &bogusAck);
  EXPECT_EQ(ackStatus.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(ackStatus.error_message().find("ack of frame"), std::string::npos);

  pb::ClientMessage wrongRepr = hello;  // finer than the zh3 served: nothing to make it from
  wrongRepr.mutable_hello()->set_representation(pb::REPRESENTATION_L2);
  const grpc::Status reprStatus = statusAfter(*stub, wrongRepr);
  EXPECT_EQ(reprStatus.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(reprStatus.error_message().find("transcodes it only to coarser ones"), std::string::npos)
      << reprStatus.error_message();

  ASSERT_TRUE(waitFor([&] { return producer.published() == 30; }, 10s));
  EXPECT_TRUE(waitFor([&] { return matchesServer(good, hub); }, 10s));
  EXPECT_EQ(good.stats().connects, 1u);
}

// A client may ask for less than the server streams: over real gRPC it is told its own
// representation and epoch, and ends holding the hub's transcoded volume bit for bit for fewer
// bytes than a client of the stream itself, while that one converges as before. Asking for more
// than the stream holds is refused for good.
TEST(Service, AClientAskingForACoarserRepresentationGetsItTranscoded) {
  ProbeHub hub(volumeConfig());  // zh3
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 30, 20ms);
  ProbeClient full(clientFor(server.port()));
  ClientConfig coarse = clientFor(server.port());
  coarse.representation = Representation::L1;
  ProbeClient l1(coarse);
  coarse.representation = Representation::L2;
  ProbeClient l2(coarse);
  for (ProbeClient* c : {&full, &l1, &l2}) c->start();
  ASSERT_TRUE(waitFor([&] { return producer.published() == 30; }, 10s));
  EXPECT_TRUE(waitFor([&] { return matchesServer(full, hub); }, 20s));
  const auto holdsL1 = [&] {
    VolumeSnapshot snap;
    if (!l1.snapshot(snap) || snap.layout.repr != Representation::L1) return false;
    const ProbeVolume made = hub.reconstruction(Representation::L1);
    return snap.volume.probes.size() == made.probes.size() &&
           std::memcmp(snap.volume.probes.data(), made.probes.data(), made.probes.size() * sizeof(float)) == 0 &&
           snap.volume.active == made.active;
  };
  EXPECT_TRUE(waitFor(holdsL1, 20s));
  EXPECT_EQ(l1.stats().framesRejected, 0u);
  EXPECT_LT(l1.stats().bytesReceived, full.stats().bytesReceived);
  EXPECT_TRUE(waitFor([&] { return l2.stats().fatal; }, 10s));
  EXPECT_NE(l2.stats().lastError.find("not served"), std::string::npos) << l2.stats().lastError;
  VolumeSnapshot none;
  EXPECT_FALSE(l2.snapshot(none));
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Service, TlsRoundTripAndNoAccidentalPlaintext) {
  std::string key, cert;
  ASSERT_TRUE(makeTestCertificate(PROBECAST_TEST_TMP, "tls", key, cert)) << "openssl could not make a test certificate";
  ProbeHub hub(volumeConfig());
  ServerConfig unsafe;
  unsafe.token = kToken;  // neither TLS nor plaintext asked for
  EXPECT_THROW(ProbeServer(unsafe, hub), std::runtime_error);

  ServerConfig sc;
  sc.token = kToken;
  sc.tlsCertPem = readFile(cert);
  sc.tlsKeyPem = readFile(key);
  ProbeServer server(sc, hub);
  Producer producer(hub, 10, 10ms);
  ClientConfig cc = clientFor(server.port());
  cc.tls = true;
  cc.rootCertPem = sc.tlsCertPem;
  cc.tlsServerName = "localhost";
  ProbeClient client(cc);
  client.start();
  ASSERT_TRUE(waitFor([&] { return producer.published() == 10; }, 10s));
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, hub); }, 10s));
  // A plaintext client cannot talk to the TLS port.
  ProbeClient plain(clientFor(server.port()));
  plain.start();
  std::this_thread::sleep_for(300ms);
  VolumeSnapshot snap;
  EXPECT_FALSE(plain.snapshot(snap));
}

TEST(Service, GetVolumeAndHealth) {
  ProbeHub hub(volumeConfig());
  ProbeServer server(plaintextConfig(), hub);
  auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(server.port()), grpc::InsecureChannelCredentials());
  auto stub = pb::ProbeStream::NewStub(channel);
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  pb::VolumeDescription v;
  ASSERT_TRUE(stub->GetVolume(&ctx, pb::GetVolumeRequest(), &v).ok());
  EXPECT_EQ(v.grid_x(), 16u);
  EXPECT_EQ(v.grid_z(), 16u);
  EXPECT_EQ(v.representation(), pb::REPRESENTATION_ZH3);
  EXPECT_EQ(v.stream_epoch(), hub.epoch());
  EXPECT_NE(v.sh_convention().find("Condon-Shortley"), std::string::npos);
  // The standard health service answers for the ProbeStream service.
  grpc::ByteBuffer response;
  grpc::ClientContext hctx;
  grpc::GenericStub generic(channel);
  // grpc.health.v1.HealthCheckRequest { service = "probecast.v1.ProbeStream" } encoded by hand:
  const std::string svc = "probecast.v1.ProbeStream";
  std::string req = std::string(1, '\x0a') + static_cast<char>(svc.size()) + svc;
  grpc::Slice slice(req);
  grpc::ByteBuffer request(&slice, 1);
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  grpc::Status status;
  generic.UnaryCall(&hctx, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &request, &response,
                    [&](grpc::Status s) {
                      std::lock_guard<std::mutex> lock(m);
                      status = s;
                      done = true;
                      cv.notify_all();
                    });
  std::unique_lock<std::mutex> lock(m);
  ASSERT_TRUE(cv.wait_for(lock, 5s, [&] { return done; }));
  EXPECT_TRUE(status.ok()) << status.error_message();
  std::vector<grpc::Slice> slices;
  ASSERT_TRUE(response.Dump(&slices).ok());
  std::string body;
  for (auto& s : slices) body.append(reinterpret_cast<const char*>(s.begin()), s.size());
  EXPECT_EQ(body, std::string("\x08\x01", 2));  // status: SERVING
}

// Offsets as a relocating updater hands them over: probe p of the 16 × 4 × 16 volume moves
// along x by a fraction of its 0.233 m cell that varies with p, and probe 5 along y too.
std::vector<float> sampleOffsets(const ProbeGrid& g) {
  std::vector<float> o(g.count() * 3, 0.0f);
  for (uint32_t p = 0; p < g.count(); ++p) o[p * 3] = 0.45f * probeCellSize(g, 0) * (static_cast<float>(p % 9) - 4.0f) / 4.0f;
  o[5 * 3 + 1] = -0.3f * probeCellSize(g, 1);
  return o;
}

// Waits until `client` holds what the server has after the producer's 3 frames; false (with the
// client's last error reported) if it does not within 10 s.
bool convergedSnapshot(ProbeClient& client, ProbeHub& hub, const Producer& producer, VolumeSnapshot& snap) {
  const bool held = waitFor([&] { return matchesServer(client, hub) && producer.published() == 3; }, 10s);
  EXPECT_TRUE(held) << client.stats().lastError;
  return held && client.snapshot(snap);
}

TEST(Service, ProbeOffsetsReachEverySubscriberOnceAndAChangeStartsANewEpoch) {
  ProbeHub hub(volumeConfig());
  const ProbeGrid g = gridOf(hub.layout(), hub.bounds());
  std::vector<float> offsets = sampleOffsets(g);
  hub.setProbeOffsets(offsets);
  EXPECT_THROW(hub.setProbeOffsets(std::vector<float>(7, 0.0f)), std::invalid_argument);  // wrong count
  std::vector<float> tooFar = offsets;
  tooFar[4] = 0.51f * probeCellSize(g, 1);
  EXPECT_THROW(hub.setProbeOffsets(tooFar), std::invalid_argument);
  const uint64_t epoch = hub.epoch();  // nothing published and nobody subscribed yet: same epoch
  snapProbeOffsets(g, offsets);         // what every viewer reconstructs from 3 bytes per probe
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 3, 20ms);
  ProbeClient client(clientFor(server.port()));
  client.start();
  VolumeSnapshot snap;
  ASSERT_TRUE(convergedSnapshot(client, hub, producer, snap));
  EXPECT_EQ(snap.volume.offsets, offsets);  // bit for bit
  EXPECT_EQ(hub.reconstruction().offsets, offsets);
  EXPECT_EQ(hub.epoch(), epoch);
  // GetVolume carries them too: 3 bytes per probe.
  auto stub = pb::ProbeStream::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(server.port()), grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  pb::VolumeDescription v;
  ASSERT_TRUE(stub->GetVolume(&ctx, pb::GetVolumeRequest(), &v).ok());
  EXPECT_EQ(v.probe_offsets().size(), g.count() * 3u);
  // New offsets (the geometry changed): a new epoch, the client subscribes again and gets them.
  producer.stop();
  std::vector<float> next(g.count() * 3, 0.0f);
  next[3 * 100 + 2] = 0.2f * probeCellSize(g, 2);
  hub.setProbeOffsets(next);
  snapProbeOffsets(g, next);
  EXPECT_NE(hub.epoch(), epoch);
  ASSERT_TRUE(waitFor([&] { return client.snapshot(snap) && snap.volume.offsets == next; }, 10s))
      << client.stats().lastError;
  client.stop();
}

// The digest a resume names its held description by, written here from the protocol's words:
// SHA-256 of the offsets and the manifest, each after its length as 8 bytes little-endian.
std::string heldDigest(const std::string& offsets, const std::string& manifest) {
  std::string bytes;
  for (const std::string* part : {&offsets, &manifest}) {
    for (int k = 0; k < 8; ++k) bytes.push_back(static_cast<char>((uint64_t{part->size()} >> (8 * k)) & 0xff));
    bytes += *part;
  }
  const SceneHash h = sha256(bytes);
  return std::string(reinterpret_cast<const char*>(h.data()), h.size());
}

// A hub with probe offsets and a scene, as a relocating producer of a named scene has.
SceneStamp offsetsAndScene(ProbeHub& hub, std::vector<float>& offsets) {
  const ProbeGrid g = gridOf(hub.layout(), hub.bounds());
  offsets = sampleOffsets(g);
  hub.setProbeOffsets(offsets);
  snapProbeOffsets(g, offsets);
  SceneStamp stamp;
  stamp.manifest = R"({"files":[],"format":1,"lighting":{},"scene":{"builtin":"cornell"}})";
  stamp.hash = sha256(stamp.manifest);
  hub.setScene(stamp);
  return stamp;
}

// The first description a raw subscriber gets for `hello` (unpaced: the description comes first).
pb::VolumeDescription firstDescription(int port, const pb::Hello& hello) {
  auto stub = pb::ProbeStream::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
  ctx.set_deadline(std::chrono::system_clock::now() + 10s);
  auto stream = stub->Subscribe(&ctx);
  pb::ClientMessage m;
  *m.mutable_hello() = hello;
  pb::ServerMessage msg;
  EXPECT_TRUE(stream->Write(m) && stream->Read(&msg) && msg.has_volume());
  ctx.TryCancel();
  stream->Finish();
  return msg.volume();
}

// A resume in the same epoch names the description it holds by its digest; the server leaves the
// offsets and the manifest out, and the client puts its own back. Another digest or epoch, or none,
// gets the whole description.
TEST(Service, AResumeInTheSameEpochIsNotSentTheOffsetsAndManifestAgain) {
  ProbeHub hub(volumeConfig());
  std::vector<float> offsets;
  const SceneStamp stamp = offsetsAndScene(hub, offsets);
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 3, 20ms);
  pb::Hello hello;
  hello.set_protocol_version(kProtocolVersion);
  const pb::VolumeDescription whole = firstDescription(server.port(), hello);
  ASSERT_EQ(whole.probe_offsets().size(), offsets.size());
  ASSERT_FALSE(whole.held_parts());
  hello.set_stream_epoch(whole.stream_epoch());
  hello.set_held_description(heldDigest(whole.probe_offsets(), whole.scene_manifest()));
  const pb::VolumeDescription resumed = firstDescription(server.port(), hello);
  EXPECT_TRUE(resumed.held_parts());
  EXPECT_TRUE(resumed.probe_offsets().empty());
  EXPECT_TRUE(resumed.scene_manifest().empty());
  EXPECT_EQ(resumed.scene_hash(), whole.scene_hash());
  EXPECT_EQ(resumed.stream_epoch(), whole.stream_epoch());
  hello.set_held_description(heldDigest(whole.probe_offsets() + "x", whole.scene_manifest()));
  EXPECT_FALSE(firstDescription(server.port(), hello).held_parts()) << "another digest";
  hello.set_held_description(heldDigest(whole.probe_offsets(), whole.scene_manifest()));
  hello.set_stream_epoch(whole.stream_epoch() + 1);
  EXPECT_FALSE(firstDescription(server.port(), hello).held_parts()) << "another epoch";

  // The client library: a cut connection resumes with the short description, and holds the same.
  ClientConfig cc = clientFor(server.port());
  cc.reconnectMaxMs = 200;
  ProbeClient client(cc);
  client.start();
  VolumeSnapshot snap;
  ASSERT_TRUE(convergedSnapshot(client, hub, producer, snap));
  EXPECT_EQ(client.stats().descriptionsResumed, 0u);
  client.dropConnection();
  ASSERT_TRUE(waitFor([&] { return client.stats().connects >= 2; }, 10s)) << client.stats().lastError;
  EXPECT_EQ(client.stats().descriptionsResumed, 1u);
  ASSERT_TRUE(client.snapshot(snap));
  EXPECT_EQ(snap.volume.offsets, offsets);
  EXPECT_EQ(snap.volume.scene.hash, stamp.hash);
  EXPECT_EQ(snap.volume.scene.manifest, stamp.manifest);
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, hub); }, 10s));
  client.stop();
}

// A description that leaves out parts nobody asked to keep is incomplete: GetVolume's caller, or a
// client that holds nothing, refuses it rather than read it as "no offsets".
TEST(Service, AShortDescriptionNobodyAskedForIsRefused) {
  pb::VolumeDescription v;
  v.set_protocol_version(4);
  v.set_held_parts(true);
  StreamLayout layout;
  GridBounds bounds;
  std::vector<float> offsets;
  AreaLightRule rule;
  SceneStamp scene;
  std::string why;
  EXPECT_FALSE(volumeFromWire(v, layout, bounds, offsets, rule, scene, why));
  EXPECT_NE(why.find("leaves out probe offsets"), std::string::npos) << why;
}

// The client area light rule travels in the description: a client holds the rule its probes were
// made with, and a new rule (a producer restarted with area lights on) is a new epoch.
TEST(Service, AreaLightRuleReachesTheClientAndAChangeStartsANewEpoch) {
  HubConfig config = volumeConfig();
  config.areaLights = {kAreaLightRuleVersion, 0.125f};
  ProbeHub hub(config);
  EXPECT_THROW(hub.setAreaLightRule({kAreaLightRuleVersion, 2.0f}), std::invalid_argument);
  EXPECT_THROW(hub.setAreaLightRule({7, 0.05f}), std::invalid_argument);
  HubConfig bad = volumeConfig();
  bad.areaLights = {0, 0.5f};
  EXPECT_THROW(ProbeHub{bad}, std::invalid_argument);
  const uint64_t epoch = hub.epoch();
  ProbeServer server(plaintextConfig(), hub);
  Producer producer(hub, 3, 20ms);
  ProbeClient client(clientFor(server.port()));
  client.start();
  VolumeSnapshot snap;
  ASSERT_TRUE(convergedSnapshot(client, hub, producer, snap));
  EXPECT_EQ(snap.volume.areaLights, config.areaLights);
  EXPECT_EQ(hub.reconstruction().areaLights, config.areaLights);
  EXPECT_EQ(hub.epoch(), epoch);
  producer.stop();
  hub.setAreaLightRule({});  // off: the probes hold every emitter again
  EXPECT_NE(hub.epoch(), epoch);
  ASSERT_TRUE(waitFor([&] { return client.snapshot(snap) && !snap.volume.areaLights.on(); }, 10s))
      << client.stats().lastError;
  EXPECT_GE(client.stats().connects, 2u);
  client.stop();
}

}  // namespace
}  // namespace probecast::service
