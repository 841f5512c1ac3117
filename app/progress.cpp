#include "progress.h"

#include <algorithm>
#include <cstdio>
#include <utility>

#include <fmt/core.h>
#include <unistd.h>

namespace probecast::app {

namespace {
bool gQuiet = false;
}  // namespace

void setQuiet(bool q) { gQuiet = q; }
bool quiet() { return gQuiet; }

std::string progressBar(double fraction) {
  const int width = 30, filled = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * width);
  return "[" + std::string(static_cast<size_t>(filled), '#') + std::string(static_cast<size_t>(width - filled), ' ') +
         "]";
}

Progress::Progress(std::string label, bool bar)
    : label_(std::move(label)), bar_(bar), terminal_(isatty(fileno(stderr)) != 0) {}

Progress::~Progress() { finish(); }

void Progress::update(double fraction, const std::string& text) {
  if (gQuiet) return;
  const std::string line = bar_ ? progressBar(fraction) + " " + text : text;
  if (terminal_) {
    fmt::print(stderr, "\r{}: {}", label_, line);
    drawn_ = true;
    return;
  }
  const auto now = std::chrono::steady_clock::now();
  if (!printedAny_ || std::chrono::duration<double>(now - lastLine_).count() >= kPlainLineSeconds) {
    plainLine(line);
  } else {
    pending_ = line;
  }
}

void Progress::message(const std::string& text) {
  if (gQuiet) return;
  if (terminal_) {
    fmt::print(stderr, "\r{}: {:<90}", label_, text.substr(0, 90));
    drawn_ = true;
    return;
  }
  plainLine(text);
}

void Progress::finish() {
  if (gQuiet) return;
  if (terminal_) {
    if (drawn_) fmt::print(stderr, "\n");
    drawn_ = false;
  } else if (!pending_.empty()) {
    plainLine(pending_);
  }
}

void Progress::plainLine(const std::string& line) {
  fmt::print(stderr, "{}: {}\n", label_, line);
  pending_.clear();
  printedAny_ = true;
  lastLine_ = std::chrono::steady_clock::now();
}

void progressLine(const std::string& text) {
  if (!gQuiet) fmt::print(stderr, "{}\n", text);
}

}  // namespace probecast::app
