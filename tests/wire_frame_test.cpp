// The hand-written Frame message the server sends (wire_convert.h) against protobuf's own
// serialisation of the same fields: the known answer is what the generated code writes.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "probecast.pb.h"
#include "wire_convert.h"

namespace probecast::service {
namespace {

std::string handWritten(const FrameFields& f, const std::string& payload) {
  std::string out(framePrefixBytes(f) + payload.size() + frameSuffixBytes(f), '\0');
  auto* begin = reinterpret_cast<uint8_t*>(out.data());
  uint8_t* p = writeFramePrefix(f, begin);
  std::copy(payload.begin(), payload.end(), p);
  uint8_t* end = writeFrameSuffix(f, p + payload.size());
  EXPECT_EQ(static_cast<size_t>(end - begin), out.size());
  return out;
}

TEST(WireFrame, HandWrittenFrameIsTheBytesProtobufWrites) {
  std::mt19937 rng(7);
  const uint32_t sequences[] = {0, 1, 127, 128, 300, UINT32_MAX};
  const uint64_t times[] = {0, 1, uint64_t{1} << 40, UINT64_MAX};
  const size_t payloads[] = {0, 1, 127, 128, 16383, 16384, 70000, (size_t{1} << 21) + 3};
  const uint32_t counts[] = {0, 1, 200, 70000};
  int cases = 0;
  for (uint32_t seq : sequences)
    for (uint64_t t : times)
      for (size_t bytes : payloads)
        for (uint32_t n : counts) {
          std::string payload(bytes, '\0');
          for (char& c : payload) c = static_cast<char>(rng());
          const FrameFields f{seq, t, bytes, n, n / 2 + seq % 3};
          v1::ServerMessage m;
          v1::Frame* frame = m.mutable_frame();
          frame->set_sequence(f.sequence);
          frame->set_server_time_us(f.serverTimeUs);
          frame->set_payload(payload);
          frame->set_keyframes(f.keyframes);
          frame->set_deltas(f.deltas);
          const std::string mine = handWritten(f, payload);
          ASSERT_EQ(mine, m.SerializeAsString()) << "sequence " << seq << " time " << t << " payload " << bytes;
          v1::ServerMessage back;
          ASSERT_TRUE(back.ParseFromString(mine));
          ASSERT_TRUE(back.has_frame());
          EXPECT_EQ(back.frame().payload(), payload);
          ++cases;
        }
  EXPECT_EQ(cases, 6 * 4 * 8 * 4);
}

TEST(WireFrame, SceneStateAndSendTimeAreTheBytesProtobufWrites) {
  bus::SceneState still;  // all zero: an empty message that is still present
  bus::SceneState playing;
  playing.time = 12.5;
  playing.rate = 0.05;
  playing.clockUs = 1764950000123456ull;
  playing.lights.resize(3);
  playing.lights[1].type = 2;
  playing.lights[2].intensity = 0.0f;
  for (const bus::SceneState* st : {&still, &playing})
    for (uint64_t sent : {uint64_t{0}, uint64_t{1}, uint64_t{1764950000654321ull}})
      for (size_t bytes : {size_t{0}, size_t{300}}) {
        v1::SceneState wire;
        stateToWire(*st, wire);
        const std::string state = wire.SerializeAsString();
        const std::string payload(bytes, 'p');
        FrameFields f{9, 77, bytes, 2, 1, &state, sent};
        v1::ServerMessage m;
        v1::Frame* frame = m.mutable_frame();
        frame->set_sequence(9);
        frame->set_server_time_us(77);
        frame->set_payload(payload);
        frame->set_keyframes(2);
        frame->set_deltas(1);
        *frame->mutable_scene_state() = wire;
        frame->set_sent_us(sent);
        const std::string mine = handWritten(f, payload);
        ASSERT_EQ(mine, m.SerializeAsString()) << "lights " << st->lights.size() << " sent " << sent;
        v1::ServerMessage back;
        ASSERT_TRUE(back.ParseFromString(mine));
        bus::SceneState parsed;
        std::string why;
        ASSERT_TRUE(stateFromWire(back.frame().scene_state(), parsed, why)) << why;
        EXPECT_EQ(parsed, *st);
        EXPECT_EQ(back.frame().sent_us(), sent);
      }
}

}  // namespace
}  // namespace probecast::service
