// probecast: one binary, one subcommand per job (see README.md).
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "progress.h"

int main(int argc, char** argv) {
  probecast::app::setCommandLine(argc, argv);
  CLI::App app{"probecast: streaming light-probe codec and service for real-time global illumination"};
  app.require_subcommand(1);
  app.fallthrough();  // top-level flags (--quiet) are accepted after the subcommand too
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "no progress output on stderr (results and errors still print)");
  app.parse_complete_callback([&quiet] { probecast::app::setQuiet(quiet); });
  probecast::app::addDemoCommand(app);
  probecast::app::addBenchCommands(app);
  probecast::app::addBakeCommand(app);
  probecast::app::addReferenceCommand(app);
  probecast::app::addServeCommands(app);
  probecast::app::addEdgeCommand(app);
  probecast::app::addCompareCommand(app);
  probecast::app::addViewCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "probecast: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
