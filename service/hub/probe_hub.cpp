#include "probecast/service/probe_hub.h"

#include <algorithm>
#include <random>
#include <stdexcept>

#include "brick_source.h"
#include "probecast/codec/probe_offsets.h"

namespace probecast::service {
namespace {

uint64_t nowUs() {
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

uint64_t randomEpoch() {
  std::random_device rd;
  return (static_cast<uint64_t>(rd()) << 32 | rd()) | 1u;  // never 0 ("no epoch")
}

bool sameVolume(const bus::Volume& a, const StreamLayout& layout, const GridBounds& bounds, bool hasOffsets,
                uint32_t offsetsCrc, const AreaLightRule& areaLights, const SceneStamp& scene) {
  const StreamLayout& l = a.layout;
  bool same = l.repr == layout.repr && l.brickDim == layout.brickDim && a.hasOffsets == hasOffsets &&
              a.offsetsCrc == offsetsCrc && a.areaLights == areaLights && a.sceneHash == scene.hash;
  for (int i = 0; i < 3; ++i)
    same = same && l.grid[i] == layout.grid[i] && a.bounds.min[i] == bounds.min[i] && a.bounds.max[i] == bounds.max[i];
  return same;
}

}  // namespace

bool canTranscode(Representation served, Representation wanted) {
  if (wanted == served) return true;
  if (served == Representation::Zh3Hallucinated) return wanted == Representation::L1;
  return recordSize(wanted) < recordSize(served);
}

bus::Brick busBrick(const BrickVersionBytes& v) {
  bus::Brick b;
  b.brick = v.brick;
  b.version = v.version;
  b.producerFrame = v.producerFrame;
  b.change = v.change;
  b.keyframe = v.keyframe;
  b.delta = v.delta;
  b.state = v.state;
  return b;
}

ProbeHub::ProbeHub(const HubConfig& config) : config_(config), epoch_(randomEpoch()) {
  std::string error;
  if (!checkAreaLightRule(config.areaLights, error)) throw std::invalid_argument(error);
  hasOffsets_ = !config.offsets.empty();
  offsetsCrc_ = bus::offsetsChecksum(config.offsets);
  auto source = std::make_unique<EncoderBricks>(config.layout, config.encoder);
  encoder_ = source.get();
  source_ = std::move(source);
}

ProbeHub::ProbeHub(const HubConfig& config, FromBus) : config_(config), fromBus_(true) {}

ProbeHub::~ProbeHub() = default;

bool ProbeHub::ready() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return source_ != nullptr && (!hasOffsets_ || !config_.offsets.empty()) &&
         (config_.scene.hash == SceneStamp{}.hash || config_.scene.known());
}

StreamLayout ProbeHub::layout() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return config_.layout;
}

GridBounds ProbeHub::bounds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return config_.bounds;
}

uint64_t ProbeHub::epoch() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return epoch_;
}

bus::Volume ProbeHub::volume() const {
  std::lock_guard<std::mutex> lock(mutex_);
  bus::Volume v;
  v.epoch = epoch_;
  v.publishedUs = publishedUs_;
  v.layout = config_.layout;
  v.bounds = config_.bounds;
  v.offsets = config_.offsets;
  v.hasOffsets = hasOffsets_;
  v.offsetsCrc = offsetsCrc_;
  v.areaLights = config_.areaLights;
  v.sceneHash = config_.scene.hash;
  v.sceneManifest = config_.scene.manifest;
  return v;
}

void ProbeHub::setScene(const SceneStamp& scene) {
  std::vector<std::function<void()>> wakes;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    encoderSource("setScene");
    if (scene.hash == config_.scene.hash && scene.manifest == config_.scene.manifest) return;
    config_.scene.hash = scene.hash;
    config_.scene.manifest = scene.manifest;
    describedAnew(wakes);
  }
  for (auto& w : wakes) w();
}

