// Light subscribers for load tests: many Subscribe streams in one process on gRPC's callback API
// over a few channels, so that the load costs little next to the server it measures. Each stream
// says hello, sends a view set and acks what it gets; per frame it checks that the sequence goes
// up by one and that the codec container is intact (header and section CRCs, without decoding),
// counts bytes and records produce → receive latency (the frame's server_time_us against this
// machine's system clock: same machine only). A sample of the subscribers decodes every frame in
// full, so the bench can check that what they hold is bit for bit the producer's reconstruction.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "probecast/codec/priority.h"
#include "probecast/service/latency_histogram.h"

namespace probecast::bench {

struct LoadClientConfig {
  // Subscriber i (global index) connects to addresses[i % addresses.size()].
  std::vector<std::string> addresses;
  std::string token;
  uint32_t firstIndex = 0;         // global index of this client's first subscriber
  uint32_t subscribers = 1;
  uint32_t channelsPerAddress = 2;  // separate connections per address, streams spread over them
  uint32_t sampleEvery = 50;       // subscribers whose global index is a multiple of this decode fully
  uint64_t budgetBytesPerSecond = 0;  // per subscriber, 0 = unlimited
  std::function<View(uint32_t index)> view;  // the view of subscriber `index` (null: no view set)
  uint32_t ackIntervalMs = 100;    // acks of the newest frame at most this often, as ProbeClient's (0: every frame)
  bool linkPacing = true;          // ack every frame, as ProbeClient (the server paces it)
};

struct LoadFigures {
  uint64_t frames = 0;
  uint64_t bytes = 0;           // frame payload bytes
  uint64_t sequenceErrors = 0;  // a frame whose sequence is not the previous one plus one
  uint64_t crcErrors = 0;       // a frame whose container check (verifyFrame) failed
  uint64_t decodeErrors = 0;    // a frame a decoding subscriber's StreamDecoder refused
  uint64_t streamErrors = 0;    // streams that ended with an error we did not cause
  service::LatencyHistogram latency;  // produce → receive, microseconds
  std::string lastError;
};

struct SampleCheck {
  uint32_t sampled = 0;    // subscribers that decode
  uint32_t identical = 0;  // of those, the ones holding exactly the expected volume
};

class LoadClient {
 public:
  // Throws std::invalid_argument for an empty address list or no subscribers.
  explicit LoadClient(const LoadClientConfig& config);
  ~LoadClient();  // stops
  LoadClient(const LoadClient&) = delete;
  LoadClient& operator=(const LoadClient&) = delete;

  void start();
  // Waits until every subscriber has had its volume description, or `timeout`; how many have.
  uint32_t waitConnected(std::chrono::milliseconds timeout);
  // The figures since start() or the previous take(), which starts a new count.
  LoadFigures take();
  // Waits up to `timeout` for every decoding subscriber to hold a volume whose volumeHash is `expected`.
  SampleCheck checkSamples(uint64_t expected, std::chrono::milliseconds timeout);
  // Cancels every stream and waits for them to end.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// FNV-1a (64 bit) over the bytes of `count` probes (27 floats each) and their active flags: what
// two processes compare to know they hold bit-identical volumes.
uint64_t volumeHash(const float* probes, const uint8_t* active, size_t count);

}  // namespace probecast::bench
