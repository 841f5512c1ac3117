// `probecast demo`: for now, the codec benchmark on built-in environment maps, with a report.
// (The streaming demo — server, stereo and light-field viewers over loopback — replaces it when
// the updater, raster client and service exist.)
#include <filesystem>

#include <fmt/format.h>

#include "codec_bench.h"
#include "commands.h"

namespace probecast::app {

void addDemoCommand(CLI::App& app, int& exitCode) {
  CLI::App* demo = app.add_subcommand("demo", "the main job on built-in data; writes out/");
  auto out = std::make_shared<std::string>("out");
  demo->add_option("--out", *out, "output folder");
  demo->callback([out, &exitCode] {
    fmt::print("probecast demo: codec benchmark on the built-in probe set (two procedural environment maps)\n");
    bench::CodecBenchOptions options;
    options.maps = bench::builtinEnvMaps();
    options.frames = 40;
    options.command = commandLine();
    options.progress = [](const std::string& s) { fmt::print(stderr, "  {}\n", s); };
    const bench::CodecBenchResult r = bench::runCodecBench(options);
    const std::string dir = *out;
    writeTextFile(dir + "/codec.json", r.json.dump(2) + "\n");
    writeTextFile(dir + "/codec.svg", r.svg);
    std::string report = "# probecast demo report\n\n";
    report += "Codec benchmark on the built-in probe set (procedural sky and room maps), produced by `" +
              commandLine() + "`.\n\n![error against bytes](codec.svg)\n\n```\n" + r.table + "```\n\n";
    report += "Data: [codec.json](codec.json). Irradiance error is relative RMSE over 2048 equal-area normals "
              "against the brute-force convolution of each map.\n";
    writeTextFile(dir + "/report.md", report);
    fmt::print("{}", r.table);
    fmt::print("wrote {}/report.md, {}/codec.json, {}/codec.svg\n", dir, dir, dir);
    exitCode = 0;
  });
}

}  // namespace probecast::app
