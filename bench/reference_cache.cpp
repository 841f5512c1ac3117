// The reference cache (harness.h): path-traced references in two halves of independent samples,
// kept on disk by everything they are made of, each half's pixels checked when read back.
#include "harness.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "probecast/imaging/image_io.h"

namespace probecast::bench {

std::string defaultReferenceCacheDir() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg != nullptr && *xdg == '/') return std::string(xdg) + "/probecast/references";
  const char* home = std::getenv("HOME");
  if (home == nullptr || *home == '\0')
    throw std::runtime_error("neither XDG_CACHE_HOME nor HOME is set: give --reference-cache DIR");
  return std::string(home) + "/.cache/probecast/references";
}

ReferenceCache::ReferenceCache(renderer::VulkanContext& context, std::string dir,
                               std::function<void(const std::string&)> progress)
    : context_(context), dir_(std::move(dir)), progress_(std::move(progress)) {
  if (dir_.empty()) dir_ = defaultReferenceCacheDir();
}

namespace {

std::string halfName(int k) { return k == 0 ? "a" : "b"; }

nlohmann::json readJsonFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return nlohmann::json(nlohmann::json::value_t::discarded);
  std::stringstream text;
  text << in.rdbuf();
  return nlohmann::json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::string& bytes) {
  {
    std::ofstream out(path + ".tmp", std::ios::binary);
    out << bytes;
    if (!out) throw std::runtime_error("cache: cannot write " + path + ".tmp");
  }
  std::error_code ec;
  std::filesystem::rename(path + ".tmp", path, ec);
  if (ec) throw std::runtime_error("cache: " + path + ": " + ec.message());
}

bool ReferenceCache::loadHalf(const nlohmann::json& key, const std::string& stem, int k, uint32_t seed, uint32_t spp,
                              renderer::Image& out, double& seconds, std::string& why) const {
  const std::string base = dir_ + "/" + stem + "." + halfName(k);
  if (!std::filesystem::exists(base + ".json")) {
    why = "absent";
    return false;
  }
  const nlohmann::json entry = readJsonFile(base + ".json");
  if (entry.is_discarded() || !entry.is_object()) {
    why = base + ".json is not valid JSON";
    return false;
  }
  if (!entry.contains("key") || entry["key"].dump() != key.dump() || entry.value("seed", 0u) != seed ||
      entry.value("spp", 0u) != spp) {
    why = base + ".json holds another key";
    return false;
  }
  const auto w = static_cast<int>(key["size"][0].get<uint32_t>()), h = static_cast<int>(key["size"][1].get<uint32_t>());
  int iw = 0, ih = 0;
  std::string error;
  if (!imaging::readExr(base + ".exr", out.rgb, iw, ih, error)) {
    why = error;
    return false;
  }
  if (iw != w || ih != h) {
    why = fmt::format("{}.exr is {}x{}, the key says {}x{}", base, iw, ih, w, h);
    return false;
  }
  if (imaging::findNonFinitePixels(out.rgb).count > 0) {
    why = base + ".exr holds non-finite pixels";
    return false;
  }
  if (!entry.contains("pixels") || !entry["pixels"].is_string() || entry["pixels"].get<std::string>() != pixelHash(out.rgb)) {
    why = base + ".exr does not match the pixel hash in its JSON";
    return false;
  }
  out.width = static_cast<uint32_t>(w);
  out.height = static_cast<uint32_t>(h);
  seconds = entry.value("seconds", 0.0);
  return true;
}