void ProbeHub::setSceneState(const bus::SceneState& state) {
  std::string why;
  if (!bus::checkSceneState(state, why)) throw std::invalid_argument(why);
  std::lock_guard<std::mutex> lock(mutex_);
  encoderSource("setSceneState");
  state_ = state;
}

bus::SceneState ProbeHub::sceneState() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_;
}

SceneStamp ProbeHub::scene() const {
  std::lock_guard<std::mutex> lock(mutex_);
  SceneStamp s = config_.scene;
  s.time = state_.time;
  return s;
}

void ProbeHub::setProbeOffsets(const std::vector<float>& offsets) {
  std::vector<std::function<void()>> wakes;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    encoderSource("setProbeOffsets");
    const ProbeGrid grid = gridOf(config_.layout, config_.bounds);
    std::string error;
    if (!checkProbeOffsets(grid, offsets, error)) throw std::invalid_argument(error);
    std::vector<int8_t> q = quantizeProbeOffsets(grid, offsets);
    if (q == config_.offsets) return;
    config_.offsets = std::move(q);
    hasOffsets_ = !config_.offsets.empty();
    offsetsCrc_ = bus::offsetsChecksum(config_.offsets);
    describedAnew(wakes);
  }
  for (auto& w : wakes) w();
}

void ProbeHub::setAreaLightRule(const AreaLightRule& rule) {
  std::vector<std::function<void()>> wakes;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    encoderSource("setAreaLightRule");
    std::string error;
    if (!checkAreaLightRule(rule, error)) throw std::invalid_argument(error);
    if (rule == config_.areaLights) return;
    config_.areaLights = rule;
    describedAnew(wakes);
  }
  for (auto& w : wakes) w();
}

void ProbeHub::describedAnew(std::vector<std::function<void()>>& wakes) {
  if (frame_ > 0 || !subscribers_.empty()) {  // what viewers were told no longer holds
    epoch_ = randomEpoch();
    endStreams(wakes);
    transcoded_.clear();  // their epochs end with the stream's
    transcodedBehind_ = false;
  }
}

EncoderBricks& ProbeHub::encoderSource(const char* what) const {
  if (!encoder_) throw std::logic_error(std::string(what) + " is for a producer's hub; an edge's takes the bus");
  return *encoder_;
}

HubConfig hubConfigFor(const ProbeGrid& grid, Representation repr, int brickDim, int deadzone) {
  HubConfig c;  // an edge out of the uint8_t range becomes 0, which isValidLayout refuses
  c.layout = streamLayoutFor(grid, repr, brickDim >= 0 && brickDim <= 255 ? static_cast<uint8_t>(brickDim) : 0);
  c.bounds = grid.bounds;
  c.encoder.deadzone = deadzone;
  return c;
}

void ProbeHub::publish(const ProbeVolume& volume) {
  std::string error;
  if (!checkProbeVolume(volume, error)) throw std::invalid_argument(error);
  for (int a = 0; a < 3; ++a)
    if (volume.grid.dims[a] != config_.layout.grid[a])
      throw std::invalid_argument("published volume's grid differs from the hub's");
  setProbeOffsets(volume.offsets);
  publish(volume.probes.data(), volume.active.data(), volume.noise.empty() ? nullptr : volume.noise.data(),
          volume.stillUpdates.empty() ? nullptr : volume.stillUpdates.data());
}

void ProbeHub::setViewWeights(std::span<const float> weights) {
  std::lock_guard<std::mutex> lock(mutex_);
  StreamEncoder& encoder = encoderSource("setViewWeights").encoder();
  if (!encoder.setViewWeights(weights)) encoder.setViewWeights({});
}

