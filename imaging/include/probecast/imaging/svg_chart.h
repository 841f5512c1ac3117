// A small SVG scatter/line chart for benchmark output (no dependencies).
#pragma once

#include <string>
#include <vector>

namespace probecast::imaging {

struct ChartPoint {
  double x = 0;
  double y = 0;
  std::string label;  // drawn next to the point when not empty
};

struct ChartSeries {
  std::string name;
  std::vector<ChartPoint> points;
  bool connect = false;  // draw a polyline through the points in order
};

struct ChartSpec {
  std::string title;
  std::string xLabel;
  std::string yLabel;
  bool logX = false;
  bool logY = false;
  bool yFromZero = true;  // linear y: start at 0 for non-negative data (false: fit the data)
  std::string footnote;  // e.g. the command that produced the data
};

std::string renderSvgChart(const ChartSpec& spec, const std::vector<ChartSeries>& series);

}  // namespace probecast::imaging
