#include "renderer/metrics/svg_plot.h"

#include "renderer/metrics/ticks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace pdflab {

namespace {

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

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// Fourteen distinguishable colours: a report compares a dozen strategies on one plot.
constexpr const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
                                    "#17becf", "#7f7f7f", "#bcbd22", "#000000", "#6b6ecf", "#e7ba52", "#843c39"};

// The parts every plot shares: the document, its title, the grid lines with
// their tick labels, the plot box, the axis labels and the legend beside it.
struct Frame {
  const PlotOptions& o;
  double left, top, pw, ph;
  std::string svg;
  double legend_y;

  Frame(const PlotOptions& options, double left_margin, double right_margin)
      : o(options), left(left_margin), top(40), pw(o.width - left_margin - right_margin), ph(o.height - 40 - 60) {
    svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(o.width) + "\" height=\"" +
          std::to_string(o.height) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
    svg += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    // Centred over the plot, but never past the left edge when a wide legend
    // leaves the plot narrower than the title (about 0.55 em a character).
    const double half_title = 0.5 * 0.55 * 15.0 * static_cast<double>(o.title.size());
    svg += "<text x=\"" + fmt("%.1f", std::max(left + pw / 2, 8.0 + half_title)) +
           "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" + escape(o.title) + "</text>\n";
    legend_y = top + 10;
  }
  void vertical_grid(double x, const std::string& label) {
    svg += "<line x1=\"" + fmt("%.1f", x) + "\" y1=\"" + fmt("%.1f", top) + "\" x2=\"" + fmt("%.1f", x) + "\" y2=\"" +
           fmt("%.1f", top + ph) + "\" stroke=\"#ddd\"/>\n";
    svg += "<text x=\"" + fmt("%.1f", x) + "\" y=\"" + fmt("%.1f", top + ph + 18) + "\" text-anchor=\"middle\">" +
           label + "</text>\n";
  }
  void horizontal_grid(double y, const std::string& label) {
    svg += "<line x1=\"" + fmt("%.1f", left) + "\" y1=\"" + fmt("%.1f", y) + "\" x2=\"" + fmt("%.1f", left + pw) +
           "\" y2=\"" + fmt("%.1f", y) + "\" stroke=\"#ddd\"/>\n";
    svg += "<text x=\"" + fmt("%.1f", left - 8) + "\" y=\"" + fmt("%.1f", y + 4) + "\" text-anchor=\"end\">" + label +
           "</text>\n";
  }
  void box_and_labels() {
    svg += "<rect x=\"" + fmt("%.1f", left) + "\" y=\"" + fmt("%.1f", top) + "\" width=\"" + fmt("%.1f", pw) +
           "\" height=\"" + fmt("%.1f", ph) + "\" fill=\"none\" stroke=\"#333\"/>\n";
    svg += "<text x=\"" + fmt("%.1f", left + pw / 2) + "\" y=\"" + fmt("%.1f", o.height - 15.0) +
           "\" text-anchor=\"middle\">" + escape(o.x_label) + "</text>\n";
    svg += "<text transform=\"translate(20," + fmt("%.1f", top + ph / 2) + ") rotate(-90)\" text-anchor=\"middle\">" +
           escape(o.y_label) + "</text>\n";
  }
  void legend(const std::string& colour, const std::string& label, bool dashed) {
    svg += "<line x1=\"" + fmt("%.1f", left + pw + 15) + "\" y1=\"" + fmt("%.1f", legend_y) + "\" x2=\"" +
           fmt("%.1f", left + pw + 40) + "\" y2=\"" + fmt("%.1f", legend_y) + "\" stroke=\"" + colour +
           "\" stroke-width=\"2\"" + (dashed ? " stroke-dasharray=\"5,4\"" : "") + "/>\n";
    svg += "<text x=\"" + fmt("%.1f", left + pw + 45) + "\" y=\"" + fmt("%.1f", legend_y + 4) + "\">" + escape(label) +
           "</text>\n";
    legend_y += 20;
  }
};

// The legend sits right of the plot; long mixture names must fit inside the
// picture (about 7 px a character at 12 px sans-serif).
double right_margin(const std::vector<PlotSeries>& series, std::size_t longest) {
  for (const auto& s : series) longest = std::max(longest, s.label.size());
  return std::max(200.0, 60.0 + 7.0 * static_cast<double>(longest));
}

}  // namespace

