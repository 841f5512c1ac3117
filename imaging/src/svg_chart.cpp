#include "probecast/imaging/svg_chart.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace probecast::imaging {
namespace {

constexpr const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2"};

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

struct Axis {
  double lo, hi;
  bool log;
  double map(double v, double a, double b) const {
    const double t = log ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (v - lo) / (hi - lo);
    return a + t * (b - a);
  }
  std::vector<double> ticks() const {
    std::vector<double> t;
    if (log) {
      for (double p = std::floor(std::log10(lo)); p <= std::ceil(std::log10(hi)); p += 1)
        for (double m : {1.0, 2.0, 5.0}) {
          const double v = m * std::pow(10.0, p);
          if (v >= lo * 0.999 && v <= hi * 1.001) t.push_back(v);
        }
      return t;
    }
    const double raw = (hi - lo) / 6;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double step = raw / mag < 2 ? 2 * mag : (raw / mag < 5 ? 5 * mag : 10 * mag);
    for (double v = std::ceil(lo / step) * step; v <= hi + 1e-12; v += step) t.push_back(v);
    return t;
  }
};

Axis makeAxis(std::vector<double> values, bool log, bool fromZero = true) {
  if (log) values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !(v > 0); }), values.end());
  if (values.empty()) return {log ? 1.0 : 0.0, log ? 10.0 : 1.0, log};
  double lo = *std::min_element(values.begin(), values.end());
  double hi = *std::max_element(values.begin(), values.end());
  if (log) {
    lo /= 1.3;
    hi *= 1.3;
  } else {
    const double pad = hi > lo ? 0.08 * (hi - lo) : std::max(1e-9, std::fabs(hi) * 0.1 + 1e-9);
    lo = fromZero && lo >= 0 ? 0.0 : lo - pad;
    hi += pad;
  }
  return {lo, hi, log};
}

std::string tickLabel(double v) {
  if (v == 0) return "0";
  const double a = std::fabs(v);
  if (a >= 1e6 || a < 0.001) return fmt::format("{:.0e}", v);
  if (a >= 1000) return fmt::format("{:.0f}", v);
  return fmt::format("{:g}", v);
}

}  // namespace

std::string renderSvgChart(const ChartSpec& spec, const std::vector<ChartSeries>& series) {
  const double W = 760, H = 500, left = 80, right = 190, top = 50, bottom = 80;
  std::vector<double> xs, ys;
  for (const auto& s : series)
    for (const auto& p : s.points) {
      xs.push_back(p.x);
      ys.push_back(p.y);
    }
  const Axis ax = makeAxis(xs, spec.logX), ay = makeAxis(ys, spec.logY, spec.yFromZero);
  const double x0 = left, x1 = W - right, y0 = H - bottom, y1 = top;
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      W, H, W, H);
  svg += fmt::format("<text x=\"{}\" y=\"28\" font-size=\"16\" font-weight=\"bold\">{}</text>\n", left, escape(spec.title));
  for (double t : ax.ticks()) {
    const double x = ax.map(t, x0, x1);
    svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"#ddd\"/>"
                       "<text x=\"{0:.1f}\" y=\"{3}\" text-anchor=\"middle\">{4}</text>\n",
                       x, y0, y1, y0 + 16, tickLabel(t));
  }
  for (double t : ay.ticks()) {
    const double y = ay.map(t, y0, y1);
    svg += fmt::format("<line x1=\"{0}\" y1=\"{1:.1f}\" x2=\"{2}\" y2=\"{1:.1f}\" stroke=\"#ddd\"/>"
                       "<text x=\"{3}\" y=\"{4:.1f}\" text-anchor=\"end\">{5}</text>\n",
                       x0, y, x1, x0 - 6, y + 4, tickLabel(t));
  }
  svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\"/>\n", x0, y1,
                     x1 - x0, y0 - y1);
  svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", (x0 + x1) / 2, y0 + 40,
                     escape(spec.xLabel + (spec.logX ? " (log)" : "")));
  svg += fmt::format("<text transform=\"translate(20,{}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n",
                     (y0 + y1) / 2, escape(spec.yLabel + (spec.logY ? " (log)" : "")));
  for (size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    const char* color = kColors[k % std::size(kColors)];
    std::string poly;
    for (const auto& p : s.points) {
      if ((spec.logX && !(p.x > 0)) || (spec.logY && !(p.y > 0))) continue;
      const double x = ax.map(p.x, x0, x1), y = ay.map(p.y, y0, y1);
      poly += fmt::format("{:.1f},{:.1f} ", x, y);
      svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"4\" fill=\"{}\"/>\n", x, y, color);
      if (!p.label.empty())
        svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"10\" fill=\"{}\">{}</text>\n", x + 6, y - 6,
                           color, escape(p.label));
    }
    if (s.connect && !poly.empty())
      svg += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\"/>\n", poly, color);
    const double ly = top + 20 + 18 * static_cast<double>(k);
    svg += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"5\" fill=\"{}\"/><text x=\"{}\" y=\"{}\">{}</text>\n", x1 + 20,
                       ly - 4, color, x1 + 30, ly, escape(s.name));
  }
  if (!spec.footnote.empty())
    svg += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"10\" fill=\"#555\">{}</text>\n", left, H - 12,
                       escape(spec.footnote));
  svg += "</svg>\n";
  return svg;
}

}  // namespace probecast::imaging
