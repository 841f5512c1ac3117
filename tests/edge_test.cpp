// The probe bus end to end with a real nats-server started by the test: a producer publishing to
// JetStream, edge servers fed from it, clients over loopback gRPC failing over between edges.
// Every wait is bounded; every test stops what it started.
#include <gtest/gtest.h>

#include <nats/nats.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <random>
#include <thread>

#include "probecast/service/bus_format.h"
#include "probecast/service/bus_nats.h"
#include "probecast/service/client.h"
#include "probecast/service/edge_server.h"
#include "probecast/testing/edge_process.h"
#include "probecast/testing/nats_server.h"
#include "service_test_support.h"
#include "test_probes.h"

namespace probecast::service {
namespace {

// A producer's hub publishing to the bus, lit by a moving light.
struct BusProducer {
  ProbeHub hub{volumeConfig()};
  BusPublisher publisher;
  std::mt19937 rng{5};
  int frame = 0;
  explicit BusProducer(const BusConfig& bus) : publisher(bus, hub) {}
  void publish(int frames, std::chrono::milliseconds interval = 20ms) {
    for (int f = 0; f < frames; ++f) {
      hub.publish(test::movingLightFrame(1024, frame++, 0.01f, rng).data(), nullptr);
      std::this_thread::sleep_for(interval);
    }
  }
  bool caughtUp() { return waitFor([&] { return publisher.caughtUp(); }, 10s); }
};

class Edge : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(testing::NatsServer::findProgram().empty())
        << "nats-server is a dependency of these tests (scripts/setup.sh installs it): not on PATH, in /usr/sbin "
           "or /usr/bin";
    nats = std::make_unique<testing::NatsServer>();
    static int tests = 0;
    bus = nats->bus("edge-test-" + std::to_string(++tests));
  }

  // A plain NATS connection to the test's server (as another program on the bus would make).
  natsConnection* connectRaw() const {
    natsConnection* nc = nullptr;
    const std::string url = "nats://" + nats->token() + "@127.0.0.1:" + std::to_string(nats->port());
    EXPECT_EQ(natsConnection_ConnectTo(&nc, url.c_str()), NATS_OK);
    return nc;
  }

  EdgeConfig edgeConfig() const {
    EdgeConfig c;
    c.bus = bus;
    c.server.listen = "127.0.0.1:0";
    c.server.token = kToken;
    c.server.plaintext = true;
    return c;
  }

  ClientConfig clientFor(std::vector<int> ports) const {
    ClientConfig c;
    for (int p : ports) c.addresses.push_back("127.0.0.1:" + std::to_string(p));
    c.token = kToken;
    c.reconnectMaxMs = 200;
    return c;
  }

  std::unique_ptr<testing::NatsServer> nats;
  BusConfig bus;
};

TEST_F(Edge, SubscribersOnTwoEdgesEndBitIdenticalToTheProducer) {
  BusProducer producer(bus);
  EdgeServer a(edgeConfig()), b(edgeConfig());
  std::vector<std::unique_ptr<ProbeClient>> clients;
  for (int i = 0; i < 6; ++i) {
    clients.push_back(std::make_unique<ProbeClient>(clientFor({i % 2 ? b.port() : a.port()})));
    clients.back()->start();
  }
  producer.publish(30);
  for (size_t i = 0; i < clients.size(); ++i)
    EXPECT_TRUE(waitFor([&] { return matchesServer(*clients[i], producer.hub); }, 10s)) << "client " << i;
  for (auto& c : clients) EXPECT_EQ(c->stats().framesRejected, 0u);
  EXPECT_EQ(a.hub().epoch(), producer.hub.epoch());
  EXPECT_EQ(a.stats().refused, 0u);
  EXPECT_GE(a.stats().applied, 16u);
}

