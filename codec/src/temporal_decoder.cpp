// The stream decoder: validates a whole frame, then commits it (all or nothing).
#include <cassert>
#include <vector>

#include <zstd.h>

#include "brick_section.h"
#include "probecast/codec/stream.h"

namespace probecast {

struct StreamDecoder::Impl {
  StreamLayout layout;
  bool zh3PerPixel = false;
  uint32_t lastFrame = 0;
  std::vector<ProbeSymbols> symbols;
  std::vector<uint8_t> active;
  std::vector<float> probes;
  std::vector<uint32_t> versions;
  std::vector<Representation> brickRepr;  // of each brick's held version (the stream's until a section says)
  BrickTable table;
  std::vector<uint32_t> seenInFrame;  // frame stamp per brick, for duplicate detection
  uint32_t stamp = 0;
  ZSTD_DCtx* dctx = nullptr;

  // A brick's new state, staged until the whole frame is valid.
  struct Staged {
    uint32_t brick;
    uint32_t version;
    Representation repr;
    std::vector<uint8_t> active;
    std::vector<ProbeSymbols> symbols;
    std::vector<float> probes;
  };
  std::vector<Staged> staged;
  std::vector<uint8_t> raw;
  std::vector<uint8_t> zstdFrame;  // a format 3 section's zstd data with its magic restored

  ~Impl() { ZSTD_freeDCtx(dctx); }
};

StreamDecoder::StreamDecoder(const StreamLayout& layout) : impl_(new Impl) {
  assert(isValidLayout(layout));
  Impl& s = *impl_;
  s.layout = layout;
  const uint32_t probes = probeCount(layout);
  const uint32_t bricks = brickCount(layout);
  s.symbols.assign(probes, ProbeSymbols{});
  s.active.assign(probes, 0);
  s.probes.assign(static_cast<size_t>(probes) * kProbeFloats, 0.0f);
  s.versions.assign(bricks, 0);
  s.brickRepr.assign(bricks, layout.repr);
  s.seenInFrame.assign(bricks, 0);
  s.table.build(layout);
  s.dctx = ZSTD_createDCtx();
}

StreamDecoder::~StreamDecoder() = default;

CodecStatus StreamDecoder::apply(const uint8_t* data, size_t size) {
  Impl& s = *impl_;
  FrameHeader header;
  if (CodecStatus st = readFrameHeader(data, size, &header); st != CodecStatus::Ok) return st;
  const StreamLayout& l = header.layout;
  if (l.repr != s.layout.repr || l.brickDim != s.layout.brickDim || l.grid[0] != s.layout.grid[0] ||
      l.grid[1] != s.layout.grid[1] || l.grid[2] != s.layout.grid[2])
    return CodecStatus::LayoutMismatch;

  if (++s.stamp == 0) {  // stamps wrapped: clear them
    std::fill(s.seenInFrame.begin(), s.seenInFrame.end(), 0);
    s.stamp = 1;
  }
  s.staged.clear();
  const bool zh3hChoice = header.formatVersion >= 2;  // format 1: every zh3h probe hallucinates
  const CodecStatus parsed = forEachSection(s.layout, data, header, [&s, &header, zh3hChoice](const SectionView& view) {
    if (s.seenInFrame[view.brick] == s.stamp) return CodecStatus::DuplicateBrick;
    s.seenInFrame[view.brick] = s.stamp;

    const uint32_t held = s.versions[view.brick];
    if (view.kind == SectionKind::Delta && view.version != held + 1) return CodecStatus::BaseVersionMismatch;
    if (view.kind == SectionKind::Keyframe && view.version < held) return CodecStatus::BadVersion;
    // A delta changes symbols of the representation held; another one starts from a keyframe.
    if (view.kind == SectionKind::Delta && view.repr != s.brickRepr[view.brick]) return CodecStatus::BadSectionKind;

    const uint8_t* raw = view.data;
    if (view.compression == kCompressionZstd) {
      // parseSection checked the frame: one, stating view.rawSize.
      const std::span<const uint8_t> frame = zstdFrameOf(header.formatVersion, view.data, view.storedSize, s.zstdFrame);
      s.raw.resize(view.rawSize);
      const size_t n = ZSTD_decompressDCtx(s.dctx, s.raw.data(), s.raw.size(), frame.data(), frame.size());
      if (ZSTD_isError(n) || n != view.rawSize) return CodecStatus::DecompressFailed;
      raw = s.raw.data();
    }

    const uint32_t first = s.table.first[view.brick];
    const uint32_t n = s.table.first[view.brick + 1] - first;
    Impl::Staged st;
    st.brick = view.brick;
    st.version = view.version;
    st.repr = view.repr;
    st.active.resize(n);
    st.symbols.resize(n);
    for (uint32_t k = 0; k < n; ++k) {
      st.active[k] = s.active[s.table.probes[first + k]];
      st.symbols[k] = s.symbols[s.table.probes[first + k]];
    }
    if (CodecStatus r = applyPayload(header.formatVersion, view.repr, n, view.kind, raw, view.rawSize, st.active.data(),
                                     st.symbols.data());
        r != CodecStatus::Ok)
      return r;
    st.probes.assign(static_cast<size_t>(n) * kProbeFloats, 0.0f);
    for (uint32_t k = 0; k < n; ++k)
      if (st.active[k] && !dequantizeProbe(view.repr, st.symbols[k], st.probes.data() + k * kProbeFloats,
                                           s.zh3PerPixel, zh3hChoice))
        return CodecStatus::BadSymbol;
    s.staged.push_back(std::move(st));
    return CodecStatus::Ok;
  });
  if (parsed != CodecStatus::Ok) return parsed;

  for (const Impl::Staged& st : s.staged) {
    const uint32_t first = s.table.first[st.brick];
    for (uint32_t k = 0; k < st.active.size(); ++k) {
      const uint32_t probe = s.table.probes[first + k];
      s.active[probe] = st.active[k];
      s.symbols[probe] = st.symbols[k];
      std::copy(st.probes.begin() + k * kProbeFloats, st.probes.begin() + (k + 1) * kProbeFloats,
                s.probes.begin() + static_cast<size_t>(probe) * kProbeFloats);
    }
    s.versions[st.brick] = st.version;
    s.brickRepr[st.brick] = st.repr;
  }
  s.lastFrame = header.frameSequence;
  return CodecStatus::Ok;
}

const StreamLayout& StreamDecoder::layout() const { return impl_->layout; }
uint32_t StreamDecoder::brickVersion(uint32_t brick) const { return impl_->versions.at(brick); }
uint32_t StreamDecoder::lastFrameSequence() const { return impl_->lastFrame; }
const float* StreamDecoder::probes() const { return impl_->probes.data(); }
const uint8_t* StreamDecoder::activeMask() const { return impl_->active.data(); }
void StreamDecoder::setZh3PerPixel(bool zh3PerPixel) { impl_->zh3PerPixel = zh3PerPixel; }
void StreamDecoder::copyVolume(const GridBounds& bounds, ProbeVolume& out) const {
  const bool l1Only = impl_->zh3PerPixel && impl_->layout.repr == Representation::Zh3Hallucinated;
  copyStreamVolume(impl_->layout, bounds, impl_->probes.data(), impl_->active.data(), l1Only, out);
}

}  // namespace probecast
