// bench adaptive's truth cache: a second run reads the converged volumes the first one stored and
// scores the same images; a damaged file is converged again, never read.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "adaptive_bench.h"

namespace probecast::bench {
namespace {

struct BenchRun {
  AdaptiveBenchResult result;
  std::vector<std::string> messages;
  int converged = 0;  // volumes converged by this run (not read from the cache)
};

BenchRun runTiny(const std::string& cache) {
  AdaptiveBenchOptions o;
  o.dims = {3, 3, 3};
  o.samplesPerProbe = 8;
  o.stillUpdates = 8;
  o.movingUpdates = 2;
  o.scoredUpdates = 2;
  o.fixedWMins = {0.25f};
  o.reconvergenceUpdates = 4;
  o.jumpUpdates = 4;
  o.reconvergenceSeeds = 1;
  o.width = 32;
  o.height = 20;
  o.truthCache = cache;
  BenchRun run;
  o.progress = [&](const std::string& m) {
    run.messages.push_back(m);
    if (m.find("converged volume at") != std::string::npos) ++run.converged;
  };
  run.result = runAdaptiveBench(o);
  return run;
}

// Every stream's scored PSNR, rule by rule: what the truth decides.
std::vector<double> scoredPsnr(const nlohmann::json& j) {
  std::vector<double> out;
  for (const auto& rule : j["rules"])
    for (const auto& stream : rule["streams"])
      for (const char* moment : {"still", "moving", "still_again"}) out.push_back(stream["psnr_db"][moment].get<double>());
  return out;
}

TEST(AdaptiveBench, TruthCacheIsReadBackAndDamagedFilesAreRemade) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "probecast_truth_cache_test";
  std::filesystem::remove_all(dir);
  const BenchRun first = runTiny(dir.string());
  // t = 0 (both still phases' start), the two moving updates' t and the last: 3 distinct t.
  EXPECT_EQ(first.converged, 3);
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files.push_back(e.path());
  ASSERT_EQ(files.size(), 3u);

  const BenchRun second = runTiny(dir.string());
  EXPECT_EQ(second.converged, 0);
  EXPECT_EQ(scoredPsnr(second.result.json), scoredPsnr(first.result.json));

  // A file cut short is refused by its checksum, said so, and converged again.
  std::filesystem::resize_file(files[0], std::filesystem::file_size(files[0]) / 2);
  const BenchRun third = runTiny(dir.string());
  EXPECT_EQ(third.converged, 1);
  bool said = false;
  for (const std::string& m : third.messages) said = said || m.find("unusable") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_EQ(scoredPsnr(third.result.json), scoredPsnr(first.result.json));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace probecast::bench
