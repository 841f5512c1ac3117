// Conversions between the protocol's messages and the codec's types (private to the service).
#pragma once

#include <string>
#include <vector>

#include "probecast.pb.h"
#include "probecast/codec/priority.h"
#include "probecast/codec/stream.h"

namespace probecast::service {

constexpr uint32_t kProtocolVersion = 2;  // 2: VolumeDescription.probe_offsets
extern const char* const kShConvention;

// `offsets`: quantised (probe_offsets.h), 3 per probe or none.
void volumeToWire(const StreamLayout& layout, const GridBounds& bounds, uint64_t epoch,
                  const std::vector<int8_t>& offsets, v1::VolumeDescription& out);
// Validates a volume description from a server, its probe offsets too (returned in metres,
// empty for none); `why` says what is wrong.
bool volumeFromWire(const v1::VolumeDescription& in, StreamLayout& layout, GridBounds& bounds,
                    std::vector<float>& offsets, std::string& why);
// Validates and converts views: count, 16 finite matrix entries each, finite eyes.
bool viewsFromWire(const v1::ViewUpdate& in, uint32_t maxViews, std::vector<View>& out, std::string& why);
void viewsToWire(const std::vector<View>& views, v1::ViewUpdate& out);

}  // namespace probecast::service