void ProbeHub::publish(const float* probes, const uint8_t* active, const float* noise, const uint32_t* stillUpdates) {
  std::vector<std::function<void()>> wakes;
  std::vector<BrickVersionBytes> made;
  BusOutput output;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    encoderSource("publish").encoder().update(probes, active, noise, stillUpdates);
    ++frame_;
    publishedUs_ = nowUs();
    transcodedBehind_ = !transcoded_.empty();
    const uint32_t bricks = brickCount(config_.layout);
    for (uint32_t b = 0; b < bricks; ++b) markStale(b);
    if (busOutput_) {
      lastOutput_.resize(bricks, 0);
      for (uint32_t b = 0; b < bricks; ++b)
        if (source_->version(b) != lastOutput_[b]) {
          made.push_back(versionBytes(b));
          lastOutput_[b] = source_->version(b);
        }
      output = busOutput_;
    }
    wakes = collectWakes();
  }
  if (output && !made.empty()) output(std::move(made));
  for (auto& w : wakes) w();
}

void ProbeHub::markStale(uint32_t brick) {
  for (auto& [id, s] : subscribers_)
    if (!s.ended && s.held[brick] < s.source->version(brick) && s.staleSince[brick] == UINT32_MAX)
      s.staleSince[brick] = frame_;
}

TranscodedBricks& ProbeHub::transcodedFor(Representation repr) {
  std::unique_ptr<TranscodedBricks>& t = transcoded_[repr];
  if (!t) {
    StreamLayout layout = config_.layout;
    layout.repr = repr;
    EncoderOptions options = config_.encoder;
    options.noiseScale = 0.0f;  // the primary's noise rule already held what noise explains
    t = std::make_unique<TranscodedBricks>(layout, options, randomEpoch());
    t->follow(*source_, config_.bounds);
  }
  return *t;
}

void ProbeHub::followTranscoded() {
  if (!transcodedBehind_) return;
  transcodedBehind_ = false;
  bool changed = false;
  for (auto& [repr, t] : transcoded_) changed = t->follow(*source_, config_.bounds) > 0 || changed;
  if (changed)
    for (uint32_t b = 0; b < brickCount(config_.layout); ++b) markStale(b);
}

BrickVersionBytes ProbeHub::versionBytes(uint32_t brick) {
  StreamEncoder& e = encoder_->encoder();
  BrickVersionBytes v;
  v.brick = brick;
  v.version = e.brickVersion(brick);
  v.producerFrame = frame_;
  v.publishedUs = publishedUs_;
  v.change = e.brickChange(brick);
  v.state = state_;
  const std::span<const uint8_t> key = e.keyframeSection(brick), delta = e.deltaSection(brick);
  v.keyframe.assign(key.begin(), key.end());
  v.delta.assign(delta.begin(), delta.end());
  return v;
}

void ProbeHub::setBusOutput(BusOutput output) {
  std::lock_guard<std::mutex> lock(mutex_);
  encoderSource("setBusOutput");
  busOutput_ = std::move(output);
  lastOutput_.assign(brickCount(config_.layout), 0);
  for (uint32_t b = 0; b < lastOutput_.size(); ++b) lastOutput_[b] = source_->version(b);
}

std::vector<BrickVersionBytes> ProbeHub::currentBricks() {
  std::lock_guard<std::mutex> lock(mutex_);
  encoderSource("currentBricks");
  std::vector<BrickVersionBytes> all;
  for (uint32_t b = 0; b < brickCount(config_.layout); ++b)
    if (source_->version(b) != 0) all.push_back(versionBytes(b));
  return all;
}

void ProbeHub::startEpoch(const bus::Volume& volume, std::vector<std::function<void()>>& wakes) {
  config_.layout = volume.layout;
  config_.bounds = volume.bounds;
  config_.offsets = volume.offsets;  // none yet when a brick message opens the epoch: the volume message brings them
  hasOffsets_ = volume.hasOffsets;
  offsetsCrc_ = volume.offsetsCrc;
  config_.areaLights = volume.areaLights;
  config_.scene.hash = volume.sceneHash;
  config_.scene.manifest = volume.sceneManifest;  // none yet when a brick message opens the epoch
  state_ = {};
  stateFrame_ = 0;
  epoch_ = volume.epoch;
  auto source = std::make_unique<BusBricks>(volume.layout);
  bus_ = source.get();
  endStreams(wakes);  // before the sources their subscribers point at go
  transcoded_.clear();
  transcodedBehind_ = false;
  source_ = std::move(source);
  frame_ = 0;
  publishedUs_ = 0;
}