TEST_F(Edge, AnEdgeShutDownMidStreamItsSubscribersResumeOnTheOtherWithoutAKeyframeStorm) {
  BusProducer producer(bus);
  auto a = std::make_unique<EdgeServer>(edgeConfig());
  EdgeServer b(edgeConfig());
  const std::string onA = "127.0.0.1:" + std::to_string(a->port()), onB = "127.0.0.1:" + std::to_string(b.port());
  producer.publish(1);  // edges without a volume answer UNAVAILABLE: the clients would start elsewhere
  ASSERT_TRUE(waitFor([&] { return a->hub().ready() && b.hub().ready(); }, 10s));
  std::vector<std::unique_ptr<ProbeClient>> clients;
  for (int i = 0; i < 4; ++i) {
    clients.push_back(std::make_unique<ProbeClient>(clientFor({a->port(), b.port()})));
    clients.back()->start();
  }
  producer.publish(20);
  for (auto& c : clients) {
    ASSERT_TRUE(waitFor([&] { return matchesServer(*c, producer.hub); }, 10s));
    ASSERT_EQ(c->stats().address, onA);
  }
  // What a subscriber that holds nothing needs: every brick's keyframe.
  ProbeHub& hub = producer.hub;
  const uint64_t fresh = hub.addSubscriber(0, 0, {}, nullptr);
  const size_t keyframeSet = hub.nextFrame(fresh)->payload.size();
  hub.removeSubscriber(fresh);
  std::vector<ClientStats> before;
  for (auto& c : clients) before.push_back(c->stats());

  a->shutdown();
  for (size_t i = 0; i < clients.size(); ++i) {
    ProbeClient& c = *clients[i];
    ASSERT_TRUE(waitFor([&] { return c.stats().connected && c.stats().address == onB; }, 10s)) << i;
    // Resumed with its epoch and held versions: nothing to send, let alone a keyframe set.
    EXPECT_TRUE(matchesServer(c, producer.hub));
    EXPECT_LT(c.stats().bytesReceived - before[i].bytesReceived, keyframeSet / 2)
        << "client " << i << " of a " << keyframeSet << "-byte keyframe set";
  }
  producer.publish(3);  // the stream goes on from the other edge, in deltas
  for (size_t i = 0; i < clients.size(); ++i) {
    ProbeClient& c = *clients[i];
    EXPECT_TRUE(waitFor([&] { return matchesServer(c, producer.hub); }, 10s)) << i;
    const ClientStats st = c.stats();
    EXPECT_EQ(st.connects, 2u);
    EXPECT_GE(st.failovers, 1u);
    EXPECT_EQ(st.framesRejected, 0u);
    // A brick version the publisher replaced by a newer one before it went out (a slow bus) has
    // no delta on the bus, so a holder one behind gets that brick's keyframe: a few, not a storm.
    EXPECT_LE(st.keyframesReceived - before[i].keyframesReceived, 2u)
        << "client " << i << "; versions superseded before publishing: " << producer.publisher.stats().superseded;
    EXPECT_GT(st.deltasReceived, before[i].deltasReceived) << "client " << i;
  }
}

// An edge that hangs (SIGSTOP) keeps its TCP connections open and sends nothing: only keepalive
// pings notice. Its subscribers must fail over to the other edge, not wait forever.
TEST_F(Edge, AFrozenEdgeIsNoticedByKeepaliveAndItsSubscribersFailOver) {
  EdgeConfig fast = edgeConfig();
  fast.server.minClientPingMs = 100;
  // The edge process is forked from this one: before any NATS client thread runs here (one
  // holding a library lock at the fork would leave it held in the child for good).
  testing::EdgeProcess a(fast);
  const int portA = a.start();
  BusProducer producer(bus);
  EdgeServer b(fast);
  const std::string onA = "127.0.0.1:" + std::to_string(portA), onB = "127.0.0.1:" + std::to_string(b.port());
  producer.publish(1);
  ProbeClient probe(clientFor({portA}));  // the edge process serves once it holds the volume
  probe.start();
  ASSERT_TRUE(waitFor([&] { return matchesServer(probe, producer.hub); }, 10s));
  probe.stop();
  ClientConfig cc = clientFor({portA, b.port()});
  cc.keepaliveMs = 200;
  cc.keepaliveTimeoutMs = 500;
  ProbeClient client(cc);
  client.start();
  producer.publish(5);
  ASSERT_TRUE(waitFor([&] { return matchesServer(client, producer.hub); }, 10s));
  ASSERT_EQ(client.stats().address, onA);
  a.freeze();
  producer.publish(5);
  EXPECT_TRUE(waitFor([&] { return client.stats().connected && client.stats().address == onB; }, 10s))
      << client.stats().lastError;
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, producer.hub); }, 10s));
  EXPECT_GE(client.stats().failovers, 1u);
  a.thaw();
}

