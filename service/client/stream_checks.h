// How a subscriber judges what a server sends before anything of it is used: a volume description
// (checked, its scene manifest hashed and parsed, its size and scene held to the client's
// configuration) and a frame (its scene state and its section counts; the codec checks the rest).
// Internal to the client library, gRPC-free (protobuf messages only), so the client fuzz target
// (fuzz/client_fuzz.cpp) drives exactly what ProbeClient runs.
#pragma once

#include <string>
#include <vector>

#include "probecast.pb.h"
#include "probecast/service/client.h"

namespace probecast::service {

struct Description {
  StreamLayout layout;
  GridBounds bounds;
  std::vector<float> offsets;  // metres
  AreaLightRule areaLights;
  SceneStamp scene;
  uint64_t epoch = 0;
};


enum class Verdict {
  Accept,
  Retry,    // refused: drop the connection, ask again later (a server may mend it)
  ForGood,  // refused for good: another scene than the one drawn, a volume beyond the limit
};

Verdict checkDescription(const v1::VolumeDescription& in, const ClientConfig& config, Description& out,
                         std::string& why);
// A frame's scene state (into `state` when it has one) and its keyframe and delta counts against
// the sections its payload holds.
bool checkFrame(const v1::Frame& in, bus::SceneState& state, std::string& why);

}  // namespace probecast::service