std::string loglog_svg(const std::vector<PlotSeries>& series, const PlotOptions& o) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = 0.0, y0 = x0, y1 = 0.0;
  for (const auto& s : series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!(s.x[i] > 0.0) || !(s.y[i] > 0.0) || !std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]), y1 = std::max(y1, s.y[i]);
    }
  if (!(x1 > 0.0)) x0 = 1.0, x1 = 10.0, y0 = 1.0, y1 = 10.0;
  // Whole decades, so the grid lines fall on powers of ten.
  const double lx0 = std::floor(std::log10(x0)), lx1 = std::max(lx0 + 1.0, std::ceil(std::log10(x1)));
  const double ly0 = std::floor(std::log10(y0)), ly1 = std::max(ly0 + 1.0, std::ceil(std::log10(y1)));

  Frame f(o, 80, right_margin(series, o.guide_label.size()));
  const double left = f.left, top = f.top, pw = f.pw, ph = f.ph;
  auto px = [&](double x) { return left + (std::log10(x) - lx0) / (lx1 - lx0) * pw; };
  auto py = [&](double y) { return top + (ly1 - std::log10(y)) / (ly1 - ly0) * ph; };
  for (double d = lx0; d <= lx1 + 1e-9; d += 1.0)
    f.vertical_grid(left + (d - lx0) / (lx1 - lx0) * pw, tick_label(std::pow(10.0, d)));
  for (double d = ly0; d <= ly1 + 1e-9; d += 1.0)
    f.horizontal_grid(top + (ly1 - d) / (ly1 - ly0) * ph, tick_label(std::pow(10.0, d)));
  f.box_and_labels();
  std::string& svg = f.svg;
  auto legend = [&](const std::string& colour, const std::string& label, bool dashed) { f.legend(colour, label, dashed); };

  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    const std::string colour = kColours[k % (sizeof kColours / sizeof kColours[0])];
    std::string points, last;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!(s.x[i] > 0.0) || !(s.y[i] > 0.0) || !std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      last = "cx=\"" + fmt("%.1f", px(s.x[i])) + "\" cy=\"" + fmt("%.1f", py(s.y[i])) + "\"";
      points += fmt("%.1f", px(s.x[i])) + "," + fmt("%.1f", py(s.y[i])) + " ";
    }
    svg += "<polyline fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"2\" points=\"" + points + "\"/>\n";
    // A line of one point draws nothing; the end marker also shows where each
    // strategy stopped, which is what an equal-time comparison reads off.
    if (!last.empty()) svg += "<circle " + last + " r=\"3.5\" fill=\"" + colour + "\"/>\n";
    legend(colour, s.label, false);
  }

  if (o.guide_slope != 0.0 && !series.empty() && !series[0].x.empty()) {
    // Through the first series' first valid point, across the whole x range.
    double gx = 0.0, gy = 0.0;
    for (std::size_t i = 0; i < series[0].x.size(); ++i)
      if (series[0].x[i] > 0.0 && series[0].y[i] > 0.0) {
        gx = series[0].x[i], gy = series[0].y[i];
        break;
      }
    if (gx > 0.0) {
      // The line log y = log gy + slope (log x - log gx), clipped to the plot box
      // in log space (so it renders the same in every SVG viewer).
      const double s0 = o.guide_slope, c0 = std::log10(gy) - s0 * std::log10(gx);
      double la = lx0, lb = lx1;
      auto ly_at = [&](double lx) { return c0 + s0 * lx; };
      auto lx_at = [&](double ly) { return (ly - c0) / s0; };
      for (double edge : {ly0, ly1}) {
        const double cross_x = lx_at(edge);
        if (cross_x > la && cross_x < lb) {
          // Keep the part inside: drop the side whose y lies beyond this edge.
          const bool left_outside = (edge == ly1) ? ly_at(la) > ly1 : ly_at(la) < ly0;
          (left_outside ? la : lb) = cross_x;
        }
      }
      if (ly_at(la) <= ly1 + 1e-9 && ly_at(la) >= ly0 - 1e-9) {
        const double xa = std::pow(10.0, la), xb = std::pow(10.0, lb);
        svg += "<line x1=\"" + fmt("%.1f", px(xa)) + "\" y1=\"" + fmt("%.1f", py(std::pow(10.0, ly_at(la)))) +
               "\" x2=\"" + fmt("%.1f", px(xb)) + "\" y2=\"" + fmt("%.1f", py(std::pow(10.0, ly_at(lb)))) +
               "\" stroke=\"#555\" stroke-width=\"1.5\" stroke-dasharray=\"6,4\"/>\n";
      }
      legend("#555", o.guide_label, true);
    }
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace pdflab

namespace pdflab {

std::string linear_svg(const std::vector<PlotSeries>& series, const PlotOptions& o) {
  double y1 = 0.0;
  for (const auto& s : series)
    for (std::size_t i = 0; i < s.y.size(); ++i) {
      if (std::isfinite(s.y[i])) y1 = std::max(y1, s.y[i]);
      if (i < s.y_hi.size() && std::isfinite(s.y_hi[i])) y1 = std::max(y1, s.y_hi[i]);
    }
  if (!(y1 > 0.0)) y1 = 1.0;
  // A round top: 1, 2 or 5 times a power of ten, five grid lines.
  const double top_value = nice_ceiling(y1 * (1.0 + 1e-9));
  const double x0 = o.x_min, x1 = o.x_max > o.x_min ? o.x_max : o.x_min + 1.0;

  Frame f(o, 90, right_margin(series, o.marker_label.size()));
  const double left = f.left, top = f.top, pw = f.pw, ph = f.ph;
  auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * pw; };
  auto py = [&](double y) { return top + (1.0 - y / top_value) * ph; };
  std::string& svg = f.svg;
  if (std::isfinite(o.marker_x)) {
    const double a = px(std::clamp(o.marker_lo, x0, x1)), b = px(std::clamp(o.marker_hi, x0, x1));
    svg += "<rect x=\"" + fmt("%.1f", std::min(a, b)) + "\" y=\"" + fmt("%.1f", top) + "\" width=\"" +
           fmt("%.1f", std::fabs(b - a)) + "\" height=\"" + fmt("%.1f", ph) + "\" fill=\"#fde9b8\"/>\n";
  }
  // Ticks at 1, 2 or 5 times a power of ten, at most ten steps over the range.
  const double x_step = nice_ceiling((x1 - x0) / 10.0 * (1.0 - 1e-9));
  for (double xv = std::ceil(x0 / x_step - 1e-9) * x_step; xv <= x1 + 1e-9 * x_step; xv += x_step)
    f.vertical_grid(px(xv), tick_label(xv));
  for (int k = 0; k <= 5; ++k) f.horizontal_grid(py(top_value * k / 5.0), tick_label(top_value * k / 5.0));
  f.box_and_labels();
  auto legend = [&](const std::string& colour, const std::string& label, bool dashed) { f.legend(colour, label, dashed); };
  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    const std::string colour = kColours[k % (sizeof kColours / sizeof kColours[0])];
    std::string points;
    const auto flush = [&] {
      if (!points.empty())
        svg += "<polyline fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"2\"" +
               (s.dashed ? " stroke-dasharray=\"6,4\"" : "") + " points=\"" + points + "\"/>\n";
      points.clear();
    };
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        flush();  // a gap in the line
        continue;
      }
      const std::string cx = fmt("%.1f", px(s.x[i])), cy = fmt("%.1f", py(s.y[i]));
      points += cx + "," + cy + " ";
      if (i < s.y_lo.size() && i < s.y_hi.size() && std::isfinite(s.y_lo[i]) && std::isfinite(s.y_hi[i]))
        svg += "<line x1=\"" + cx + "\" y1=\"" + fmt("%.1f", py(std::max(0.0, s.y_lo[i]))) + "\" x2=\"" + cx +
               "\" y2=\"" + fmt("%.1f", py(s.y_hi[i])) + "\" stroke=\"" + colour + "\" stroke-width=\"1.2\"/>\n";
      if (!s.dashed) svg += "<circle cx=\"" + cx + "\" cy=\"" + cy + "\" r=\"3\" fill=\"" + colour + "\"/>\n";
    }
    flush();
    legend(colour, s.label, s.dashed);
  }
  if (std::isfinite(o.marker_x)) {
    const std::string x = fmt("%.1f", px(std::clamp(o.marker_x, x0, x1)));
    svg += "<line x1=\"" + x + "\" y1=\"" + fmt("%.1f", top) + "\" x2=\"" + x + "\" y2=\"" + fmt("%.1f", top + ph) +
           "\" stroke=\"#b8860b\" stroke-width=\"2\"/>\n";
    legend("#b8860b", o.marker_label, false);
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace pdflab
