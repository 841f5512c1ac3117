// What the files of `probecast bench` share: the subcommands a file of its own adds, which
// addBenchCommands (commands_bench.cpp) adds with the rest, in the order --help lists them.
#pragma once

#include <CLI/CLI.hpp>

namespace probecast::app {

// `probecast bench video` (commands_bench_video.cpp).
void addBenchVideo(CLI::App* bench);

}  // namespace probecast::app