void ProbeHub::endStreams(std::vector<std::function<void()>>& wakes) {
  for (auto& [id, s] : subscribers_) {  // what they hold is of another epoch: their streams end
    s.ended = true;
    s.source = nullptr;
    s.waiting = false;
    if (s.wake) wakes.push_back(s.wake);
  }
}

ProbeHub::Received ProbeHub::receive(const bus::Message& m, bool wake, std::string& why) {
  if (!fromBus_) throw std::logic_error("receive is for an edge's hub; a producer's encodes its own");
  std::vector<std::function<void()>> wakes;
  Received result = Received::Stale;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!source_ || m.volume.epoch != epoch_) {
      startEpoch(m.volume, wakes);
      result = Received::NewEpoch;
    } else if (!sameVolume(m.volume, config_.layout, config_.bounds, hasOffsets_, offsetsCrc_, config_.areaLights,
                           config_.scene)) {
      why = "a message of stream epoch " + std::to_string(epoch_) + " describes another volume than the epoch's";
      return Received::Refused;
    } else if (m.kind == bus::Kind::Volume && config_.offsets.empty() && !m.volume.offsets.empty()) {
      config_.offsets = m.volume.offsets;  // the offsets the epoch's brick messages announced (checksum checked)
      result = Received::Applied;
    }
    if (m.kind == bus::Kind::Volume && !config_.scene.known() && !m.volume.sceneManifest.empty()) {
      config_.scene.manifest = m.volume.sceneManifest;  // the manifest of the hash the epoch announced
      if (result != Received::NewEpoch) result = Received::Applied;
    }
    if (m.kind == bus::Kind::Brick) {
      const BusBricks::Accepted a = bus_->accept(m.brick, why);
      if (a == BusBricks::Accepted::Refused) {
        result = Received::Refused;
      } else if (a == BusBricks::Accepted::Applied) {
        frame_ = std::max(frame_, m.brick.producerFrame);
        publishedUs_ = std::max(publishedUs_, m.volume.publishedUs);
        if (m.brick.producerFrame >= stateFrame_) {
          stateFrame_ = m.brick.producerFrame;
          state_ = m.brick.state;
        }
        markStale(m.brick.brick);
        transcodedBehind_ = !transcoded_.empty();
        if (result != Received::NewEpoch) result = Received::Applied;
      }
    }
    if (wake) {
      std::vector<std::function<void()>> more = collectWakes();
      wakes.insert(wakes.end(), more.begin(), more.end());
    }
  }
  for (auto& w : wakes) w();
  return result;
}

void ProbeHub::tick() {
  std::vector<std::function<void()>> wakes;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    wakes = collectWakes();
  }
  for (auto& w : wakes) w();
}

std::vector<std::function<void()>> ProbeHub::collectWakes() {
  std::vector<std::function<void()>> wakes;
  for (auto& [id, s] : subscribers_)
    if (s.waiting && s.wake) {
      s.waiting = false;
      wakes.push_back(s.wake);
    }
  return wakes;
}

uint32_t ProbeHub::serverFrame() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frame_;
}

