// libFuzzer target: arbitrary bytes as a scene manifest (scene_package.h), as a viewer receives
// one in a volume description. An accepted manifest must be canonical, name only safe paths whose
// sizes add up to at most kMaxPackageBytes, list the file its scene and environment name, and hash
// to the SHA-256 of its bytes. Whatever is printed of it (refusals, describe()) holds no control
// character and no byte that is not UTF-8.
#include <cstdlib>
#include <string_view>

#include "probecast/service/scene_package.h"

using namespace probecast::service;

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

bool listed(const ScenePackage& p, const std::string& path) {
  for (const PackageFile& f : p.files)
    if (f.path == path) return true;
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  ScenePackage p;
  std::string error;
  const auto printable = [](const std::string& s) {
    for (unsigned char c : s)
      if (c < 0x20 || c == 0x7f || c == 0xff) return false;
    return s.find("\xc2\x9b") == std::string::npos;
  };
  require(printable(printableText(text, size + 1)));
  if (!parseManifest(text, p, error)) {
    require(!error.empty() && printable(error));
    return 0;
  }
  require(p.manifest == text && p.totalBytes() <= kMaxPackageBytes);
  require(printable(p.describe()));
  require(p.hash == sha256(text));
  require(p.files.size() <= kMaxPackageFiles);
  for (const PackageFile& f : p.files) require(isSafePackagePath(f.path) && f.source.empty());
  require(p.builtin() || listed(p, p.scene));
  if (p.lighting.kind == SceneLighting::Kind::Environment) require(listed(p, p.lighting.file));
  (void)p.describe();
  (void)p.sceneHash();
  return 0;
}
