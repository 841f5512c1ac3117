// Writes the seed corpus for web_fuzz into a folder: the sample bus messages in a page's order
// and reversed (bricks before their volume message, which must wait for it).
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "bus_fuzz_common.h"

namespace {
void record(std::ofstream& out, const std::vector<uint8_t>& message) {
  out.put(0);
  out.put(static_cast<char>(message.size() & 0xff));
  out.put(static_cast<char>((message.size() >> 8) & 0xff));
  out.write(reinterpret_cast<const char*>(message.data()), static_cast<std::streamsize>(message.size()));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: web_fuzz_seeds OUTDIR\n");
    return 2;
  }
  // Per representation: a volume message, the same with offsets and a scene, then two brick versions.
  const auto messages = probecast::fuzz::sampleBusMessages();
  for (size_t i = 0; i + 3 < messages.size(); i += 4) {
    std::ofstream inOrder(std::string(argv[1]) + "/web-" + std::to_string(i) + "-in-order", std::ios::binary);
    for (size_t k = 0; k < 4; ++k) record(inOrder, messages[i + k]);
    std::ofstream volumeLast(std::string(argv[1]) + "/web-" + std::to_string(i) + "-volume-last", std::ios::binary);
    for (size_t k = 4; k-- > 0;) record(volumeLast, messages[i + k]);
  }
  return 0;
}