double ReferenceCache::renderHalf(const scene::Scene& scene, const ReferenceRequest& request, const nlohmann::json& key,
                                  const std::string& stem, int k, uint32_t seed, uint32_t spp, renderer::Image& out,
                                  std::string& pixels) {
  const renderer::ReferenceOptions& ro = request.options;
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw std::runtime_error("--reference-cache " + dir_ + ": " + ec.message());
  renderer::ReferenceOptions o = ro;
  o.samplesPerPixel = spp;
  o.seed = seed;
  int lastPercent = -1;
  const auto t0 = std::chrono::steady_clock::now();
  o.progress = [&](uint32_t done, uint32_t total) {
    const int percent = static_cast<int>(100.0 * done / total);
    if (percent / 10 == lastPercent / 10 && done != total) return;
    lastPercent = percent;
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    sayProgress(progress_, fmt::format("reference {}: half {} of 2, {}/{} spp ({}%), {}x{}, {:.0f} s", stem, k + 1, done,
                                       total, percent, ro.width, ro.height, sec));
  };
  renderer::ReferenceStats stats;
  const renderer::Image image = renderer::renderReference(context_, scene, request.camera, o, &stats);
  ++renders_;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (stats.droppedSamples > 0)
    sayProgress(progress_, fmt::format("reference {}: {} non-finite samples dropped", stem, stats.droppedSamples));
  // Written, then read back: what is returned is exactly what a later run will load.
  const std::string base = dir_ + "/" + stem;
  const std::string path = base + "." + halfName(k) + ".exr";
  std::string error;
  int w = 0, h = 0;
  if (!imaging::writeExr(path + ".tmp", image.rgb, static_cast<int>(image.width), static_cast<int>(image.height),
                         error) ||
      !imaging::readExr(path + ".tmp", out.rgb, w, h, error))
    throw std::runtime_error("reference cache: " + error);
  std::filesystem::rename(path + ".tmp", path, ec);
  if (ec) throw std::runtime_error("reference cache: " + path + ": " + ec.message());
  out.width = image.width;
  out.height = image.height;
  pixels = pixelHash(out.rgb);
  // The half's JSON goes last: an image without one (an interrupted write) is simply absent.
  writeFileAtomically(base + "." + halfName(k) + ".json",
                      nlohmann::json{{"key", key},
                                     {"half", halfName(k)},
                                     {"seed", seed},
                                     {"spp", spp},
                                     {"seconds", seconds},
                                     {"device", context_.deviceName()},
                                     {"pixels", pixels}}
                              .dump(2) +
                          "\n");
  return seconds;
}

namespace {

// The reference from its two halves: their mean, and their difference as its noise floor.
void combineHalves(Reference& ref) {
  ref.mean.width = ref.halfA.width;
  ref.mean.height = ref.halfA.height;
  ref.mean.rgb.resize(ref.halfA.rgb.size());
  for (size_t i = 0; i < ref.mean.rgb.size(); ++i) ref.mean.rgb[i] = 0.5f * (ref.halfA.rgb[i] + ref.halfB.rgb[i]);
  ref.floor = imaging::compareImages(ref.halfA.rgb, ref.halfB.rgb, static_cast<int>(ref.halfA.width),
                                     static_cast<int>(ref.halfA.height));
  ref.accuracyDb = ref.floor.psnrDb + 10.0 * std::log10(4.0);
}

}  // namespace

Reference ReferenceCache::get(const scene::Scene& scene, const ReferenceRequest& request) {
  const renderer::ReferenceOptions& ro = request.options;
  if (ro.samplesPerPixel < 2)
    throw std::runtime_error(fmt::format("a reference needs at least 2 samples per pixel (two halves), not {}",
                                         ro.samplesPerPixel));
  const nlohmann::json key = referenceKey(scene, request);
  Reference ref;
  ref.key = referenceKeyStem(key);
  const uint32_t half = (ro.samplesPerPixel + 1) / 2;
  const uint32_t seeds[2] = {ro.seed, ro.seed + kSecondSeedOffset};
  renderer::Image* halves[2] = {&ref.halfA, &ref.halfB};
  nlohmann::json pixels = nlohmann::json::array();
  int loaded = 0;
  // Each half is stored on its own as soon as it is traced, so an interrupted run keeps what it finished.
  for (int k = 0; k < 2; ++k) {
    std::string why;
    double seconds = 0.0;
    if (loadHalf(key, ref.key, k, seeds[k], half, *halves[k], seconds, why)) {
      ++loaded;
      ref.seconds += seconds;
      pixels.push_back(pixelHash(halves[k]->rgb));
      continue;
    }
    if (why != "absent")
      sayProgress(progress_, fmt::format("reference {}: half {} unusable ({}); rendering it again", ref.key, halfName(k), why));
    std::string hash;
    ref.seconds += renderHalf(scene, request, key, ref.key, k, seeds[k], half, *halves[k], hash);
    pixels.push_back(hash);
  }
  ref.fromCache = loaded == 2;
  if (ref.fromCache) {
    sayProgress(progress_, fmt::format("reference {}: from the cache ({} spp, {}x{})", ref.key, ro.samplesPerPixel,
                                       ro.width, ro.height));
  } else {
    // The summary of the whole entry, for people and scripts (loading checks each half's own JSON).
    writeFileAtomically(dir_ + "/" + ref.key + ".json", nlohmann::json{{"key", key},
                                                                       {"spp", half * 2},
                                                                       {"spp_per_half", half},
                                                                       {"seeds", {seeds[0], seeds[1]}},
                                                                       {"seconds", ref.seconds},
                                                                       {"pixels", pixels}}
                                                                .dump(2) +
                                                            "\n");
    sayProgress(progress_, fmt::format("reference {}: {} of 2 halves rendered, {:.1f} s in all, stored in {}", ref.key,
                                       2 - loaded, ref.seconds, dir_));
  }
  combineHalves(ref);
  return ref;
}

}  // namespace probecast::bench
