// probecast: one binary, one subcommand per job (see README.md).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "progress.h"

namespace {

// CLI11 reads "nan", "inf" and overflowing literals into floating-point options, and its Range
// checks compare false against NaN, so NaN would pass every range. Every floating-point option of
// every command therefore also refuses what is not a finite number.
void refuseNonFiniteNumbers(CLI::App& app) {
  const CLI::Validator finite(
      [](std::string& value) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(value.c_str(), &end);
        if (end != value.c_str() && !std::isfinite(v)) return "not a finite number: " + value;
        return {};
      },
      "", "FINITE");
  for (CLI::Option* option : app.get_options())
    if (option->get_type_name().find("FLOAT") != std::string::npos) option->check(finite);
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) refuseNonFiniteNumbers(*sub);
}

}  // namespace

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
  probecast::app::addServeCommand(app);
  probecast::app::addSubscribeCommand(app);
  probecast::app::addEdgeCommand(app);
  probecast::app::addCompareCommand(app);
  probecast::app::addViewCommand(app);
  refuseNonFiniteNumbers(app);
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