uint64_t ProbeHub::addSubscriber(uint64_t budgetBytesPerSecond, uint64_t epoch, std::span<const HeldBrick> held,
                                 std::function<void()> wake, std::optional<Representation> repr, bool paced) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!source_) throw std::logic_error("addSubscriber before the hub has a volume (check ready())");
  const uint32_t bricks = brickCount(config_.layout);
  Subscriber s;
  s.source = source_.get();
  s.layout = config_.layout;
  uint64_t streamEpoch = epoch_;
  bool producer = !fromBus_;  // whether every version there is was made here
  if (repr && *repr != config_.layout.repr) {
    if (!canTranscode(config_.layout.repr, *repr))
      throw std::invalid_argument(std::string("a ") + representationName(config_.layout.repr) +
                                  " stream cannot be transcoded to " + representationName(*repr));
    followTranscoded();
    TranscodedBricks& t = transcodedFor(*repr);
    s.source = &t;
    s.layout.repr = *repr;
    streamEpoch = t.epoch();
    producer = true;
  }
  s.budget = budgetBytesPerSecond;
  s.paced = paced;
  s.stats.paced = paced;
  s.tokens = static_cast<double>(budgetBytesPerSecond) * config_.burstSeconds;
  s.refilled = Clock::now();
  s.held.assign(bricks, 0);
  s.staleSince.assign(bricks, UINT32_MAX);
  if (epoch == streamEpoch)
    for (const HeldBrick& h : held)
      // On an edge a subscriber may come from a faster edge and hold versions this one has yet
      // to receive: it is sent nothing of those bricks until they move past what it holds. A
      // producer (or a transcoded stream) has made every version there is, so a later one is
      // nonsense there.
      if (h.brick < bricks && (!producer || h.version <= s.source->version(h.brick))) s.held[h.brick] = h.version;
  for (uint32_t b = 0; b < bricks; ++b)
    if (s.held[b] < s.source->version(b)) s.staleSince[b] = frame_;
  s.wake = std::move(wake);
  const uint64_t id = nextId_++;
  subscribers_.emplace(id, std::move(s));
  return id;
}

bus::Volume ProbeHub::volumeFor(uint64_t id) const {
  bus::Volume v = volume();
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = subscribers_.find(id);
  if (it == subscribers_.end() || !it->second.source || it->second.layout.repr == v.layout.repr) return v;
  v.layout.repr = it->second.layout.repr;
  v.epoch = static_cast<const TranscodedBricks*>(it->second.source)->epoch();
  return v;
}

void ProbeHub::removeSubscriber(uint64_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  subscribers_.erase(id);
}

void ProbeHub::setViews(uint64_t id, std::vector<View> views) {
  std::function<void()> wake;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = subscribers_.find(id);
    if (it == subscribers_.end()) return;
    it->second.views = std::move(views);
    if (it->second.waiting) {  // priorities changed: it may now want something else first
      it->second.waiting = false;
      wake = it->second.wake;
    }
  }
  if (wake) wake();
}

std::vector<View> ProbeHub::subscriberViews() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<View> views;
  for (const auto& [id, s] : subscribers_) views.insert(views.end(), s.views.begin(), s.views.end());
  return views;
}

size_t ProbeHub::subscriberCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return subscribers_.size();
}

void ProbeHub::refill(Subscriber& s, Clock::time_point now) const {
  if (s.budget == 0) return;
  const double dt = std::chrono::duration<double>(now - s.refilled).count();
  s.refilled = now;
  const double cap = static_cast<double>(s.budget) * config_.burstSeconds;
  s.tokens = std::min(cap, s.tokens + dt * static_cast<double>(s.budget));
}

std::optional<OutgoingFrame> ProbeHub::nextFrame(uint64_t id) { return nextFrame(id, nullptr); }

