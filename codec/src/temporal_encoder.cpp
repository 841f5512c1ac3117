// The stream encoder: quantises frames, versions bricks, encodes each version once.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>

#include <zstd.h>

#include "brick_section.h"
#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/sh.h"
#include "probecast/codec/stream.h"

namespace probecast {

struct StreamEncoder::Impl {
  StreamLayout layout;
  EncoderOptions options;
  uint32_t frame = 0;
  std::vector<ProbeSymbols> symbols;       // decoder-side symbols per probe (0 when inactive)
  std::vector<uint8_t> active;             // per probe
  std::vector<float> reconstruction;       // 27 floats per probe
  BrickTable table;                        // grid indices of each brick's probes
  std::vector<uint32_t> versions;
  std::vector<Representation> brickRepr;   // of each brick's current version
  std::vector<uint8_t> deltaIsKeyframe;    // per brick: its latest version changed representation
  std::vector<Representation> choices;     // brickRepresentations(layout.repr) with an error bound, else the layout's
  std::vector<float> change;
  static constexpr uint32_t kHistory = 16;
  std::vector<float> changeHistory;        // kHistory per brick, indexed by version % kHistory
  std::vector<uint32_t> changedThisFrame;  // bricks given a version by the last update
  std::vector<std::vector<uint8_t>> deltas;
  std::vector<std::vector<uint8_t>> keyframes;
  std::vector<uint8_t> keyframeValid;
  ZSTD_CCtx* cctx = nullptr;

  // Scratch, sized for one brick.
  std::vector<ProbeSymbols> base, next;
  std::vector<uint8_t> baseActive, nextActive, raw;
  std::vector<uint8_t> riceRaw, riceSection;  // a delta spelled with Rice codes, and its section
  std::vector<ProbeSymbols> candidates;  // per choice × brick probe, with an error bound
  std::vector<float> viewScale;  // per probe: the noise rule's thresholds × this (setViewWeights); empty: 1
  std::vector<uint32_t> beyond;  // per probe: consecutive updates beyond c·σ not yet sent (EncoderOptions::confirmations)

  // The representation brick `b` is sent in this update (EncoderOptions::errorBound), its probes'
  // symbols for each choice left in `candidates`.
  Representation chooseRepresentation(uint32_t b, const float* probes, const uint8_t* activeIn);

