// Writes the seed corpus for bus_fuzz into a folder: valid bus messages, as they are and with the
// checksum-repair flag.
#include <cstdio>
#include <fstream>
#include <string>

#include "bus_fuzz_common.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: bus_fuzz_seeds OUTDIR\n");
    return 2;
  }
  const auto messages = probecast::fuzz::sampleBusMessages();
  for (size_t i = 0; i < messages.size(); ++i)
    for (uint8_t control : {uint8_t{0}, probecast::fuzz::kBusRepairFlag}) {
      std::ofstream out(std::string(argv[1]) + "/bus-" + std::to_string(i) + "-" + std::to_string(control),
                        std::ios::binary);
      out.put(static_cast<char>(control));
      out.write(reinterpret_cast<const char*>(messages[i].data()), static_cast<std::streamsize>(messages[i].size()));
    }
  return 0;
}