std::optional<OutgoingFrame> ProbeHub::nextFrame(uint64_t id, const FrameStorage& storage) {
  std::lock_guard<std::mutex> lock(mutex_);
  const FrameStorage* to = storage ? &storage : nullptr;
  auto it = subscribers_.find(id);
  if (it == subscribers_.end() || it->second.ended) return std::nullopt;
  Subscriber& s = it->second;
  if (s.source != source_.get()) followTranscoded();
  BrickSource& source = *s.source;
  const uint32_t bricks = brickCount(config_.layout);
  candidates_.assign(bricks, BrickCandidate{});
  uint32_t behind = 0;
  uint64_t staleBytes = 0;
  for (uint32_t b = 0; b < bricks; ++b) {
    const uint32_t current = source.version(b);
    if (s.held[b] >= current) continue;  // current, or ahead of a lagging edge
    ++behind;
    BrickCandidate& c = candidates_[b];
    c.change = std::max(source.changeSince(b, s.held[b]), 1e-3f);
    c.ageFrames = frame_ - std::min(frame_, s.staleSince[b]);
    c.bytes = static_cast<uint32_t>(source.sectionFor(b, s.held[b]).size());
    staleBytes += c.bytes;
  }
  s.stats.bricksBehind = behind;
  if (behind == 0) {
    s.waiting = true;
    return std::nullopt;
  }
  refill(s, Clock::now());
  chosen_.resize(bricks);
  // What may go now: the budget's bucket (saturating: a bucket of 2^64 bytes or more cannot bind,
  // and converting it would overflow) and a paced subscriber's link window.
  const uint64_t bucket = s.budget == 0 || s.tokens >= 0x1p64 ? UINT64_MAX
                                                                : static_cast<uint64_t>(std::max(0.0, s.tokens));
  const uint64_t link = s.paced ? s.link.allowance(Clock::now()) : UINT64_MAX;
  if (s.budget == 0 && link >= staleBytes && everyStaleBrickScores()) {
    // Nothing binds: every brick it lacks goes in this frame, and their order within it does not
    // matter, so the scoring (frustum tests per view and brick, a sort) is skipped.
    size_t n = 0;
    for (uint32_t b = 0; b < bricks; ++b)
      if (s.held[b] < source.version(b)) chosen_[n++] = b;
    return buildFrame(s, n, behind, false, to);
  }
  scores_.resize(bricks);
  scoreBricks(config_.layout, config_.bounds, s.views, candidates_, config_.priority, scores_.data());
  const double cap = static_cast<double>(s.budget) * config_.burstSeconds;
  size_t n = selectBricks(scores_, candidates_, std::min(bucket, link), chosen_.data());
  // A full bucket and an empty link may always send the best brick, so one larger than the bucket
  // or the window still goes out.
  if (n == 0 && (s.budget == 0 || s.tokens >= cap) && (!s.paced || s.link.inFlight() == 0)) {
    uint32_t best = 0;
    for (uint32_t b = 1; b < bricks; ++b)
      if (scores_[b] > scores_[best]) best = b;
    if (scores_[best] > 0) {
      chosen_[0] = best;
      n = 1;
    }
  }
  if (n == 0) {
    if (link < bucket) s.link.waited();
    s.waiting = true;  // the producer's tick refills the bucket, an ack opens the window; both wake it
    return std::nullopt;
  }
  return buildFrame(s, n, behind, link < bucket && n < behind, to);
}

bool ProbeHub::everyStaleBrickScores() const {
  // scoreBricks gives a stale brick (change >= 1e-3 here, bytes > 0) a positive score unless bricks
  // out of view weigh nothing or age counts against it.
  return config_.priority.outOfViewWeight > 0.0f && config_.priority.ageWeight >= 0.0f;
}

OutgoingFrame ProbeHub::buildFrame(Subscriber& s, size_t n, uint32_t behind, bool linkLimited,
                                   const FrameStorage* storage) {
  OutgoingFrame frame;
  std::vector<std::span<const uint8_t>> sections;
  sections.reserve(n);
  for (size_t k = 0; k < n; ++k) {
    const uint32_t b = chosen_[k];
    bool delta = false;
    sections.push_back(s.source->sectionFor(b, s.held[b], &delta));
    (delta ? frame.deltas : frame.keyframes) += 1;
    s.held[b] = s.source->version(b);
    s.staleSince[b] = UINT32_MAX;
  }
  frame.sequence = ++s.sequence;
  frame.serverTimeUs = publishedUs_;
  frame.state = state_;
  frame.sentUs = nowUs();
  frame.payloadBytes = frameSize(sections);
  const Clock::time_point now = Clock::now();
  if (s.paced) s.link.sent(frame.sequence, frame.payloadBytes, !linkLimited, now);
  if (storage)
    writeFrame(s.layout, frame.sequence, sections, (*storage)(frame, frame.payloadBytes));
  else
    writeFrame(s.layout, frame.sequence, sections, frame.payload);
  if (s.budget != 0) s.tokens -= static_cast<double>(frame.payloadBytes);
  s.unacked.emplace_back(frame.sequence, now);
  if (s.unacked.size() > 1024) s.unacked.pop_front();  // a client that never acks keeps a bounded record
  s.stats.bytesSent += frame.payloadBytes;
  s.stats.framesSent += 1;
  s.stats.bricksBehind = behind - static_cast<uint32_t>(n);
  return frame;
}

