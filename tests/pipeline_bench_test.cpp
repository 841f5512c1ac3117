// The Pareto front the pipeline benchmark marks, and the chart's y range.
#include <gtest/gtest.h>

#include "pipeline_bench.h"
#include "probecast/imaging/svg_chart.h"

namespace probecast::bench {
namespace {

TEST(PipelineBench, ParetoFrontKeepsOnlyPointsNothingBeatsOnBothCostAndQuality) {
  // (cost, quality): b beats a (cheaper and better); c is the best; d costs more than c for less;
  // e ties b on cost but is worse; f is cheapest and worst — still on the front.
  const std::vector<ParetoPoint> pts = {{10, 20}, {8, 25}, {30, 30}, {40, 29}, {8, 22}, {1, 5}};
  EXPECT_EQ(paretoFront(pts), (std::vector<size_t>{5, 1, 2}));
  EXPECT_TRUE(paretoFront({}).empty());
  EXPECT_EQ(paretoFront({{3, 3}}), (std::vector<size_t>{0}));
}

TEST(PipelineBench, ChartsOfPsnrFitTheirDataInsteadOfStartingAtZero) {
  imaging::ChartSpec spec;
  spec.yFromZero = false;
  const std::string fitted = imaging::renderSvgChart(spec, {{"s", {{1, 26.0, ""}, {2, 28.0, ""}}, false}});
  spec.yFromZero = true;
  const std::string zero = imaging::renderSvgChart(spec, {{"s", {{1, 26.0, ""}, {2, 28.0, ""}}, false}});
  const std::string yZeroTick = "text-anchor=\"end\">0<";  // y tick labels are right-aligned
  EXPECT_EQ(fitted.find(yZeroTick), std::string::npos);
  EXPECT_NE(zero.find(yZeroTick), std::string::npos);
}

}  // namespace
}  // namespace probecast::bench
