// The transport-free core of the service: the brick versions of one volume, and per subscriber
// what it holds, what it sees and what it may be sent. Frames are built from brick sections
// encoded once (the same bytes for every subscriber); a subscriber that falls behind gets the
// newest version (a keyframe when it skipped some), never a queue of stale ones.
//
// The versions come from a source: a producer's hub encodes them itself (publish), an edge's
// hub takes them from bus messages (receive) with the producer's epoch and version numbers, so
// a subscriber resumes on any edge with what it holds. Everything per subscriber is one code
// path for both.
#pragma once

#include <deque>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "probecast/codec/priority.h"
#include "probecast/codec/stream.h"
#include "probecast/service/bus_format.h"
#include "probecast/service/link_estimate.h"

namespace probecast::service {

using Clock = std::chrono::steady_clock;

struct HubConfig {
  StreamLayout layout;
  GridBounds bounds;
  EncoderOptions encoder;
  PriorityParams priority;
  double burstSeconds = 1.0;  // a subscriber's budget bucket holds this many seconds of bytes
  // Probe offsets as descriptions carry them (probe_offsets.h: 3 bytes per probe); empty = none.
  std::vector<int8_t> offsets;
  // The emitters the probes leave out for viewers to light (ProbeVolume::areaLights); none by default.
  AreaLightRule areaLights;
  // The scene the probes are traced in (hash and manifest; its time is the scene state's): what
  // every description names. Unknown by default.
  SceneStamp scene;
};

// The hub of a probe grid streamed as `repr` in bricks of brickDim³ probes, dropping changes of
// up to `deadzone` quantisation steps; check the layout with isValidLayout (a grid can be too
// large for the stream format).
HubConfig hubConfigFor(const ProbeGrid& grid, Representation repr, int brickDim = 4, int deadzone = 0);

// Whether a hub streaming `served` can give a subscriber `wanted`: the same, or a coarser one it
// makes from what it holds (fewer bytes per probe, or l1 from zh3h): transcoding never invents
// what the stream lacks.
bool canTranscode(Representation served, Representation wanted);

// A brick's new version as the producer hands it to the bus (bytes owned).
struct BrickVersionBytes {
  uint32_t brick = 0;
  uint32_t version = 0;
  uint32_t producerFrame = 0;
  uint64_t publishedUs = 0;  // when the lighting of this version was published (wall clock)
  float change = 0.0f;
  std::vector<uint8_t> keyframe, delta;
  bus::SceneState state;  // of the frame that made it
};

// The bus message fields of a version (its sections view `v`).
bus::Brick busBrick(const BrickVersionBytes& v);

// Tag of an edge's hub, fed from the bus.
struct FromBus {};

class BrickSource;
class EncoderBricks;
class TranscodedBricks;
class BusBricks;

struct HeldBrick {
  uint32_t brick = 0;
  uint32_t version = 0;
};

struct OutgoingFrame {
  uint32_t sequence = 0;
  uint64_t serverTimeUs = 0;  // when the newest lighting in it was published
  std::vector<uint8_t> payload;  // codec frame (empty when it was written to a FrameStorage)
  size_t payloadBytes = 0;       // its size
  uint32_t keyframes = 0;
  uint32_t deltas = 0;
  bus::SceneState state;  // the scene state of the newest lighting in it
  uint64_t sentUs = 0;    // wall clock when it was made, µs since 1970
};

// Where nextFrame writes a frame's payload instead of OutgoingFrame::payload: called under the
// hub's lock with the frame's other fields set and its payload's size, it returns storage for
// that many bytes (a transport's send buffer), written before nextFrame returns.
using FrameStorage = std::function<uint8_t*(const OutgoingFrame& frame, size_t payloadBytes)>;

struct SubscriberStats {
  uint64_t bytesSent = 0;
  uint32_t bricksBehind = 0;
  uint32_t framesSent = 0;
  uint32_t framesAcked = 0;  // the highest frame sequence the subscriber says it applied
  uint32_t ackRttUs = 0;     // frame handed to the network → its ack back, latest, microseconds
  bool paced = false;        // kept within its link (addSubscriber's `paced`)
  LinkStats link;            // the link as its acks show it (paced subscribers only)
};

class ProbeHub {
 public:
  // A producer's hub: it encodes the lighting it is given (publish).
  explicit ProbeHub(const HubConfig& config);
  // An edge's hub: volume, epoch and versions come from bus messages (receive); config's priority
  // and burst apply, its layout and encoder do not. Not ready() until the first message.
  ProbeHub(const HubConfig& config, FromBus);
  ~ProbeHub();

