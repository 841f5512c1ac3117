// libFuzzer target: arbitrary bytes into the probe bus decoder. A message it accepts must be
// written back byte for byte from what it parsed, and its sections must be what they claim (a
// keyframe that a fresh decoder takes at the stated version, or a clean refusal).
#include <cstdlib>
#include <vector>

#include "bus_fuzz_common.h"
#include "probecast/service/bus_format.h"

using namespace probecast;

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  std::vector<uint8_t> message(data + 1, data + size);
  if (data[0] & fuzz::kBusRepairFlag) fuzz::repairBusChecksum(message);
  bus::Message m;
  std::string why;
  if (!bus::readMessage(message.data(), message.size(), m, why)) {
    require(!why.empty());
    return 0;
  }
  std::vector<uint8_t> again;
  if (m.kind == bus::Kind::Volume) bus::writeVolumeMessage(m.volume, m.flags, again);
  else bus::writeBrickMessage(m.volume, m.brick, m.flags, again);
  require(again == message);
  if (m.kind == bus::Kind::Brick && probeCount(m.volume.layout) <= 4096) {
    std::vector<uint8_t> frame;
    const std::span<const uint8_t> sections[] = {m.brick.keyframe};
    writeFrame(m.volume.layout, 1, sections, frame);
    StreamDecoder decoder(m.volume.layout);
    if (decoder.apply(frame.data(), frame.size()) == CodecStatus::Ok)
      require(decoder.brickVersion(m.brick.brick) == m.brick.version);
    else
      require(decoder.brickVersion(m.brick.brick) == 0);
  }
  return 0;
}