  ~Impl() { ZSTD_freeCCtx(cctx); }
};

StreamEncoder::StreamEncoder(const StreamLayout& layout, const EncoderOptions& options) : impl_(new Impl) {
  assert(isValidLayout(layout));
  Impl& s = *impl_;
  s.layout = layout;
  s.options = options;
  const uint32_t probes = probeCount(layout);
  const uint32_t bricks = brickCount(layout);
  s.symbols.assign(probes, ProbeSymbols{});
  s.beyond.assign(probes, 0);
  s.active.assign(probes, 0);
  s.reconstruction.assign(static_cast<size_t>(probes) * kProbeFloats, 0.0f);
  s.table.build(layout);
  s.versions.assign(bricks, 0);
  s.brickRepr.assign(bricks, layout.repr);
  s.deltaIsKeyframe.assign(bricks, 0);
  s.choices = options.errorBound > 0.0f ? brickRepresentations(layout.repr) : std::vector<Representation>{layout.repr};
  s.change.assign(bricks, 0.0f);
  s.changeHistory.assign(static_cast<size_t>(bricks) * Impl::kHistory, 0.0f);
  s.deltas.resize(bricks);
  s.keyframes.resize(bricks);
  s.keyframeValid.assign(bricks, 0);
  s.cctx = ZSTD_createCCtx();
}

StreamEncoder::~StreamEncoder() = default;

namespace {

// EncoderOptions::confirmations: a change beyond this × c·σ is new light, sent without waiting.
constexpr float kConfirmedBeyond = 4.0f;

// The noise rule of EncoderOptions::noiseScale: true when `candidate` (what a new version would
// decode to) differs from `held` (what the decoder has) by at most `threshold` in the irradiance-
// weighted RMS over the coefficients, each channel's differences divided by that channel's share
// of the held luminance (noise scales with the light). One mean over 27 values, not a maximum:
// noise of standard error σ in every coefficient gives a mean square of σ², where the maximum of
// 27 values would exceed 2σ in most frames.
bool withinNoise(const float candidate[kProbeFloats], const float held[kProbeFloats], float threshold) {
  constexpr float kBandWeight[3] = {1.0f, 4.0f / 9.0f, 1.0f / 16.0f};  // (Â_l / π)², Â = (π, 2π/3, π/4)
  const float luminance = 0.2126f * held[0] + 0.7152f * held[1] + 0.0722f * held[2];
  double sum = 0.0, weights = 0.0;
  for (int i = 0; i < kShCoeffs; ++i) {
    const float w = kBandWeight[shBand(i)];
    for (int c = 0; c < 3; ++c) {
      const float d = candidate[i * 3 + c] - held[i * 3 + c];
      const float share = luminance > 0.0f ? std::max(held[c], 0.0f) / luminance : 1.0f;
      if (!(share > 0.0f)) {
        if (d != 0.0f) return false;
        continue;
      }
      sum += static_cast<double>(w) * (d / share) * (d / share);
    }
    weights += 3.0 * w;
  }
  return sum <= static_cast<double>(threshold) * threshold * weights;
}

}  // namespace

bool StreamEncoder::setViewWeights(std::span<const float> weights) {
  Impl& s = *impl_;
  if (weights.empty()) {
    s.viewScale.clear();
    return true;
  }
  if (weights.size() != probeCount(s.layout)) return false;
  double sum = 0.0;
  size_t seen = 0;
  for (float w : weights) {
    if (!std::isfinite(w) || w < 0.0f) return false;
    if (w > 0.0f) {
      sum += w;
      ++seen;
    }
  }
  if (seen == 0) return false;
  const double mean = sum / static_cast<double>(seen);
  s.viewScale.resize(weights.size());
  for (size_t p = 0; p < weights.size(); ++p)
    s.viewScale[p] = weights[p] > 0.0f ? static_cast<float>(std::clamp(std::cbrt(mean / weights[p]),
                                                                       static_cast<double>(kViewScaleMin),
                                                                       static_cast<double>(kViewScaleMax)))
                                       : kViewScaleMax;
  return true;
}

Representation StreamEncoder::Impl::chooseRepresentation(uint32_t b, const float* probes, const uint8_t* activeIn) {
  const uint32_t first = table.first[b], n = table.first[b + 1] - first;
  const size_t count = choices.size();  // at most 3 (brickRepresentations)
  candidates.resize(count * n);
  double err[3] = {}, energy[3] = {};
  for (size_t c = 0; c < count; ++c)
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t p = table.probes[first + k];
      ProbeSymbols& out = candidates[c * n + k];
      if (activeIn != nullptr && activeIn[p] == 0) {
        out = ProbeSymbols{};
        continue;
      }
      // The brick's own representation keeps the dead-zone against what the decoder holds.
      const ProbeSymbols* previous = active[p] && choices[c] == brickRepr[b] ? &symbols[p] : nullptr;
      float input[kProbeFloats];
      std::copy(probes + static_cast<size_t>(p) * kProbeFloats, probes + static_cast<size_t>(p + 1) * kProbeFloats, input);
      sanitizeProbe(input);
      quantizeProbe(choices[c], input, previous, options.deadzone, &out);
      float decoded[kProbeFloats];
      dequantizeProbe(choices[c], out, decoded, /*zh3PerPixel=*/false);
      irradianceErrorEnergy(decoded, input, err[c], energy[c]);
    }
  const double bound = options.errorBound;
  size_t held = 0;  // a brick with nothing sent yet takes the cheapest within the bound outright
  for (size_t c = 0; c < count && versions[b] > 0; ++c)
    if (choices[c] == brickRepr[b]) held = c;
  size_t pick = count - 1;  // none within the bound: the stream's own
  for (size_t c = 0; c < count; ++c) {
    // The brick's relative irradiance error; cheaper than its representation only with room to
    // spare (0.8 of the bound). A brick of black or inactive probes takes the cheapest.
    const double e = energy[c] > 0.0 ? std::sqrt(err[c] / energy[c]) : (err[c] > 0.0 ? 1e300 : 0.0);
    if (e <= (c < held ? 0.8 * bound : bound)) {
      pick = c;
      break;
    }
  }
  return choices[pick];
}