TEST_F(Edge, NatsServerRestartedEdgesAndProducerRecoverAndSubscribersConverge) {
  BusProducer producer(bus);
  EdgeServer a(edgeConfig()), b(edgeConfig());
  ProbeClient onA(clientFor({a.port()})), onB(clientFor({b.port()}));
  onA.start();
  onB.start();
  producer.publish(10);
  ASSERT_TRUE(waitFor([&] { return matchesServer(onA, producer.hub) && matchesServer(onB, producer.hub); }, 10s));
  nats->stop();
  producer.publish(10);  // lighting moves on while the bus is away
  EXPECT_FALSE(matchesServer(onA, producer.hub));
  nats->start();
  producer.publish(5);
  EXPECT_TRUE(waitFor([&] { return matchesServer(onA, producer.hub) && matchesServer(onB, producer.hub); }, 15s))
      << "edge a: " << a.stats().lastError << "; producer: " << producer.publisher.stats().lastError;
  EXPECT_GE(producer.publisher.stats().resyncs, 2u);
  EXPECT_GE(a.stats().subscribes, 2u);
  EXPECT_EQ(onA.stats().framesRejected, 0u);
}

TEST_F(Edge, AnEdgeStartedLateServesFromTheRetainedMessages) {
  BusProducer producer(bus);
  producer.publish(15, 5ms);
  ASSERT_TRUE(producer.caughtUp());
  EdgeServer late(edgeConfig());  // everything it gets was published before it existed
  ProbeClient client(clientFor({late.port()}));
  client.start();
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, producer.hub); }, 10s)) << late.stats().lastError;
  EXPECT_EQ(late.stats().epochs, 1u);
}

TEST_F(Edge, MalformedBusMessagesAreRefusedNotAppliedAndTheStreamGoesOn) {
  BusProducer producer(bus);
  EdgeServer edge(edgeConfig());
  ProbeClient client(clientFor({edge.port()}));
  client.start();
  producer.publish(5);
  ASSERT_TRUE(waitFor([&] { return matchesServer(client, producer.hub); }, 10s));
  const uint64_t refusedBefore = edge.stats().refused;
  // Garbage, a valid message cut short, and one with a flipped byte, on a brick's subject.
  natsConnection* nc = connectRaw();
  ASSERT_NE(nc, nullptr);
  std::vector<uint8_t> valid;
  const ProbeHub& hub = producer.hub;
  bus::writeVolumeMessage(hub.volume(), 0, valid);
  std::vector<uint8_t> cut(valid.begin(), valid.end() - 5), flipped = valid;
  flipped[30] ^= 1;
  // Each on a subject of its own: the stream keeps only the newest message of a subject.
  uint32_t brick = 3;
  for (const std::vector<uint8_t>& m : {std::vector<uint8_t>{'j', 'u', 'n', 'k'}, cut, flipped}) {
    const std::string subject = brickSubject(bus.stream, brick++);
    ASSERT_EQ(natsConnection_Publish(nc, subject.c_str(), m.data(), static_cast<int>(m.size())), NATS_OK);
  }
  ASSERT_EQ(natsConnection_FlushTimeout(nc, 2000), NATS_OK);
  natsConnection_Destroy(nc);
  EXPECT_TRUE(waitFor([&] { return edge.stats().refused >= refusedBefore + 3; }, 5s))
      << edge.stats().received << " received, " << edge.stats().refused << " refused, " << edge.stats().lastError;
  EXPECT_NE(edge.stats().lastError.find("refused"), std::string::npos) << edge.stats().lastError;
  EXPECT_TRUE(matchesServer(client, producer.hub));
  producer.publish(3);
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, producer.hub); }, 10s));
  EXPECT_EQ(client.stats().framesRejected, 0u);
  EXPECT_EQ(client.stats().connects, 1u);
}

TEST_F(Edge, ARestartedProducerIsANewEpochEdgesEndTheirStreamsAndClientsConvergeAgain) {
  EdgeServer edge(edgeConfig());
  ProbeClient client(clientFor({edge.port()}));
  client.start();
  uint64_t firstEpoch = 0;
  {
    BusProducer first(bus);
    first.publish(5);
    ASSERT_TRUE(waitFor([&] { return matchesServer(client, first.hub); }, 10s));
    firstEpoch = first.hub.epoch();
  }
  BusProducer second(bus);
  second.rng.seed(77);  // other lighting
  second.publish(5);
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, second.hub); }, 10s)) << edge.stats().lastError;
  EXPECT_NE(second.hub.epoch(), firstEpoch);
  EXPECT_EQ(edge.hub().epoch(), second.hub.epoch());
  EXPECT_GE(client.stats().connects, 2u);  // its stream was ended and it subscribed again
  EXPECT_EQ(client.stats().framesRejected, 0u);
}