  bool ready() const;
  StreamLayout layout() const;
  GridBounds bounds() const;
  uint64_t epoch() const;
  // Layout, bounds, epoch, offsets and area light rule read together (an edge's change with the producer's epoch).
  // An edge is not ready() while its epoch announces offsets that have not arrived yet.
  bus::Volume volume() const;
  // A producer's probe offsets (ProbeVolume::offsets, metres, checkProbeOffsets's rules against
  // the hub's grid; std::invalid_argument otherwise), quantised as the wire carries them. A change
  // once the hub has published or has subscribers starts a new epoch: every stream ends, and
  // clients subscribe again and get the new description.
  void setProbeOffsets(const std::vector<float>& offsets);
  // A producer's scene (hash and manifest). A change once the hub has published or has
  // subscribers starts a new epoch, as for the offsets.
  void setScene(const SceneStamp& scene);
  // A producer's scene state for the publishes that follow (checkSceneState; std::invalid_argument
  // otherwise): every frame and bus message of their lighting carries it.
  void setSceneState(const bus::SceneState& state);
  // The state of the newest lighting (an edge's: of the newest producer frame received).
  bus::SceneState sceneState() const;
  // The scene descriptions name (hash and manifest; on an edge the manifest may still be on its way).
  SceneStamp scene() const;
  // A producer's client area light rule (checkAreaLightRule; std::invalid_argument otherwise). A
  // change once the hub has published or has subscribers starts a new epoch, as for the offsets:
  // light held by the old rule would be counted twice or lost by the new one.
  void setAreaLightRule(const AreaLightRule& rule);

  // A new lighting frame (27 floats per probe, sh.h layout; active mask or null; per-probe noise
  // and updates still or null, see EncoderOptions::noiseScale and refinementInterval). Each changed
  // brick gets a new version, encoded once. Wakes subscribers that wait for data. Producer hubs only
  // (std::logic_error on an edge's).
  void publish(const float* probes, const uint8_t* active, const float* noise = nullptr,
               const uint32_t* stillUpdates = nullptr);
  // The same for a volume (its noise and stillUpdates too, when it has them, and its offsets:
  // setProbeOffsets), which must pass checkProbeVolume and have the hub's grid size
  // (std::invalid_argument otherwise, nothing published). Its areaLights are not read: the rule is
  // the hub's (setAreaLightRule), as a traced volume's samples say nothing of it.
  void publish(const ProbeVolume& volume);
  // With the noise rule (EncoderOptions::noiseScale): how much the subscribers see of each probe,
  // for the publishes after it (StreamEncoder::setViewWeights: a probe nobody sees is held within
  // 4c·σ). Empty, or weights the encoder refuses (none positive: nobody looks at anything): every
  // probe alike. Producer hubs only.
  void setViewWeights(std::span<const float> weights);
  // Every brick version publish() makes, keyframe and delta, is handed to `output` (called on the
  // publishing thread, outside the hub's lock). Producer hubs only.
  using BusOutput = std::function<void(std::vector<BrickVersionBytes>)>;
  void setBusOutput(BusOutput output);
  // The current version of every brick that has one (for republishing everything). Producer hubs only.
  std::vector<BrickVersionBytes> currentBricks();

  // An edge's input: a parsed bus message. A new epoch (the producer restarted) resets the hub and
  // ends every subscriber's stream (streamEnded) so clients subscribe again. `wake` false defers
  // waking subscribers to the next message with it set, or to tick().
  enum class Received { Applied, Stale, NewEpoch, Refused };
  Received receive(const bus::Message& message, bool wake, std::string& why);
  // Wakes subscribers whose budget has refilled (call at the producer's rate when nothing changes).
  void tick();
  uint32_t serverFrame() const;

  // `wake` is called (never under the hub's lock) when the subscriber may have a frame to take.
  // `held` is honoured when `epoch` equals the epoch of the stream it subscribes to (resume),
  // ignored otherwise. `repr`: the representation it wants (none: the stream's); another one
  // (canTranscode, std::invalid_argument otherwise) is encoded by this hub from the volume it holds,
  // once for every subscriber that wants it, as a stream of its own epoch (volumeFor). It stays
  // for the epoch (at most one per representation), so a subscriber that reconnects resumes.
  // `paced`: the subscriber acks every frame as soon as it applies it, and the hub keeps its unacknowledged bytes within what its link delivers
  // (LinkEstimator): what the link cannot take yet waits here, where newer versions replace it and
  // priorities order it, instead of in the transport's buffers.
  uint64_t addSubscriber(uint64_t budgetBytesPerSecond, uint64_t epoch, std::span<const HeldBrick> held,
                         std::function<void()> wake, std::optional<Representation> repr = std::nullopt,
                         bool paced = false);
  // What a subscriber is told: volume(), with the representation and epoch of its stream.
  bus::Volume volumeFor(uint64_t id) const;
  void removeSubscriber(uint64_t id);
  void setViews(uint64_t id, std::vector<View> views);
  // Every view of every subscriber, one after another (what anyone may look at: the producer's
  // ray budget traces those probes first). Read-only.
  std::vector<View> subscriberViews() const;
  size_t subscriberCount() const;