bool ProbeHub::acknowledge(uint64_t id, uint32_t sequence, std::string& why) {
  std::function<void()> wake;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = subscribers_.find(id);
    if (it == subscribers_.end()) return why = "unknown subscriber", false;
    Subscriber& s = it->second;
    if (sequence > s.sequence)
      return why = "ack of frame " + std::to_string(sequence) + " but only " + std::to_string(s.sequence) +
                   " were sent", false;
    if (sequence < s.stats.framesAcked)
      return why = "ack of frame " + std::to_string(sequence) + " after frame " +
                   std::to_string(s.stats.framesAcked), false;
    const Clock::time_point now = Clock::now();
    s.stats.framesAcked = sequence;
    while (!s.unacked.empty() && s.unacked.front().first <= sequence) {
      if (s.unacked.front().first == sequence)
        s.stats.ackRttUs = static_cast<uint32_t>(std::min<int64_t>(
            UINT32_MAX, std::chrono::duration_cast<std::chrono::microseconds>(now - s.unacked.front().second).count()));
      s.unacked.pop_front();
    }
    if (s.paced) {
      s.link.acked(sequence, now);
      if (s.waiting && s.link.allowance(now) > 0 && s.wake) {  // the window opened
        s.waiting = false;
        wake = s.wake;
      }
    }
  }
  if (wake) wake();
  return true;
}

bool ProbeHub::streamEnded(uint64_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = subscribers_.find(id);
  return it != subscribers_.end() && it->second.ended;
}

SubscriberStats ProbeHub::stats(uint64_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = subscribers_.find(id);
  if (it == subscribers_.end()) return SubscriberStats{};
  SubscriberStats st = it->second.stats;
  if (it->second.paced) st.link = it->second.link.stats();
  return st;
}

ProbeVolume ProbeHub::reconstruction(Representation repr) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!source_) throw std::logic_error("reconstruction before the hub has a volume (check ready())");
  if (repr == config_.layout.repr) return reconstructionLocked(*source_);
  auto it = transcoded_.find(repr);
  if (it == transcoded_.end())
    throw std::invalid_argument(std::string("no subscriber asked for ") + representationName(repr));
  followTranscoded();
  return reconstructionLocked(*it->second);
}

ProbeVolume ProbeHub::reconstruction() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (source_) return reconstructionLocked(*source_);
  ProbeVolume v;
  v.areaLights = config_.areaLights;
  v.scene.hash = config_.scene.hash;
  v.scene.manifest = config_.scene.manifest;
  v.scene.time = state_.time;
  return v;
}

ProbeVolume ProbeHub::reconstructionLocked(const BrickSource& source) const {
  ProbeVolume v;
  source.copyVolume(config_.bounds, v);
  std::string why;
  if (!dequantizeProbeOffsets(v.grid, config_.offsets.data(), config_.offsets.size(), v.offsets, why))
    v.offsets.clear();  // never: offsets are checked when they arrive
  v.areaLights = config_.areaLights;
  v.scene.hash = config_.scene.hash;
  v.scene.manifest = config_.scene.manifest;
  v.scene.time = state_.time;
  return v;
}

}  // namespace probecast::service