TEST_F(Edge, ASecondProducerOnALiveStreamIsDisplacedAndTheFirstsVolumeStays) {
  // Two producers started on one stream name by mistake: without the claim the second purged the
  // first's bricks and both overwrote each other's. Now the second sees the first renew its claim
  // and stops without touching the stream; the edge's subscribers keep the first's volume.
  bus.claimRenewMs = 200;
  EdgeServer edge(edgeConfig());
  ProbeClient client(clientFor({edge.port()}));
  client.start();
  BusProducer first(bus);
  first.publish(5);
  ASSERT_TRUE(waitFor([&] { return matchesServer(client, first.hub); }, 10s));
  BusProducer second(bus);
  second.rng.seed(77);  // other lighting
  second.publish(3);
  const auto displaced = [&] { return second.publisher.stats().displaced; };
  for (int i = 0; i < 100 && !displaced(); ++i) first.publish(1, 50ms);  // the first keeps renewing
  ASSERT_TRUE(displaced());
  EXPECT_NE(second.publisher.stats().lastError.find("has a live producer"), std::string::npos)
      << second.publisher.stats().lastError;
  EXPECT_EQ(second.publisher.stats().messages, 0u);
  EXPECT_FALSE(second.publisher.caughtUp());
  second.publish(3);  // a displaced producer's new versions go nowhere
  first.publish(5);
  ASSERT_TRUE(first.caughtUp()) << first.publisher.stats().lastError;
  EXPECT_FALSE(first.publisher.stats().displaced);
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, first.hub); }, 10s)) << edge.stats().lastError;
  EXPECT_EQ(edge.hub().epoch(), first.hub.epoch());
  EXPECT_EQ(client.stats().framesRejected, 0u);
}

TEST_F(Edge, AProducerWhoseClaimIsTakenOverStopsPublishing) {
  // A producer cut off from the bus for longer than its claim lasts may find, on its return, that
  // another producer took the stream over: it must stop, not overwrite the new owner's bricks.
  bus.claimRenewMs = 200;
  BusProducer first(bus);
  first.publish(3);
  ASSERT_TRUE(first.caughtUp());
  // Another producer's claim, as one would publish it after taking over.
  natsConnection* nc = connectRaw();
  ASSERT_NE(nc, nullptr);
  jsCtx* js = nullptr;
  ASSERT_EQ(natsConnection_JetStream(&js, nc, nullptr), NATS_OK);
  const std::string other = "probecast producer elsewhere";
  jsPubAck* ack = nullptr;
  ASSERT_EQ(js_Publish(&ack, js, producerSubject(bus.stream).c_str(), other.data(), static_cast<int>(other.size()),
                       nullptr, nullptr),
            NATS_OK);
  jsPubAck_Destroy(ack);
  jsCtx_Destroy(js);
  natsConnection_Destroy(nc);
  EXPECT_TRUE(waitFor([&] { return first.publisher.stats().displaced; }, 5s));
  EXPECT_NE(first.publisher.stats().lastError.find("took stream"), std::string::npos)
      << first.publisher.stats().lastError;
  const uint64_t sent = first.publisher.stats().messages;
  first.publish(3);
  std::this_thread::sleep_for(300ms);
  EXPECT_EQ(first.publisher.stats().messages, sent);
}

}  // namespace
}  // namespace probecast::service

