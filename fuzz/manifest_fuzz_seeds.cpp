// Writes the seed corpus for manifest_fuzz into a folder: manifests of every kind of scene and lighting.
#include <cstdio>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: manifest_fuzz_seeds OUTDIR\n");
    return 2;
  }
  const std::string hash(64, 'a');
  const char* manifests[] = {
      R"({"files":[],"format":1,"lighting":{},"scene":{"builtin":"cornell"}})",
      R"({"files":[],"format":1,"lighting":{"sky":[0.5,0.25,1.0]},"scene":{"builtin":"hall"}})",
      R"({"files":[{"bytes":1200,"path":"box.gltf","sha256":"HASH"},{"bytes":96,"path":"bin/box%20a.bin","sha256":"HASH"}],"format":1,"lighting":{},"scene":{"gltf":"box.gltf"}})",
      R"({"files":[{"bytes":10,"path":"s.glb","sha256":"HASH"},{"bytes":4096,"path":"environment/sky.hdr","sha256":"HASH"}],"format":1,"lighting":{"environment":{"file":"environment/sky.hdr","intensity":1.5,"rotation_deg":-90.0}},"scene":{"gltf":"s.glb"}})",
  };
  int k = 0;
  for (std::string m : manifests) {
    for (size_t at; (at = m.find("HASH")) != std::string::npos;) m.replace(at, 4, hash);
    std::ofstream(std::string(argv[1]) + "/manifest-" + std::to_string(k++), std::ios::binary) << m;
  }
  return 0;
}