  // The next frame for this subscriber: the bricks it lacks, best first, within its budget.
  // nullopt when it holds everything or its budget is spent (it is woken later).
  std::optional<OutgoingFrame> nextFrame(uint64_t id);
  // The same, its payload written to `storage` (the sections are copied once, into it).
  std::optional<OutgoingFrame> nextFrame(uint64_t id, const FrameStorage& storage);
  // The subscriber's stream should end: the volume it subscribed to was replaced (a new epoch).
  bool streamEnded(uint64_t id) const;
  SubscriberStats stats(uint64_t id) const;
  // The subscriber applied frames up to `sequence`. False (with the reason) for an ack of a frame
  // never sent or one that goes backwards: the client is broken and its stream should end. A paced
  // subscriber waiting for its window is woken (outside the hub's lock) when the ack opens it.
  bool acknowledge(uint64_t id, uint32_t sequence, std::string& why);

  // The volume every subscriber converges to (the encoder's reconstruction, or on an edge the
  // decoded bus versions; zh3h hallucinated per probe; offsets as subscribers reconstruct them),
  // for tests and tools.
  ProbeVolume reconstruction() const;
  // The same for the subscribers of `repr` (std::invalid_argument when no subscriber asked for it).
  ProbeVolume reconstruction(Representation repr);

 private:
  struct Subscriber {
    BrickSource* source = nullptr;  // source_, or a transcoded one (null once its stream ended)
    StreamLayout layout;            // of its stream
    uint64_t budget = 0;  // bytes per second, 0 = unlimited
    double tokens = 0;
    Clock::time_point refilled;
    std::vector<uint32_t> held;       // version per brick
    std::vector<uint32_t> staleSince;  // server frame when the held version became stale
    std::vector<View> views;
    std::function<void()> wake;
    bool waiting = false;
    bool ended = false;
    uint32_t sequence = 0;
    std::deque<std::pair<uint32_t, Clock::time_point>> unacked;  // sequence, when handed out
    bool paced = false;
    LinkEstimator link;
    SubscriberStats stats;
  };

  void refill(Subscriber& s, Clock::time_point now) const;
  // Whether every brick a subscriber lacks scores above 0 (then an unlimited budget takes them all).
  bool everyStaleBrickScores() const;
  // The frame of the first `n` bricks of chosen_ for `s` (who lacked `behind`), its state updated.
  // The payload goes to `storage` when there is one.
  // linkLimited: bricks were left for the link's window (the frame is not application-limited).
  OutgoingFrame buildFrame(Subscriber& s, size_t n, uint32_t behind, bool linkLimited, const FrameStorage* storage);
  std::vector<std::function<void()>> collectWakes();
  void markStale(uint32_t brick);
  ProbeVolume reconstructionLocked(const BrickSource& source) const;
  // The transcoded stream of `repr`, made (following source_) on first use.
  TranscodedBricks& transcodedFor(Representation repr);
  // Brings every transcoded stream up to source_'s current volume (after publish or receive).
  void followTranscoded();
  BrickVersionBytes versionBytes(uint32_t brick);
  EncoderBricks& encoderSource(const char* what) const;
  void startEpoch(const bus::Volume& volume, std::vector<std::function<void()>>& wakes);
  void endStreams(std::vector<std::function<void()>>& wakes);
  // After a change of what descriptions say: a new epoch when anyone may have been told the old.
  void describedAnew(std::vector<std::function<void()>>& wakes);

  HubConfig config_;
  uint64_t epoch_ = 0;
  bool fromBus_ = false;
  bool hasOffsets_ = false;   // what the epoch announces (config_.offsets may still be on its way to an edge)
  uint32_t offsetsCrc_ = 0;
  mutable std::mutex mutex_;
  std::unique_ptr<BrickSource> source_;
  EncoderBricks* encoder_ = nullptr;  // source_ of a producer's hub
  BusBricks* bus_ = nullptr;          // source_ of an edge's hub
  std::map<Representation, std::unique_ptr<TranscodedBricks>> transcoded_;  // for this epoch
  bool transcodedBehind_ = false;     // source_ moved since they followed it
  BusOutput busOutput_;
  std::vector<uint32_t> lastOutput_;  // version last handed to busOutput_, per brick
  uint32_t frame_ = 0;
  uint64_t publishedUs_ = 0;
  bus::SceneState state_;
  uint32_t stateFrame_ = 0;  // an edge's: the producer frame state_ is of
  uint64_t nextId_ = 1;
  std::map<uint64_t, Subscriber> subscribers_;
  std::vector<BrickCandidate> candidates_;
  std::vector<float> scores_;
  std::vector<uint32_t> chosen_;
};

}  // namespace probecast::service