namespace probecast::service {
namespace {

// A bus link is never open by accident: credentials and TLS, or their absence said outright.
TEST(BusConfigCheck, CredentialsAndTlsOrTheirAbsenceSaidOutright) {
  BusConfig c;
  c.token = "t0k";
  c.plaintext = true;
  std::string why;
  EXPECT_TRUE(checkBusConfig(c, why)) << why;
  BusConfig open = c;
  open.token.clear();
  EXPECT_FALSE(checkBusConfig(open, why));
  EXPECT_NE(why.find("no credentials"), std::string::npos) << why;
  open.noAuth = true;
  EXPECT_TRUE(checkBusConfig(open, why)) << why;
  BusConfig both = c;
  both.credsFile = "user.creds";
  EXPECT_FALSE(checkBusConfig(both, why));
  BusConfig contradiction = c;
  contradiction.noAuth = true;
  EXPECT_FALSE(checkBusConfig(contradiction, why));
  BusConfig spaced = c;
  spaced.token = "two words";
  EXPECT_FALSE(checkBusConfig(spaced, why));
  BusConfig clear = c;
  clear.plaintext = false;
  EXPECT_FALSE(checkBusConfig(clear, why));
  EXPECT_NE(why.find("without TLS"), std::string::npos) << why;
  clear.tls = true;
  EXPECT_TRUE(checkBusConfig(clear, why)) << why;
  clear.plaintext = true;
  EXPECT_FALSE(checkBusConfig(clear, why));
  BusConfig caAlone = c;
  caAlone.caFile = "ca.pem";
  EXPECT_FALSE(checkBusConfig(caAlone, why));
  // The defaults ask for neither: a producer refuses them before touching the network.
  ProbeHub hub(volumeConfig());
  EXPECT_THROW(BusPublisher(BusConfig{}, hub), std::invalid_argument);
}

TEST_F(Edge, ALinkTheBusRefusesFailsAtOnceSayingWhyAndAnAbsentBusIsReported) {
  BusConfig wrong = bus;
  wrong.token = "not-the-token";
  ProbeHub hub(volumeConfig());
  try {
    BusPublisher publisher(wrong, hub);
    ADD_FAILURE() << "a producer with the wrong token started";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("Authorization Violation"), std::string::npos) << e.what();
  }
  EdgeConfig ec = edgeConfig();
  ec.bus = wrong;
  EXPECT_THROW(EdgeServer{ec}, std::runtime_error);
  BusConfig clear = bus;  // this server speaks plaintext only
  clear.plaintext = false;
  clear.tls = true;
  EXPECT_THROW(BusPublisher(clear, hub), std::runtime_error);
  // No server at all is not a refusal: the link keeps trying, and its stats say why it is down.
  BusConfig absent = bus;
  absent.url = "nats://127.0.0.1:1";  // a privileged port nothing here listens on (a free one could be taken meanwhile)
  BusPublisher waiting(absent, hub);
  EXPECT_FALSE(waiting.stats().connected);
  EXPECT_NE(waiting.stats().lastError.find("No server"), std::string::npos) << waiting.stats().lastError;
}

// The bus over TLS: a producer and an edge that trust the server's certificate carry the stream
// bit for bit; a plaintext link, or one that does not trust the certificate, is refused.
TEST(EdgeTls, ABusOverTlsCarriesTheStreamAndUntrustedOrPlaintextLinksAreRefused) {
  std::string key, cert;
  ASSERT_TRUE(makeTestCertificate(PROBECAST_TEST_TMP, "nats-tls", key, cert)) << "openssl could not make a test certificate";
  testing::NatsServerOptions no;
  no.tlsCert = cert;
  no.tlsKey = key;
  testing::NatsServer nats(no);
  const BusConfig bus = nats.bus("edge-tls");
  ASSERT_TRUE(bus.tls);
  BusConfig plain = bus;
  plain.tls = false;
  plain.caFile.clear();
  plain.plaintext = true;
  ProbeHub hub(volumeConfig());
  EXPECT_THROW(BusPublisher(plain, hub), std::runtime_error);
  BusConfig untrusting = bus;
  untrusting.caFile.clear();  // the system's roots do not know a self-signed certificate
  EXPECT_THROW(BusPublisher(untrusting, hub), std::runtime_error);

  BusProducer producer(bus);
  EdgeConfig ec;
  ec.bus = bus;
  ec.server.listen = "127.0.0.1:0";
  ec.server.token = kToken;
  ec.server.plaintext = true;
  EdgeServer edge(ec);
  ClientConfig cc;
  cc.address = "127.0.0.1:" + std::to_string(edge.port());
  cc.token = kToken;
  ProbeClient client(cc);
  client.start();
  producer.publish(5);
  EXPECT_TRUE(waitFor([&] { return matchesServer(client, producer.hub); }, 10s));
}

}  // namespace
}  // namespace probecast::service