uint32_t StreamEncoder::update(const float* probes, const uint8_t* activeIn, const float* noise,
                              const uint32_t* stillUpdates) {
  Impl& s = *impl_;
  const uint32_t bricks = brickCount(s.layout);
  s.changedThisFrame.clear();
  ++s.frame;
  for (uint32_t b = 0; b < bricks; ++b) {
    const uint32_t first = s.table.first[b];
    const uint32_t n = s.table.first[b + 1] - first;
    s.base.resize(n);
    s.baseActive.resize(n);
    s.next.resize(n);
    s.nextActive.resize(n);
    const Representation repr = s.choices.size() > 1 ? s.chooseRepresentation(b, probes, activeIn) : s.brickRepr[b];
    const bool switched = repr != s.brickRepr[b];  // this version is a keyframe in `repr`
    size_t choice = 0;
    while (s.choices[choice] != repr) ++choice;
    bool changed = switched;
    bool urgent = switched;  // anything but refinements within 2c·σ (EncoderOptions::refinementInterval)
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t p = s.table.probes[first + k];
      s.base[k] = s.symbols[p];
      s.baseActive[k] = s.active[p];
      const bool isActive = activeIn == nullptr || activeIn[p] != 0;
      s.nextActive[k] = isActive ? 1 : 0;
      if (isActive) {
        const ProbeSymbols* previous = s.active[p] && !switched ? &s.symbols[p] : nullptr;
        if (s.choices.size() > 1) s.next[k] = s.candidates[choice * n + k];
        else quantizeProbe(repr, probes + static_cast<size_t>(p) * kProbeFloats, previous, s.options.deadzone, &s.next[k]);
        // A change the input's own noise explains is not sent: keep what the decoder holds while
        // the would-be new version is within c·σ of it.
        const float sigma = (noise && std::isfinite(noise[p]) ? std::max(noise[p], 0.0f) : 0.0f) *
                            (s.viewScale.empty() ? 1.0f : s.viewScale[p]);
        const bool moved = !previous || std::memcmp(&s.next[k], previous, sizeof(ProbeSymbols)) != 0;
        if (previous && sigma > 0.0f && s.options.noiseScale > 0.0f && moved) {
          float candidate[kProbeFloats];
          const bool ok = dequantizeProbe(repr, s.next[k], candidate, /*zh3PerPixel=*/false);
          assert(ok && "the encoder only makes valid symbols");
          (void)ok;
          const float* held = s.reconstruction.data() + static_cast<size_t>(p) * kProbeFloats;
          if (withinNoise(candidate, held, s.options.noiseScale * sigma)) {
            s.next[k] = *previous;
            s.beyond[p] = 0;
          } else if (s.beyond[p] < s.options.confirmations &&
                     withinNoise(candidate, held, kConfirmedBeyond * s.options.noiseScale * sigma)) {
            ++s.beyond[p];  // not confirmed yet: kept (the count is cleared when the probe is sent)
            s.next[k] = *previous;
          } else {
            // Beyond 2c·σ it is new light; within, a refinement, unless the probe's light has not
            // held still for the refinement interval (then it is the light moving on).
            const bool still = stillUpdates == nullptr || stillUpdates[p] >= s.options.refinementInterval;
            urgent = urgent || !still || !withinNoise(candidate, held, 2.0f * s.options.noiseScale * sigma);
          }
        } else if (moved) {
          urgent = true;  // no noise to weigh it against, or newly active
        } else {
          s.beyond[p] = 0;
        }
      } else {
        s.next[k] = ProbeSymbols{};
        s.beyond[p] = 0;
      }
      urgent = urgent || s.nextActive[k] != s.active[p];
      changed = changed || s.nextActive[k] != s.active[p] ||
                std::memcmp(&s.next[k], &s.base[k], sizeof(ProbeSymbols)) != 0;
    }
    // Refinements alone (changes between c·σ and 2c·σ of still probes: the estimate converging,
    // not new light) wait for the next update whose sequence is a multiple of refinementInterval,
    // and then go together, every brick's in one frame.
    if (changed && !urgent && s.options.refinementInterval > 0 && s.frame % s.options.refinementInterval != 0)
      changed = false;
    if (!changed) continue;

    // A brick that changed representation starts again from a keyframe (no symbol differences across them).
    if (switched) buildKeyframePayload(repr, n, s.nextActive.data(), s.next.data(), s.raw);
    else
      buildDeltaPayload(repr, n, s.baseActive.data(), s.nextActive.data(), s.base.data(), s.next.data(), s.raw,
                        &s.riceRaw);
    ++s.versions[b];
    const SectionKind kind = switched ? SectionKind::Keyframe : SectionKind::Delta;
    void* const zstd = s.options.compress ? s.cctx : nullptr;
    writeSection(b, s.versions[b], kind, repr, s.layout.repr, s.raw, s.options.zstdLevel, zstd, s.deltas[b]);
    // The delta's differences as Rice codes, where those are shorter, stored instead when the section
    // comes out shorter (byte planes compress where Rice codes do not: a large change of many probes).
    // Rice codes are stored raw: zstd finds next to nothing in them, and compressing every delta twice
    // would double the encoder's zstd time.
    if (!switched && !s.riceRaw.empty()) {
      writeSection(b, s.versions[b], kind, repr, s.layout.repr, s.riceRaw, s.options.zstdLevel, nullptr, s.riceSection);
      if (s.riceSection.size() < s.deltas[b].size()) s.deltas[b].swap(s.riceSection);
    }
    s.brickRepr[b] = repr;
    s.deltaIsKeyframe[b] = switched ? 1 : 0;
    s.keyframeValid[b] = 0;
    s.changedThisFrame.push_back(b);

    double diff = 0.0, total = 0.0;
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t p = s.table.probes[first + k];
      if (std::memcmp(&s.next[k], &s.symbols[p], sizeof(ProbeSymbols)) != 0) s.beyond[p] = 0;
      s.symbols[p] = s.next[k];
      s.active[p] = s.nextActive[k];
      float decoded[kProbeFloats] = {};
      if (s.active[p]) {
        const bool ok = dequantizeProbe(repr, s.next[k], decoded, /*zh3PerPixel=*/false);
        assert(ok && "the encoder only makes valid symbols");
        (void)ok;
      }
      float* out = s.reconstruction.data() + static_cast<size_t>(p) * kProbeFloats;
      for (int i = 0; i < kProbeFloats; ++i) {
        diff += std::fabs(decoded[i] - out[i]);
        total += std::fabs(decoded[i]);
        out[i] = decoded[i];
      }
    }
    s.change[b] = total > 0.0 ? static_cast<float>(diff / total) : (diff > 0.0 ? 1.0f : 0.0f);
    s.changeHistory[static_cast<size_t>(b) * Impl::kHistory + s.versions[b] % Impl::kHistory] = s.change[b];
  }
  return static_cast<uint32_t>(s.changedThisFrame.size());
}

