// Writes the seed corpus for gltf_fuzz into a folder: the repository's glTF test scenes (the
// animated Cornell box among them) as .glb files, each behind the 8-byte scene time the target reads.
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void put32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

// One .glb of a .gltf whose single buffer is the .bin beside it.
std::string glbOf(const std::string& gltfPath, const std::string& binPath) {
  nlohmann::json j = nlohmann::json::parse(readFile(gltfPath));
  std::string bin = readFile(binPath);
  j["buffers"] = nlohmann::json::array({{{"byteLength", bin.size()}}});
  std::string text = j.dump();
  while (text.size() % 4) text.push_back(' ');
  while (bin.size() % 4) bin.push_back('\0');
  std::string glb = "glTF";
  put32(glb, 2);
  put32(glb, static_cast<uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
  put32(glb, static_cast<uint32_t>(text.size()));
  glb += "JSON" + text;
  put32(glb, static_cast<uint32_t>(bin.size()));
  glb += std::string("BIN\0", 4) + bin;
  return glb;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: gltf_fuzz_seeds OUTDIR\n");
    return 2;
  }
  const std::string data = PROBECAST_TEST_DATA;
  const std::string scenes[][2] = {
      {"/scenes/cornell-animated/cornell-animated.gltf", "/scenes/cornell-animated/cornell-animated.bin"},
      {"/scenes/cornell-box/CornellBox-Original.gltf", "/scenes/cornell-box/CornellBox-Original.bin"},
  };
  int k = 0;
  for (const auto& s : scenes) {
    const std::string glb = glbOf(data + s[0], data + s[1]);
    for (double t : {0.0, 1.5}) {
      std::string seed(8, '\0');
      std::memcpy(seed.data(), &t, 8);
      std::ofstream(std::string(argv[1]) + "/gltf-" + std::to_string(k++), std::ios::binary) << seed + glb;
    }
  }
  return 0;
}
