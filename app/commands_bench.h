// What the files of `probecast bench` share: the subcommands a file of its own adds, which
// addBenchCommands (commands_bench.cpp) adds with the rest, in the order --help lists them.
#pragma once

#include <CLI/CLI.hpp>

namespace probecast::app {

// The raster client and the reference tracer against references (commands_bench_render.cpp).
void addBenchRaster(CLI::App* bench);
void addBenchScene(CLI::App* bench);
void addBenchPipeline(CLI::App* bench);
void addBenchEnvironment(CLI::App* bench);
void addBenchPanel(CLI::App* bench);

// The probe updater over many updates (commands_bench_updater.cpp).
void addBenchUpdate(CLI::App* bench);
void addBenchMotion(CLI::App* bench);
void addBenchAdaptive(CLI::App* bench);

// `probecast bench video` (commands_bench_video.cpp).
void addBenchVideo(CLI::App* bench);

}  // namespace probecast::app