const StreamLayout& StreamEncoder::layout() const { return impl_->layout; }
uint32_t StreamEncoder::frameSequence() const { return impl_->frame; }
uint32_t StreamEncoder::brickVersion(uint32_t brick) const { return impl_->versions.at(brick); }
float StreamEncoder::brickChange(uint32_t brick) const { return impl_->change.at(brick); }

float StreamEncoder::changeSince(uint32_t brick, uint32_t heldVersion) const {
  const Impl& s = *impl_;
  const uint32_t current = s.versions.at(brick);
  if (heldVersion >= current) return 0.0f;
  if (heldVersion == 0 || current - heldVersion > Impl::kHistory) return 1.0f;
  float sum = 0.0f;
  for (uint32_t v = heldVersion + 1; v <= current; ++v)
    sum += s.changeHistory[static_cast<size_t>(brick) * Impl::kHistory + v % Impl::kHistory];
  return sum;
}

std::span<const uint8_t> StreamEncoder::deltaSection(uint32_t brick) const { return impl_->deltas.at(brick); }
bool StreamEncoder::deltaIsKeyframe(uint32_t brick) const { return impl_->deltaIsKeyframe.at(brick) != 0; }
Representation StreamEncoder::brickRepresentation(uint32_t brick) const { return impl_->brickRepr.at(brick); }

std::span<const uint8_t> StreamEncoder::keyframeSection(uint32_t brick) {
  Impl& s = *impl_;
  if (!s.keyframeValid.at(brick)) {
    const uint32_t first = s.table.first[brick];
    const uint32_t n = s.table.first[brick + 1] - first;
    s.next.resize(n);
    s.nextActive.resize(n);
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t p = s.table.probes[first + k];
      s.next[k] = s.symbols[p];
      s.nextActive[k] = s.active[p];
    }
    buildKeyframePayload(s.brickRepr[brick], n, s.nextActive.data(), s.next.data(), s.raw);
    writeSection(brick, s.versions[brick], SectionKind::Keyframe, s.brickRepr[brick], s.layout.repr, s.raw,
                 s.options.zstdLevel, s.options.compress ? s.cctx : nullptr, s.keyframes[brick]);
    s.keyframeValid[brick] = 1;
  }
  return s.keyframes[brick];
}

std::span<const uint8_t> StreamEncoder::sectionFor(uint32_t brick, uint32_t heldVersion) {
  const uint32_t current = impl_->versions.at(brick);
  if (heldVersion == current) return {};
  if (heldVersion + 1 == current) return deltaSection(brick);
  return keyframeSection(brick);
}

void StreamEncoder::writeChangedFrame(std::vector<uint8_t>& out) const {
  std::vector<std::span<const uint8_t>> sections;
  sections.reserve(impl_->changedThisFrame.size());
  for (uint32_t b : impl_->changedThisFrame) sections.push_back(impl_->deltas[b]);
  writeFrame(impl_->layout, impl_->frame, sections, out);
}

void StreamEncoder::writeKeyframeFrame(std::vector<uint8_t>& out) {
  const uint32_t bricks = brickCount(impl_->layout);
  std::vector<std::span<const uint8_t>> sections;
  sections.reserve(bricks);
  for (uint32_t b = 0; b < bricks; ++b) sections.push_back(keyframeSection(b));
  writeFrame(impl_->layout, impl_->frame, sections, out);
}

const float* StreamEncoder::reconstruction() const { return impl_->reconstruction.data(); }
const uint8_t* StreamEncoder::activeMask() const { return impl_->active.data(); }
void StreamEncoder::copyVolume(const GridBounds& bounds, ProbeVolume& out) const {
  copyStreamVolume(impl_->layout, bounds, impl_->reconstruction.data(), impl_->active.data(), false, out);
}

}  // namespace probecast
