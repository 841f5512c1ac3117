// Progress on stderr that fits where stderr goes: on a terminal a line redrawn in place with '\r'
// (and a bar), otherwise plain lines, at most one per kPlainLineSeconds plus the final state, so
// logs and pipes get no '\r'. `--quiet` (setQuiet) silences all of it; results go to stdout.
#pragma once

#include <chrono>
#include <string>

namespace probecast::app {

// Seconds between two plain progress lines when stderr is not a terminal.
inline constexpr double kPlainLineSeconds = 5.0;

void setQuiet(bool quiet);
bool quiet();

// A 30-character bar "[####    ]" for a fraction in [0, 1].
std::string progressBar(double fraction);

// One progress line labelled "label: ". Ends (a newline on a terminal, the final state elsewhere)
// at finish() or destruction.
class Progress {
 public:
  // `bar`: draw progressBar before the text.
  explicit Progress(std::string label, bool bar = true);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // The current state: fraction done (for the bar) and a description.
  void update(double fraction, const std::string& text);
  // A step's message (no bar, padded to clear the line on a terminal); on a pipe every message is
  // a line of its own.
  void message(const std::string& text);
  void finish();

 private:
  void plainLine(const std::string& line);

  std::string label_;
  bool bar_;
  bool terminal_;
  bool drawn_ = false;           // a '\r' line is on the terminal
  std::string pending_;          // plain mode: the latest state not yet printed
  bool printedAny_ = false;
  std::chrono::steady_clock::time_point lastLine_{};
};

// A benchmark's progress message as a line of its own (unless quiet).
void progressLine(const std::string& text);

}  // namespace probecast::app
