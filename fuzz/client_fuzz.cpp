// libFuzzer target: what a hostile server sends a viewer, through the client's own checks
// (service/client/stream_checks.h), in the order a viewer meets it: a volume description (its
// scene manifest hashed and parsed, its size and scene held to the configuration), frames (scene
// state, section counts, then the codec) and, for a described scene with files, the pieces of a
// GetScene transfer written into a scene cache (PackageWriter) and finished. Whatever is accepted
// must hold the client's promises: a volume within the probe limit, a package written only inside
// the cache with every file of its listed size.
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <unistd.h>

#include "client_fuzz_common.h"
#include "probecast.pb.h"
#include "probecast/service/scene_package.h"
#include "stream_checks.h"

using namespace probecast;
using namespace probecast::service;
namespace fs = std::filesystem;

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

constexpr uint64_t kFuzzMaxProbes = 1u << 12;
constexpr uint64_t kFuzzMaxSceneBytes = 1u << 16;

const fs::path& cacheDir() {
  static const fs::path dir = fs::temp_directory_path() / ("probecast-client-fuzz-" + std::to_string(getpid()));
  return dir;
}

struct Viewer {
  ClientConfig config;
  std::unique_ptr<StreamDecoder> decoder;
  Description held;
  std::unique_ptr<PackageWriter> writer;

  void onMessage(const v1::ServerMessage& m) {
    std::string why;
    if (m.has_volume()) {
      Description d;
      const Verdict v = checkDescription(m.volume(), config, d, why);
      if (v != Verdict::Accept) return require(!why.empty());
      require(probeCount(d.layout) <= config.maxProbes);
      decoder = std::make_unique<StreamDecoder>(d.layout);
      writer.reset();
      ScenePackage named;
      if (d.scene.known() && parseManifest(d.scene.manifest, named, why) && !named.files.empty() &&
          named.totalBytes() <= kFuzzMaxSceneBytes) {
        writer = std::make_unique<PackageWriter>(cacheDir(), named);
        if (!writer->begin(why)) writer.reset();
      }
      held = std::move(d);
    } else if (m.has_frame()) {
      bus::SceneState state;
      if (!checkFrame(m.frame(), state, why)) return require(!why.empty());
      if (!decoder) return;
      const auto* data = reinterpret_cast<const uint8_t*>(m.frame().payload().data());
      (void)decoder->apply(data, m.frame().payload().size());
    }
  }

  void onChunk(const v1::SceneChunk& c) {
    std::string why;
    if (writer && !writer->write(c.path(), c.offset(), c.data(), why)) writer.reset();
  }

  void finish() {
    if (!writer) return;
    ScenePackage out;
    std::string why;
    if (writer->finish(out, why)) {  // every hash matched: the files are inside the cache, whole
      for (const PackageFile& f : out.files) {
        std::error_code ec;
        require(isSafePackagePath(f.path) && fs::file_size(f.source, ec) == f.bytes && !ec);
        require(f.source.string().rfind(cacheDir().string() + "/", 0) == 0);
      }
    }
    writer.reset();
    std::error_code ec;
    fs::remove_all(cacheDir(), ec);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Viewer viewer;
  viewer.config.maxProbes = kFuzzMaxProbes;
  size_t at = 0;
  while (at + 3 <= size) {
    const uint8_t kind = data[at];
    const size_t n = std::min<size_t>(data[at + 1] | (size_t{data[at + 2]} << 8), size - at - 3);
    const auto* bytes = data + at + 3;
    at += 3 + n;
    if ((kind & 1) == fuzz::kServerMessage) {
      v1::ServerMessage m;
      if (m.ParseFromArray(bytes, static_cast<int>(n))) viewer.onMessage(m);
    } else {
      v1::SceneChunk c;
      if (c.ParseFromArray(bytes, static_cast<int>(n))) viewer.onChunk(c);
    }
  }
  viewer.finish();
  return 0;
}
