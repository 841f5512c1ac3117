// The browser viewer's decoder (web/wasm/probecast_web.cpp, built natively): a sequence of bus
// messages, each as a page would hand it over, then everything a page reads back. Input: records
// of u8 control | u16 length (little-endian) | bytes; control bit 0 repairs the message's checksum
// first (so mutated fields reach the parser behind it).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "bus_fuzz_common.h"

extern "C" {
void* pc_viewer_new();
void pc_viewer_free(void*);
int pc_viewer_message(void*, const uint8_t*, uint32_t);
const char* pc_viewer_error(void*);
uint32_t pc_viewer_probe_count(void*);
uint32_t pc_viewer_bricks_held(void*);
const float* pc_viewer_probes(void*);
const uint8_t* pc_viewer_active(void*);
const float* pc_viewer_offsets(void*);
uint32_t pc_viewer_checksum(void*);
const char* pc_viewer_scene_hash(void*);
const char* pc_viewer_scene_manifest(void*);
const char* pc_viewer_representation(void*);
uint32_t pc_viewer_dim(void*, int);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  void* viewer = pc_viewer_new();
  size_t at = 0;
  uint64_t sink = 0;  // read at the end, so that nothing above is optimised away
  while (at + 3 <= size) {
    const uint8_t control = data[at];
    const size_t length = std::min<size_t>(data[at + 1] | (size_t{data[at + 2]} << 8), size - at - 3);
    std::vector<uint8_t> message(data + at + 3, data + at + 3 + length);
    at += 3 + length;
    if (control & probecast::fuzz::kBusRepairFlag) probecast::fuzz::repairBusChecksum(message);
    const int r = pc_viewer_message(viewer, message.data(), static_cast<uint32_t>(message.size()));
    sink += static_cast<uint64_t>(r) + std::strlen(pc_viewer_error(viewer));
    // Everything a page reads, checked against the sizes it is told.
    const uint32_t n = pc_viewer_probe_count(viewer);
    if (n != pc_viewer_dim(viewer, 0) * pc_viewer_dim(viewer, 1) * pc_viewer_dim(viewer, 2)) __builtin_trap();
    if (const float* p = pc_viewer_probes(viewer)) sink += static_cast<uint64_t>(p[27 * size_t{n} - 1] != 0.0f);
    if (const uint8_t* a = pc_viewer_active(viewer)) sink += a[n - 1];
    if (const float* o = pc_viewer_offsets(viewer)) sink += static_cast<uint64_t>(o[3 * size_t{n} - 1] != 0.0f);
    sink += pc_viewer_checksum(viewer) + pc_viewer_bricks_held(viewer);
    sink += std::strlen(pc_viewer_scene_hash(viewer)) + std::strlen(pc_viewer_scene_manifest(viewer)) +
            std::strlen(pc_viewer_representation(viewer));
  }
  pc_viewer_free(viewer);
  static volatile uint64_t keep;
  keep = sink;
  return 0;
}
